// refine_camera_poses: SIFT tracks + bundle adjustment (Triggs, McLauchlan, Hartley & Fitzgibbon,
// "Bundle adjustment — a modern synthesis", 1999) with Ceres, the board's points fixed.
//
// Each camera's parameters are a left increment δ (rotation vector, camera frame) and the
// translation t: R = exp(δ) R₀, with R₀ the pose before the solve. After each solve R₀ absorbs δ
// and δ restarts at 0, so the covariance of δ at the solution is directly the covariance of the
// left perturbation R_true = exp(δ) R_est that board_pose.hpp reports.
#include <algorithm>
#include <cmath>
#include <memory>
#include <mutex>

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <fmt/format.h>
#include <opencv2/core/utility.hpp>

#include "antpose/camera/board_pose.hpp"
#include "antpose/reconstruction/features.hpp"
#include "antpose/reconstruction/reconstruct.hpp"

namespace antpose::reconstruction {
namespace {

/// The distorted projection of CameraIntrinsics::project, templated for autodiff.
template <typename T>
void project(const camera::CameraIntrinsics& K, const T* p, T* uv) {
  const T x = p[0] / p[2], y = p[1] / p[2];
  const T r2 = x * x + y * y;
  const auto& d = K.distortion;
  const T radial = T(1) + r2 * (T(d[0]) + r2 * (T(d[1]) + r2 * T(d[4])));
  const T xd = x * radial + T(2 * d[2]) * x * y + T(d[3]) * (r2 + T(2) * x * x);
  const T yd = y * radial + T(d[2]) * (r2 + T(2) * y * y) + T(2 * d[3]) * x * y;
  uv[0] = T(K.fx) * xd + T(K.cx);
  uv[1] = T(K.fy) * yd + T(K.cy);
}

/// Residual (px, divided by sigma) of a point observed by a camera (δ, t | R₀).
struct ReprojectionCost {
  ReprojectionCost(const camera::CameraIntrinsics& K, const Mat3& R0, const Vec2& uv, double sigma)
      : K(K), R0(R0), uv(uv), inv_sigma(1.0 / sigma) {}
  template <typename T>
  bool operator()(const T* camera, const T* point, T* residual) const {
    T q[3];
    for (int i = 0; i < 3; ++i) q[i] = T(R0(i, 0)) * point[0] + T(R0(i, 1)) * point[1] + T(R0(i, 2)) * point[2];
    T p[3];
    ceres::AngleAxisRotatePoint(camera, q, p);
    for (int i = 0; i < 3; ++i) p[i] += camera[3 + i];
    if (p[2] <= T(1e-6)) return false;
    T pred[2];
    project(K, p, pred);
    residual[0] = (pred[0] - uv.x()) * inv_sigma;
    residual[1] = (pred[1] - uv.y()) * inv_sigma;
    return true;
  }
  camera::CameraIntrinsics K;
  Mat3 R0;
  Vec2 uv;
  double inv_sigma;
};

/// The same for a fixed (board) point.
struct FixedPointCost {
  FixedPointCost(const camera::CameraIntrinsics& K, const Mat3& R0, const Vec3& X, const Vec2& uv, double sigma)
      : inner(K, R0, uv, sigma), X(X) {}
  template <typename T>
  bool operator()(const T* camera, T* residual) const {
    const T point[3] = {T(X.x()), T(X.y()), T(X.z())};
    return inner(camera, point, residual);
  }
  ReprojectionCost inner;
  Vec3 X;
};

struct SceneObservation {
  int view, track;
  Vec2 uv;
};

}  // namespace

RefinedPoses refine_camera_poses(const std::vector<PosedView>& views, const camera::CameraIntrinsics& intrinsics,
                                 const PoseRefinementOptions& options, const Progress& progress) {
  if (views.size() < 2)
    throw MeasurementError(fmt::format("pose refinement needs at least 2 photos, got {}", views.size()));
  for (const auto& v : views) {
    if (v.image.empty() || v.image.type() != CV_8UC1)
      throw MeasurementError(fmt::format("{}: the image is empty or not 8-bit grey", v.name));
    if (v.image.cols != intrinsics.width || v.image.rows != intrinsics.height)
      throw MeasurementError(fmt::format("{}: the image is {}×{} px but the intrinsics are for {}×{} px", v.name,
                                         v.image.cols, v.image.rows, intrinsics.width, intrinsics.height));
    if (v.board_image_px.size() != v.board_points_m.size())
      throw MeasurementError(fmt::format("{}: {} board detections for {} board points", v.name, v.board_image_px.size(),
                                         v.board_points_m.size()));
  }
  const int n = int(views.size());
  const double focal = 0.5 * (intrinsics.fx + intrinsics.fy);
  auto report = [&](const std::string& stage, int done, int total) {
    if (progress) progress(stage, done, total);
  };

  // 1. Features, with the board masked out: its corners are already observations of fixed
  //    points, and its repetitive pattern would only produce ambiguous matches.
  std::vector<detail::ViewFeatures> features(n);
  constexpr int kMaxSide = 2000;  // 12 MP photos: features at ~4 MP are plenty for the poses
  cv::parallel_for_(cv::Range(0, n), [&](const cv::Range& r) {
    for (int v = r.start; v < r.end; ++v) {
      const auto& bp = views[v].board_image_px;
      double grow = 0;
      if (bp.size() >= 3) {
        Vec2 lo = bp[0], hi = bp[0];
        for (const auto& p : bp) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
        grow = 0.2 * (hi - lo).norm() + 10.0;  // outer squares and the white margin
      }
      const cv::Mat mask = detail::mask_outside_hull(views[v].image.size(), bp, grow);
      features[v] = detail::detect_features(views[v].image, mask, cv::Rect(0, 0, intrinsics.width, intrinsics.height),
                                            options.max_features_per_view, kMaxSide, intrinsics);
    }
  });
  report("features", n, n);

  // 2. Pairwise candidate matches (ratio test), computed once.
  std::vector<detail::PairMatches> pairs;
  for (int a = 0; a < n; ++a)
    for (int b = a + 1; b < n; ++b) pairs.push_back({a, b, {}});
  std::vector<std::vector<std::pair<int, int>>> candidates(pairs.size());
  std::mutex mutex;
  int matched_pairs = 0;
  cv::parallel_for_(cv::Range(0, int(pairs.size())), [&](const cv::Range& r) {
    for (int k = r.start; k < r.end; ++k) {
      candidates[k] = detail::ratio_matches(features[pairs[k].view_a], features[pairs[k].view_b], options.ratio_test);
      std::lock_guard lock(mutex);
      report("matching", ++matched_pairs, int(pairs.size()));
    }
  });

  // The PnP poses' own rotation uncertainty (rad, 1σ, all axes): a small or distant board
  // leaves errors of several pixels on the epipolar lines, so the first filter allows 3σ more.
  std::vector<double> pnp_sigma(n, 0.0);
  for (int v = 0; v < n; ++v) {
    try {
      const auto pnp = camera::estimate_board_pose(views[v].board_image_px, views[v].board_points_m, intrinsics);
      pnp_sigma[v] = std::sqrt(pnp.covariance.topLeftCorner<3, 3>().trace());
    } catch (const Error&) {
      pnp_sigma[v] = deg2rad(1.0);  // no usable board in this view: its pose is a guess
    }
  }

  // 3. Tracks and their points with the current poses: epipolar filter (extra px per pair),
  //    union-find chaining, triangulation with a reprojection limit.
  std::vector<Mat3> R(n);
  std::vector<Eigen::Matrix<double, 6, 1>> cam(n);
  // The poses as given, the board's PnP: the start, and the result where the features are
  // rejected (after the final solve).
  const auto start_at_board_poses = [&] {
    for (int v = 0; v < n; ++v) {
      R[v] = views[v].R_camera_board;
      cam[v] << Vec3::Zero(), views[v].t_camera_board;
    }
  };
  start_at_board_poses();
  std::vector<Vec3> points;
  std::vector<SceneObservation> scene;
  std::vector<char> active;
  auto make_tracks = [&](bool loose) {
    double worst_extra = 0;
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      auto& p = pairs[k];
      const Mat3 R_b_a = R[p.view_b] * R[p.view_a].transpose();
      const Vec3 t_b_a = cam[p.view_b].tail<3>() - R_b_a * cam[p.view_a].tail<3>();
      double extra = 0;
      if (loose)
        extra = std::min(50.0, std::max(2.0 * options.max_epipolar_px,
                                        3.0 * focal * std::hypot(pnp_sigma[p.view_a], pnp_sigma[p.view_b])));
      worst_extra = std::max(worst_extra, extra);
      // Features found on a downscaled image are that much less precise.
      const double tol =
          (options.max_epipolar_px + extra) / std::min(features[p.view_a].scale, features[p.view_b].scale);
      p.matches =
          detail::epipolar_filter(features[p.view_a], features[p.view_b], candidates[k], R_b_a, t_b_a, tol, focal);
    }
    std::vector<std::size_t> counts(n);
    for (int v = 0; v < n; ++v) counts[v] = features[v].px.size();
    auto tracks = detail::build_tracks(counts, pairs);
    detail::TriangulationChecks checks;
    checks.max_reprojection_px = 2.0 * options.max_reprojection_px + worst_extra;
    checks.min_angle_rad = deg2rad(1.0);
    std::vector<Vec3> tr(n);
    for (int v = 0; v < n; ++v) tr[v] = cam[v].tail<3>();
    points.clear();
    scene.clear();
    for (auto& track : tracks) {
      const auto X = detail::triangulate_track(track, features, R, tr, intrinsics, checks);
      if (!X) continue;
      const int id = int(points.size());
      points.push_back(*X);
      for (const auto& [v, i] : track) scene.push_back({v, id, features[v].px[i]});
    }
    active.assign(scene.size(), 1);
  };
  make_tracks(true);
  report("triangulation", 1, 2);

