// Small rotation utilities on Eigen, with the project's naming convention:
// R_a_b maps a vector expressed in frame b into frame a (v_a = R_a_b v_b), and
// R_a_c = R_a_b * R_b_c. Angles are radians unless a name ends in _deg.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <numbers>
#include <vector>

namespace antpose {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Quat = Eigen::Quaterniond;

constexpr double deg2rad(double deg) { return deg * std::numbers::pi / 180.0; }
constexpr double rad2deg(double rad) { return rad * 180.0 / std::numbers::pi; }

/// Right-handed (counter-clockwise when the axis points at the viewer) rotation by `angle`
/// about the x, y or z axis: Rx(a) e_y = (0, cos a, sin a).
Mat3 rot_x(double angle);
Mat3 rot_y(double angle);
Mat3 rot_z(double angle);

/// Wraps an angle to [0, 2π).
double wrap_2pi(double angle);
/// Wraps an angle to (-π, π].
double wrap_pi(double angle);

/// Angle of the rotation R (in [0, π]), robust near 0 and π.
double rotation_angle(const Mat3& R);
/// Angle between two rotations, |log(R_a^T R_b)|.
double rotation_distance(const Mat3& R_a, const Mat3& R_b);

/// Projects a nearly orthogonal matrix onto SO(3) (closest rotation in Frobenius norm, via SVD).
Mat3 nearest_rotation(const Mat3& M);

/// Chordal L2 mean of rotations: the rotation nearest (Frobenius) to their sum (Hartley, Trumpf,
/// Dai & Li, "Rotation averaging", IJCV 103, 2013). Identity for an empty list.
Mat3 chordal_mean(const std::vector<Mat3>& rotations);

/// Skew-symmetric matrix [v]x with [v]x w = v × w.
Mat3 skew(const Vec3& v);

/// Rotation exp([w]x) of the rotation vector w (axis * angle), and its inverse log.
Mat3 exp_so3(const Vec3& w);
Vec3 log_so3(const Mat3& R);

/// Angle between two (non-zero) vectors, in [0, π], accurate for small and large angles.
double angle_between(const Vec3& a, const Vec3& b);

}  // namespace antpose
