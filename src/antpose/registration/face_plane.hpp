// The planes of a registered panel's long faces from the region's points: a check of the
// orientation its outline gives, by a measurement independent of it.
//
// The outline and the dense points measure a face's orientation in different ways: the outline by
// where the panel's edges lie in the photos, the points by stereo depth across the face. Each can
// be biased in a way its own σ does not know: the outline by what the model lacks (arms and
// clamps beside the back edge, a rounder edge), the points by an oblique view of a narrow or
// periodically textured face. Where the two agree within their σ, nothing is learnt beyond the
// outline's answer. Where they disagree beyond it, one of them is biased and the photos do not
// say which: the face laid onto its points' plane is then a rival pose the answer's σ must cover
// (measure/antenna_attitude.hpp, widen_for_rivals). The answer itself stays the outline's: the
// points' plane is not the better estimate (a narrow face seen obliquely leaves its points off
// by several degrees), only evidence that the outline may be off by as much.
//
// On each long face (±x_a, ±y_a) the photos see, the region's points within `gate_m` of its
// registered plane, over its flat part (inside the edge rounding, away from the end caps), are
// fitted by least squares with depth d = c₀ + b·u + c·v (u along the long axis z_a, v across the
// face, (u, v, n) right-handed), re-gated at `inlier_sigmas` × their RMS. A small turn ω of the
// true face against the registered one (antenna frame) gives b = −ω·e_v and c = ω·e_u, so the fit
// measures the turn's two components in the face's plane (the one about its normal is not seen).
// The slopes' covariance C_s is the fit's σ²(AᵀA)⁻¹, inflated by n/n_eff for neighbouring stereo
// points' correlation: n_eff counts the correlation_m squares of the face the points occupy (the
// dense matching's window spreads one error over its neighbours, and points bunched on a plain
// radome's few details are few measurements however many they are), plus the face's own deviation
// from a plane (`flatness_m`) over its extent. The disagreement is χ² = sᵀ(C_s + H Σ Hᵀ)⁻¹s of the
// slopes s against the outline's rotation covariance Σ carried into slope space (H: ω to the
// slopes).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "antpose/core/check.hpp"
#include "antpose/geometry/point_cloud.hpp"
#include "antpose/geometry/rotation.hpp"

namespace antpose::registration {

struct FacePlaneOptions {
  bool enabled = true;
  double gate_m = 0.02;             // points this near a face's registered plane are its candidates
  double end_fraction = 0.8;        // of the face's length, centred: away from the end caps
  double edge_margin_m = 0.005;     // inside the edge rounding across the face
  double inlier_sigmas = 3.0;       // re-gated at this many RMS of the fit
  double min_gate_m = 0.004;        // ... but no narrower
  int iterations = 4;               // fits, each re-gated
  std::size_t min_points = 100;     // on a face, else it is not fitted
  double min_cover_fraction = 0.5;  // the points span at least this share of the flat part, along and across
  double correlation_m = 0.03;      // see the file comment
  double max_rms_m = 0.005;         // the points' scatter about their plane at most: beyond, not a plane's
  double flatness_m = 0.0005;       // the face's own tilt across its extent (an extruded radome: ±0.5 mm)
  double max_chi2 = 9.21;           // χ² with 2 degrees of freedom at 99 %: beyond, the two disagree
  OptionProblems Check() const;
};

/// One face's plane as its points lie, against the registered face.
struct FacePlane {
  Vec3 normal_antenna = Vec3::Zero();  // the face's outward normal, an axis of the antenna frame
  std::size_t points = 0;
  double rms_m = 0.0;                        // of the points about their plane
  Vec2 slopes = Vec2::Zero();                // (b, c): depth per metre along the long axis and across
  Mat3 covariance_board = Mat3::Zero();      // of `turn_board`, rad² (rank 2: nothing about the normal)
  Vec3 turn_board = Vec3::Zero();            // rad: laid by R = exp(turn)·R_board_antenna on the points' plane
  double chi2 = 0.0;                         // of the turn against its covariance and the outline's
  bool disagrees = false;                    // chi2 > FacePlaneOptions::max_chi2
};

/// The planes of the long faces the photos see (facing the mean viewpoint) where the region's
/// points lie on them as on a plane: at least `min_points`, covering enough of the face, scattered
/// by at most `max_rms_m` (more is other objects among them: arms, clamps, the mast, or stereo
/// mismatched on a repeating texture). `T_board_antenna`: the registered pose; `size_m`: the box
/// (width, depth, length along x_a, y_a, z_a); `edge_radius_m`: the rounding of its long edges;
/// `outline_covariance_board`: the registration's rotation covariance (rad²).
std::vector<FacePlane> fit_face_planes(const PointCloud& points_board, const Iso3& T_board_antenna,
                                       const Vec3& size_m, double edge_radius_m,
                                       const std::vector<Vec3>& viewpoints_board,
                                       const Mat3& outline_covariance_board, const FacePlaneOptions& options);

/// The face's short name for reports: "+x", "-y", ...
std::string face_name(const Vec3& normal_antenna);

}  // namespace antpose::registration