  // 4. Bundle adjustment: a first solve, outlier removal, noise levels re-estimated per
  //    observation class, a second solve.
  double sigma_board = 0.3, sigma_scene = 1.0;
  RefinedPoses out;
  out.covariance.assign(n, Eigen::Matrix<double, 6, 6>::Zero());

  auto build_and_solve = [&](ceres::Problem& problem) {
    // Created only when used: the problem owns (and deletes) only the losses of its blocks.
    const bool any_scene = std::find(active.begin(), active.end(), 1) != active.end();
    ceres::LossFunction* huber = any_scene ? new ceres::HuberLoss(options.huber_px / sigma_scene) : nullptr;
    for (int v = 0; v < n; ++v) {
      problem.AddParameterBlock(cam[v].data(), 6);
      for (std::size_t k = 0; k < views[v].board_points_m.size(); ++k) {
        auto* cost = new ceres::AutoDiffCostFunction<FixedPointCost, 2, 6>(
            new FixedPointCost(intrinsics, R[v], views[v].board_points_m[k], views[v].board_image_px[k], sigma_board));
        problem.AddResidualBlock(cost, nullptr, cam[v].data());
      }
    }
    for (std::size_t k = 0; k < scene.size(); ++k) {
      if (!active[k]) continue;
      const auto& o = scene[k];
      auto* cost = new ceres::AutoDiffCostFunction<ReprojectionCost, 2, 6, 3>(
          new ReprojectionCost(intrinsics, R[o.view], o.uv, sigma_scene));
      problem.AddResidualBlock(cost, huber, cam[o.view].data(), points[o.track].data());
    }
    ceres::Solver::Options so;
    // The reduced camera system is small (6 per photo) and dense: Eigen's dense Cholesky solves
    // it, single-threaded and the same to the last bit on every run (SuiteSparse brings its own
    // OpenMP and BLAS threads).
    so.linear_solver_type = ceres::DENSE_SCHUR;
    so.dense_linear_algebra_library_type = ceres::EIGEN;
    so.max_num_iterations = options.max_iterations;
    // One thread: with two, runs of `antpose measure` on the same photos differed in the last
    // bits, and near-ties downstream turned on them; with one, runs agree to the last bit. The
    // same photos must give the same numbers. The problem is small (12 cameras, ~1000 tracks): it costs ~0.1 s.
    so.num_threads = 1;
    so.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(so, &problem, &summary);
    // Fold the increments into R₀ so that δ = 0 at the solution.
    for (int v = 0; v < n; ++v) {
      R[v] = exp_so3(cam[v].head<3>()) * R[v];
      cam[v].head<3>().setZero();
    }
    return summary;
  };

