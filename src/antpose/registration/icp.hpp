// Iterative closest point (Besl & McKay, "A method for registration of 3-D shapes", PAMI 1992):
// find T_target_source so that the source points, mapped into the target frame, lie on the
// target. Each iteration pairs every mapped source point with its nearest target point (k-d
// tree) within max_correspondence_distance_m, then solves for a rigid increment ΔT applied on
// the left (T ← ΔT T):
//   - point-to-point: the closed-form quaternion solution of Horn ("Closed-form solution of
//     absolute orientation using unit quaternions", JOSA A 4(4), 1987), weighted (thesis §6.3);
//   - point-to-plane: min Σ w (n·(ΔT p − q))², linearised (Chen & Medioni 1992; Low 2004);
//   - generalized (plane-to-plane): min Σ w dᵀ(C_q + R C_p Rᵀ)⁻¹d, d = q − ΔT p (Segal et al.,
//     RSS 2009), Gauss–Newton on SE(3).
// Robust kernels re-weight the pairs each iteration (IRLS) on the residual (m, or whitened for
// GICP). Correspondence search and the sums run in parallel (oneTBB).
// Convergence as PCL's: the increment's rotation cosine ≥ 1 − ε and its squared translation ≤ ε.
#pragma once

#include <cstddef>
#include <limits>
#include <optional>
#include <vector>

#include "antpose/geometry/point_cloud.hpp"
#include "antpose/registration/kdtree.hpp"

namespace antpose::registration {

enum class IcpMethod { kPointToPoint, kPointToPlane, kGeneralized };
enum class RobustKernel { kNone, kHuber, kTukey, kCauchy };

struct IcpOptions {
  IcpMethod method = IcpMethod::kPointToPoint;
  double max_correspondence_distance_m = 0.05;
  int max_iterations = 50;
  double transformation_epsilon = 1e-8;  // see the file comment
  RobustKernel kernel = RobustKernel::kNone;
  double kernel_scale = 0.01;     // m (whitened units for kGeneralized)
  std::size_t normal_k = 10;      // neighbours for normals (point-to-plane, target)
  std::size_t covariance_k = 20;  // neighbours for GICP covariances
  double gicp_epsilon = 1e-3;
  /// Where set (a unit vector in the target frame), the increment turns about no axis along it:
  /// the rotation about it stays the start's. Point-to-plane and generalized ICP only (their
  /// linear step is solved on the 5-D subspace); a measurement holds a panel's yaw about its
  /// long axis (z_a), which its points fix poorly when seen face-on, to read the axis's tilt.
  std::optional<Vec3> held_rotation_axis;
};

/// A cloud ready for registration: its k-d tree and what the method needs (target normals for
/// point-to-plane, covariances for GICP), computed once and reused across alignments.
struct PreparedCloud {
  PointCloud cloud;
  KdTree tree;
  std::vector<Mat3> covariances;  // GICP only
};
/// Normals are estimated when the method needs them and the cloud has none (sign arbitrary:
/// point-to-plane does not care).
PreparedCloud prepare(PointCloud cloud, const IcpOptions& options);

struct IcpResult {
  Iso3 T_target_source = Iso3::Identity();
  bool converged = false;
  int iterations = 0;
  std::size_t correspondences = 0;                           // pairs within the distance at the result
  double rmse_m = std::numeric_limits<double>::quiet_NaN();  // RMS point distance of those pairs
  double fitness = 0.0;                                      // correspondences / source points
  /// Gauss–Newton information of the final step (6×6, rotation then translation, left
  /// perturbation in the target frame): unscaled JᵀWJ.
  Eigen::Matrix<double, 6, 6> information = Eigen::Matrix<double, 6, 6>::Zero();
};

/// Aligns `source` to `target` from `T_initial`. std::invalid_argument for an empty cloud or a
/// method whose target data (normals, covariances) is missing.
IcpResult align(const PreparedCloud& source, const PreparedCloud& target, const Iso3& T_initial,
                const IcpOptions& options);

/// PCL's getFitnessScore: mean squared distance (m²) from each mapped source point to its
/// nearest target point, over pairs closer than max_distance_m.
double fitness_score(const PointCloud& source, const KdTree& target, const Iso3& T_target_source,
                     double max_distance_m = std::numeric_limits<double>::infinity());

/// The rotation maximising Σ w qᵢᵀ R pᵢ for centred point sets, given their weighted
/// cross-covariance S = Σ w pᵢ qᵢᵀ (Horn 1987, the eigenvector of the largest eigenvalue of the
/// symmetric 4×4 matrix N(S)).
Mat3 horn_rotation(const Mat3& S);

}  // namespace antpose::registration
