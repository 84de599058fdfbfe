#include "antpose/registration/icp.hpp"

#include <cmath>
#include <optional>
#include <stdexcept>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>  // parallel_deterministic_reduce

#include "antpose/registration/local_geometry.hpp"

namespace antpose::registration {
namespace {

using Mat6 = Eigen::Matrix<double, 6, 6>;
using Vec6 = Eigen::Matrix<double, 6, 1>;

/// IRLS weight of a residual r ≥ 0 (m, or whitened).
double kernel_weight(RobustKernel kernel, double r, double k) {
  switch (kernel) {
    case RobustKernel::kNone:
      return 1.0;
    case RobustKernel::kHuber:
      return r <= k ? 1.0 : k / r;
    case RobustKernel::kTukey: {
      if (r >= k) return 0.0;
      const double u = 1.0 - (r / k) * (r / k);
      return u * u;
    }
    case RobustKernel::kCauchy:
      return 1.0 / (1.0 + (r / k) * (r / k));
  }
  return 1.0;
}

/// What one pass over the correspondences accumulates (summed in parallel).
struct Sums {
  // Gauss–Newton normal equations (point-to-plane, GICP; also point-to-point for the information).
  Mat6 H = Mat6::Zero();
  Vec6 g = Vec6::Zero();
  // Horn: weighted first and second moments of the pairs (point-to-point).
  double w = 0.0;
  Vec3 sp = Vec3::Zero(), sq = Vec3::Zero();
  Mat3 spq = Mat3::Zero();
  double squared = 0.0;  // Σ |p − q|² over pairs
  std::size_t pairs = 0;