  auto residual_px = [&](int v, const Vec3& X, const Vec2& uv) {
    const auto p = intrinsics.project(R[v] * X + cam[v].tail<3>());
    return p ? (*p - uv).norm() : 1e9;
  };
  // The board corners' reprojection RMS (px) and their count, at the current poses.
  auto board_rms = [&] {
    double s = 0;
    std::size_t m = 0;
    for (int v = 0; v < n; ++v)
      for (std::size_t k = 0; k < views[v].board_points_m.size(); ++k, ++m)
        s += std::pow(residual_px(v, views[v].board_points_m[k], views[v].board_image_px[k]), 2);
    return std::make_pair(m ? std::sqrt(s / double(m)) : 0.0, m);
  };
  const double board_only_rms = board_rms().first;

  {
    // A first solve on the loosely filtered tracks (robust loss), then the tracks again with
    // the improved poses and the strict epipolar limit.
    ceres::Problem problem;
    build_and_solve(problem);
    make_tracks(false);
    report("triangulation", 2, 2);
    ceres::Problem strict;
    build_and_solve(strict);
  }
  report("bundle adjustment", 1, 3);
  // Outliers: observations beyond max_reprojection_px; a track left with < 2 views is dropped.
  std::vector<int> per_track(points.size(), 0);
  for (std::size_t k = 0; k < scene.size(); ++k) {
    const auto& o = scene[k];
    active[k] = residual_px(o.view, points[o.track], o.uv) <= options.max_reprojection_px;
    per_track[o.track] += active[k];
  }
  for (std::size_t k = 0; k < scene.size(); ++k)
    if (per_track[scene[k].track] < 2) active[k] = 0;
  auto scene_rms = [&] {
    double s = 0;
    std::size_t m = 0;
    for (std::size_t k = 0; k < scene.size(); ++k)
      if (active[k]) s += std::pow(residual_px(scene[k].view, points[scene[k].track], scene[k].uv), 2), ++m;
    return std::make_pair(m ? std::sqrt(s / double(m)) : 0.0, m);
  };
  // Weights from the first solve's residuals (each class its own noise level, so that neither
  // the sub-pixel board corners nor the many features dominate by count or by a guessed σ).
  // rms() is of the 2-D residual's length: per axis it is / √2, and the residuals are smaller
  // than the noise by the parameters they fitted (each camera's 6 mostly from its board, each
  // track's 3 from its own observations).
  {
    const auto [rb, nb] = board_rms();
    const auto [rs, ns] = scene_rms();
    std::vector<char> live(points.size(), 0);
    for (std::size_t k = 0; k < scene.size(); ++k)
      if (active[k]) live[scene[k].track] = 1;
    const double live_tracks = double(std::count(live.begin(), live.end(), 1));
    const double fb = double(2 * nb) / std::max(1.0, double(2 * nb) - 6.0 * n);
    const double fs = double(2 * ns) / std::max(1.0, double(2 * ns) - 3.0 * live_tracks);
    sigma_board = std::max(0.02, rb / std::sqrt(2.0) * std::sqrt(std::max(1.0, fb)));
    sigma_scene = std::max(0.05, rs / std::sqrt(2.0) * std::sqrt(std::max(1.0, fs)));
  }

