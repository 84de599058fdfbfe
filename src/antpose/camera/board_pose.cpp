#include "antpose/camera/board_pose.hpp"
#include "antpose/io/photo_file.hpp"

#include <cmath>

#include <Eigen/Dense>
#include <fmt/core.h>
#include <tbb/parallel_for.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgcodecs.hpp>

namespace antpose::camera {
namespace {

cv::Mat camera_matrix(const CameraIntrinsics& in) {
  cv::Mat K;
  cv::eigen2cv(Mat3(in.K()), K);
  return K;
}

cv::Mat distortion(const CameraIntrinsics& in) {
  cv::Mat d(1, 5, CV_64F);
  for (int i = 0; i < 5; ++i) d.at<double>(i) = in.distortion[static_cast<std::size_t>(i)];
  return d;
}

// ∂π/∂p (2×3) at a camera-frame point, by central differences of the full lens model (smooth
// for Z > 0; the step is relative to the point's depth so the truncation error is ~1e-10).
Eigen::Matrix<double, 2, 3> projection_jacobian(const CameraIntrinsics& in, const Vec3& p) {
  Eigen::Matrix<double, 2, 3> J;
  const double h = 1e-6 * std::max(std::abs(p.z()), 1e-3);
  for (int k = 0; k < 3; ++k) {
    Vec3 a = p, b = p;
    a[k] += h;
    b[k] -= h;
    const auto ua = in.project(a), ub = in.project(b);
    if (!ua || !ub) throw MeasurementError("board pose: a board point lies behind the camera");
    J.col(k) = (*ua - *ub) / (2.0 * h);
  }
  return J;
}

}  // namespace

std::vector<Vec2> reprojection_residuals(const std::vector<Vec2>& uv, const std::vector<Vec3>& P,
                                         const CameraIntrinsics& in, const Mat3& R, const Vec3& t) {
  std::vector<Vec2> r;
  r.reserve(uv.size());
  for (std::size_t i = 0; i < uv.size(); ++i) {
    const auto u = in.project(R * P[i] + t);
    if (!u) throw MeasurementError("board pose: a board point lies behind the camera");
    r.push_back(*u - uv[i]);
  }
  return r;
}

std::string image_size_mismatch(int width, int height, const CameraIntrinsics& in) {
  if (width == in.width && height == in.height) return {};
  if (width == in.height && height == in.width)
    return fmt::format(
        "image is {}x{} px but the intrinsics are for {}x{} px (rotated: portrait vs landscape; "
        "photos must be stored in the orientation of the calibration)",
        width, height, in.width, in.height);
  return fmt::format("image is {}x{} px but the intrinsics are for {}x{} px (another resolution or a cropped photo)",
                     width, height, in.width, in.height);
}

BoardPose estimate_board_pose(const std::vector<Vec2>& uv, const std::vector<Vec3>& P, const CameraIntrinsics& in) {
  if (const auto bad = in.invalid_reason()) throw Error("board pose: intrinsics are " + *bad);
  if (uv.size() != P.size())
    throw MeasurementError(fmt::format("board pose: {} image points for {} board points", uv.size(), P.size()));
  const std::size_t n = uv.size();
  if (n < 4) throw MeasurementError(fmt::format("board pose: {} points, need at least 4", n));

  // Degeneracy: the board points must span a plane (two clearly non-zero principal extents).
  Vec3 mean = Vec3::Zero();
  for (const auto& p : P) mean += p;
  mean /= static_cast<double>(n);
  Mat3 scatter = Mat3::Zero();
  for (const auto& p : P) scatter += (p - mean) * (p - mean).transpose();
  const Vec3 ev = Eigen::SelfAdjointEigenSolver<Mat3>(scatter).eigenvalues();  // ascending
  if (!(ev[2] > 0.0) || ev[1] < 1e-6 * ev[2])
    throw MeasurementError(fmt::format("board pose: the {} board points are (nearly) collinear", n));
  const bool planar = ev[0] < 1e-12 * ev[2];

  std::vector<cv::Point3d> obj;
  std::vector<cv::Point2d> img;
  for (std::size_t i = 0; i < n; ++i) {
    obj.emplace_back(P[i].x(), P[i].y(), P[i].z());
    img.emplace_back(uv[i].x(), uv[i].y());
  }
  const cv::Mat K = camera_matrix(in), dist = distortion(in);
  cv::Mat rvec, tvec;
  // IPPE is exact for coplanar points (any plane; boards have z = 0) and returns the better of
  // the two planar-ambiguity solutions; SQPnP handles a general point set.
  const bool ippe = planar;
  bool ok = false;
  try {
    ok = cv::solvePnP(obj, img, K, dist, rvec, tvec, false, ippe ? cv::SOLVEPNP_IPPE : cv::SOLVEPNP_SQPNP);
  } catch (const cv::Exception& e) {
    throw MeasurementError(fmt::format("board pose: cv::solvePnP failed ({})", e.err));
  }
  if (!ok) throw MeasurementError("board pose: cv::solvePnP found no pose");
  cv::solvePnPRefineLM(obj, img, K, dist, rvec, tvec);

  BoardPose pose;
  Vec3 w, t;
  cv::cv2eigen(rvec.reshape(1, 3), w);
  cv::cv2eigen(tvec.reshape(1, 3), t);
  pose.R_camera_board = exp_so3(w);
  pose.t_camera_board = t;
  pose.points = n;
  if (!(t.z() > 0.0)) throw MeasurementError("board pose: the board lies behind the camera");

  const auto r = reprojection_residuals(uv, P, in, pose.R_camera_board, t);
  double ssr = 0.0;
  for (const auto& e : r) ssr += e.squaredNorm();
  pose.rms_px = std::sqrt(ssr / static_cast<double>(n));

  // Gauss–Newton covariance in (δ, t): ∂p/∂δ = −[R p_board]×, ∂p/∂t = I.
  Eigen::Matrix<double, 6, 6> JtJ = Eigen::Matrix<double, 6, 6>::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 Rp = pose.R_camera_board * P[i];
    const auto Jp = projection_jacobian(in, Rp + t);
    Eigen::Matrix<double, 2, 6> J;
    J.leftCols<3>() = -Jp * skew(Rp);
    J.rightCols<3>() = Jp;
    JtJ += J.transpose() * J;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> es(JtJ);
  if (!(es.eigenvalues()[0] > 1e-12 * es.eigenvalues()[5]))
    throw MeasurementError("board pose: the pose is not determined by these points (singular Jacobian)");
  // With exactly 4 points (2 redundant residuals) σ² is still defined; never divide by zero.
  const double dof = std::max<double>(2.0 * static_cast<double>(n) - 6.0, 1.0);
  pose.covariance = (ssr / dof) * JtJ.inverse();
  return pose;
}

std::vector<PhotoBoardPose> board_poses(const Capture& capture, const BoardSpec& board,
                                        const CameraIntrinsics& intrinsics, Diagnostics& diagnostics) {
  return board_poses(capture, board, intrinsics, diagnostics, DetectionOptions{});
}

namespace {

// Why a decoded photo cannot serve, or empty.
std::string decoded_photo_refusal(const io::Photo& photo, const CameraIntrinsics& in) {
  if (!photo.ok()) return photo.problem;
  if (photo.image.depth() != CV_8U) return "unsupported image (not 8 bits per channel)";
  return image_size_mismatch(photo.image.cols, photo.image.rows, in);
}

// The board's pose in one photo, or why there is none; `notes` gets the photo's warnings.
PhotoBoardPose board_pose_in_photo(const Capture& capture, std::size_t i, const BoardSpec& board,
                                   const DetectionOptions& options, std::vector<std::string>& notes) {
  const Shot& shot = capture.shots[i];
  PhotoBoardPose p{i, shot.t, shot.image, std::nullopt, {}, shot.extra, {}, {}};
  const auto file = capture.root / shot.image;
  // A header that claims another size is refused before its pixels are decoded (a false claim of
  // 30000×30000 px would otherwise be decoded into 900 MB).
  if (const io::PhotoHeader header = io::read_photo_header(file); header.ok())
    p.reason = image_size_mismatch(header.width_px, header.height_px, *options.intrinsics);
  io::Photo photo;
  if (p.reason.empty()) {
    photo = io::read_photo(file, cv::IMREAD_UNCHANGED);
    p.reason = decoded_photo_refusal(photo, *options.intrinsics);
  }
  if (p.reason.empty()) {
    const BoardDetection d = detect_board(photo.image, board, options);
    if (!d.found) {
      p.reason = d.reason;
    } else {
      if (!d.reason.empty()) notes.push_back(d.reason);
      try {
        p.pose = estimate_board_pose(d.image_points, d.object_points, *options.intrinsics);
        p.image_points_px = d.image_points;
        p.board_points_m = d.object_points;
      } catch (const MeasurementError& e) {
        p.reason = e.what();
      }
    }
  }
  if (!p.reason.empty()) notes.push_back("photo skipped: " + p.reason);
  return p;
}

}  // namespace

std::vector<PhotoBoardPose> board_poses(const Capture& capture, const BoardSpec& board,
                                        const CameraIntrinsics& intrinsics, Diagnostics& diagnostics,
                                        const DetectionOptions& options_in) {
  if (const auto bad = intrinsics.invalid_reason()) throw Error("board poses: intrinsics are " + *bad);
  DetectionOptions options = options_in;
  options.intrinsics = intrinsics;
  // Photos are independent: detected in parallel, their warnings then given in shot order.
  std::vector<PhotoBoardPose> out(capture.shots.size());
  std::vector<std::vector<std::string>> notes(capture.shots.size());
  tbb::parallel_for(std::size_t{0}, capture.shots.size(),
                    [&](std::size_t i) { out[i] = board_pose_in_photo(capture, i, board, options, notes[i]); });
  for (std::size_t i = 0; i < out.size(); ++i)
    for (auto& n : notes[i]) diagnostics.warn(capture.root / capture.shots[i].image, 0, std::move(n));
  return out;
}

}  // namespace antpose::camera