  void add(const Sums& o) {
    H += o.H, g += o.g, w += o.w, sp += o.sp, sq += o.sq, spq += o.spq, squared += o.squared, pairs += o.pairs;
  }
};

/// Jacobian of ΔT p with respect to a left increment (ω, v) at identity: [−[p]×, I].
Eigen::Matrix<double, 3, 6> point_jacobian(const Vec3& p) {
  Eigen::Matrix<double, 3, 6> J;
  J.leftCols<3>() = -skew(p);
  J.rightCols<3>().setIdentity();
  return J;
}

/// One pass over the correspondences at T. Point-to-point needs JᵀWJ only for the result's
/// information, so it is summed only when `information` is asked for.
Sums accumulate(const PreparedCloud& source, const PreparedCloud& target, const Iso3& T, const IcpOptions& o,
                bool information = false) {
  const double max_d2 = o.max_correspondence_distance_m * o.max_correspondence_distance_m;
  const auto& src = source.cloud.points;
  const auto& dst = target.cloud.points;
  // Deterministic: the same split into ranges and the same order of additions on every run and
  // thread count. A floating-point sum in a scheduling-dependent order differs in the last bits,
  // and the measurement's held-axis search, on a flat outline score, turned that into a degree.
  return tbb::parallel_deterministic_reduce(
      tbb::blocked_range<std::size_t>(0, src.size(), 512), Sums{},
      [&](const tbb::blocked_range<std::size_t>& range, Sums s) {
        for (std::size_t i = range.begin(); i < range.end(); ++i) {
          const Vec3 p = T * src[i];
          std::size_t j;
          double d2;
          if (!target.tree.nearest(p, j, d2, max_d2)) continue;
          const Vec3& q = dst[j];
          const Eigen::Matrix<double, 3, 6> J = point_jacobian(p);
          ++s.pairs;
          s.squared += d2;
          switch (o.method) {
            case IcpMethod::kPointToPoint: {
              const double w = kernel_weight(o.kernel, std::sqrt(d2), o.kernel_scale);
              s.w += w, s.sp += w * p, s.sq += w * q, s.spq += w * p * q.transpose();
              if (information) s.H += w * J.transpose() * J;
              break;
            }
            case IcpMethod::kPointToPlane: {
              const Vec3& n = target.cloud.normals[j];
              const double r = n.dot(p - q);
              const double w = kernel_weight(o.kernel, std::abs(r), o.kernel_scale);
              const Vec6 Jr = J.transpose() * n;
              s.H += w * Jr * Jr.transpose();
              s.g += w * Jr * r;
              break;
            }
            case IcpMethod::kGeneralized: {
              const Mat3 R = T.linear();
              const Mat3 C = target.covariances[j] + R * source.covariances[i] * R.transpose();
              const Mat3 M = C.inverse();
              const Vec3 d = p - q;
              const double w = kernel_weight(o.kernel, std::sqrt(d.dot(M * d)), o.kernel_scale);
              s.H += w * J.transpose() * M * J;
              s.g += w * J.transpose() * M * d;
              break;
            }
          }
        }
        return s;
      },
      [](Sums a, const Sums& b) {
        a.add(b);
        return a;
      });
}

/// The increment of one iteration (applied on the left), or nullopt when it is undetermined.
std::optional<Iso3> increment(const Sums& s, IcpMethod method, const std::optional<Vec3>& held_axis) {
  Iso3 dT = Iso3::Identity();
  if (method == IcpMethod::kPointToPoint) {
    if (s.pairs < 3 || s.w <= 0.0) return std::nullopt;
    const Vec3 mp = s.sp / s.w, mq = s.sq / s.w;
    const Mat3 S = s.spq - s.w * mp * mq.transpose();
    dT.linear() = horn_rotation(S);
    dT.translation() = mq - dT.linear() * mp;
    return dT;
  }
  if (s.pairs < 6) return std::nullopt;
  Vec6 xi;
  if (!held_axis) {
    const Eigen::LDLT<Mat6> ldlt(s.H);
    if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return std::nullopt;
    xi = -ldlt.solve(s.g);
  } else {
    // ξ = P y, P spanning the rotations across the axis and all translations: PᵀHP y = −Pᵀg.
    const Vec3 a = held_axis->normalized(), u = a.unitOrthogonal();
    Eigen::Matrix<double, 6, 5> P = Eigen::Matrix<double, 6, 5>::Zero();
    P.block<3, 1>(0, 0) = u;
    P.block<3, 1>(0, 1) = a.cross(u);
    P.block<3, 3>(3, 2).setIdentity();
    const Eigen::LDLT<Eigen::Matrix<double, 5, 5>> ldlt(P.transpose() * s.H * P);
    if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return std::nullopt;
    xi = -P * ldlt.solve(P.transpose() * s.g);
  }
  if (!xi.allFinite()) return std::nullopt;
  dT.linear() = exp_so3(xi.head<3>());
  dT.translation() = xi.tail<3>();
  return dT;
}

}  // namespace

Mat3 horn_rotation(const Mat3& S) {
  const double xx = S(0, 0), xy = S(0, 1), xz = S(0, 2), yx = S(1, 0), yy = S(1, 1), yz = S(1, 2), zx = S(2, 0),
               zy = S(2, 1), zz = S(2, 2);
  Eigen::Matrix4d N;
  N << xx + yy + zz, yz - zy, zx - xz, xy - yx,  //
      yz - zy, xx - yy - zz, xy + yx, zx + xz,   //
      zx - xz, xy + yx, -xx + yy - zz, yz + zy,  //
      xy - yx, zx + xz, yz + zy, -xx - yy + zz;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> es(N);
  const Eigen::Vector4d q = es.eigenvectors().col(3);  // largest eigenvalue
  return Quat(q(0), q(1), q(2), q(3)).normalized().toRotationMatrix();
}

PreparedCloud prepare(PointCloud cloud, const IcpOptions& options) {
  KdTree tree(cloud.points);
  PreparedCloud out{std::move(cloud), std::move(tree), {}};
  if (options.method == IcpMethod::kPointToPlane && !out.cloud.has_normals())
    out.cloud.normals = estimate_normals(out.tree, options.normal_k);
  if (options.method == IcpMethod::kGeneralized)
    out.covariances = estimate_covariances(out.tree, options.covariance_k, options.gicp_epsilon);
  return out;
}

IcpResult align(const PreparedCloud& source, const PreparedCloud& target, const Iso3& T_initial,
                const IcpOptions& options) {
  if (source.cloud.empty() || target.cloud.empty()) throw std::invalid_argument("ICP: empty source or target cloud");
  if (options.method == IcpMethod::kPointToPlane && !target.cloud.has_normals())
    throw std::invalid_argument("ICP point-to-plane: the target has no normals (use prepare())");
  if (options.method == IcpMethod::kGeneralized &&
      (source.covariances.size() != source.cloud.size() || target.covariances.size() != target.cloud.size()))
    throw std::invalid_argument("generalized ICP: both clouds need covariances (use prepare())");
  if (options.held_rotation_axis && options.method == IcpMethod::kPointToPoint)
    throw std::invalid_argument("ICP point-to-point: a held rotation axis needs point-to-plane or generalized ICP");
  IcpResult result;
  Iso3 T = T_initial;
  for (int it = 0; it < options.max_iterations; ++it) {
    const Sums s = accumulate(source, target, T, options);
    const auto dT = increment(s, options.method, options.held_rotation_axis);
    result.iterations = it + 1;
    if (!dT) break;
    T = *dT * T;
    const double cos_angle = 0.5 * (dT->linear().trace() - 1.0);
    if (cos_angle >= 1.0 - options.transformation_epsilon &&
        dT->translation().squaredNorm() <= options.transformation_epsilon) {
      result.converged = true;
      break;
    }
  }
  T.linear() = nearest_rotation(T.linear());
  result.T_target_source = T;
  const Sums s = accumulate(source, target, T, options, true);
  result.correspondences = s.pairs;
  result.fitness = static_cast<double>(s.pairs) / static_cast<double>(source.cloud.size());
  if (s.pairs > 0) result.rmse_m = std::sqrt(s.squared / static_cast<double>(s.pairs));
  result.information = s.H;
  return result;
}

double fitness_score(const PointCloud& source, const KdTree& target, const Iso3& T_target_source,
                     double max_distance_m) {
  const double max_d2 = max_distance_m * max_distance_m;
  double sum = 0.0;
  std::size_t n = 0;
  for (const auto& p : source.points) {
    std::size_t j;
    double d2;
    if (target.nearest(T_target_source * p, j, d2, max_d2)) sum += d2, ++n;
  }
  return n ? sum / static_cast<double>(n) : std::numeric_limits<double>::infinity();
}

}  // namespace antpose::registration