  // Covariance of each camera's (δ, t) at the solution, scaled by the whitened residual
  // variance (cost per degree of freedom), Hartley & Zisserman §5.2.3 / Triggs et al. §6.
  auto pose_covariance = [&](ceres::Problem& problem) {
    ceres::Problem::EvaluateOptions eo;
    double cost = 0;
    problem.Evaluate(eo, &cost, nullptr, nullptr, nullptr);
    const int params = problem.NumParameters();
    const int residuals = problem.NumResiduals();
    const double dof = std::max(1, residuals - params);
    const double variance = 2.0 * cost / dof;
    ceres::Covariance::Options co;
    co.algorithm_type = ceres::SPARSE_QR;
    // SuiteSparse's QR: Eigen's took 18 s for the 3000 tracks of a ground site (0.1 s here).
    co.num_threads = 1;
    ceres::Covariance covariance(co);
    std::vector<std::pair<const double*, const double*>> blocks;
    for (int v = 0; v < n; ++v) blocks.emplace_back(cam[v].data(), cam[v].data());
    if (covariance.Compute(blocks, &problem)) {
      for (int v = 0; v < n; ++v) {
        Eigen::Matrix<double, 6, 6, Eigen::RowMajor> c;
        covariance.GetCovarianceBlock(cam[v].data(), cam[v].data(), c.data());
        out.covariance[v] = c * variance;
      }
    } else {
      out.warnings.emplace_back("the pose covariances could not be computed (rank-deficient bundle adjustment)");
    }
  };
  auto problem = std::make_unique<ceres::Problem>();
  build_and_solve(*problem);
  report("bundle adjustment", 2, 3);

  // The board is the reference: true tracks move the cameras within what its corners allow, so
  // its residual barely grows (a few hundredths of a pixel). False tracks that agree with each
  // other (a moiré on ground seen at a grazing angle, something that moved) can bend all the
  // poses together instead: a common turn of a tenth of a degree triples the board's RMS and
  // puts a panel 20 m away more than 1° off in downtilt. Then the poses are the board's alone.
  const double board_rms_with_scene = board_rms().first;
  const bool scene_rejected =
      board_rms_with_scene > options.max_board_rms_growth * std::max(board_only_rms, options.board_rms_floor_px);
  if (scene_rejected) {
    out.warnings.push_back(fmt::format(
        "the photos' features pull the camera poses away from the board (its corners fit to {:.2f} px with them, "
        "{:.2f} px without): they hold false matches that agree with each other (a repeating or moiré texture, "
        "something that moved), so the poses rest on the board alone",
        board_rms_with_scene, board_only_rms));
    start_at_board_poses();
    active.assign(scene.size(), 0);
    problem = std::make_unique<ceres::Problem>();
    build_and_solve(*problem);
  }
  pose_covariance(*problem);
  report("bundle adjustment", 3, 3);

  for (int v = 0; v < n; ++v) {
    out.R_camera_board.push_back(R[v]);
    out.t_camera_board.push_back(cam[v].tail<3>());
  }
  out.board_rms_px = board_rms().first;
  std::tie(out.scene_rms_px, out.observations) = scene_rms();
  std::vector<int> seen(points.size(), 0);
  std::vector<std::vector<int>> view_tracks(n);
  for (std::size_t k = 0; k < scene.size(); ++k)
    if (active[k]) ++seen[scene[k].track];
  out.tracks = std::count_if(seen.begin(), seen.end(), [](int c) { return c >= 2; });

  // Few shared tracks: the poses are essentially the PnP poses (still valid, less refined).
  if (scene_rejected) return out;
  for (int v = 0; v < n; ++v) {
    std::size_t obs = 0;
    for (std::size_t k = 0; k < scene.size(); ++k) obs += active[k] && scene[k].view == v;
    if (obs < 20)
      out.warnings.push_back(
          fmt::format("{}: only {} feature observations tie it to the other photos; its pose "
                      "rests on the board alone",
                      views[v].name, obs));
  }
  if (out.tracks < 50)
    out.warnings.push_back(
        fmt::format("only {} feature tracks tie the photos together (too little texture or "
                    "overlap); the poses are barely refined beyond the board's PnP",
                    out.tracks));
  return out;
}

}  // namespace antpose::reconstruction
