// The OpenCV FileStorage camera file (calibrate_camera.hpp): written from a calibration, read back
// with every field checked.
#include "antpose/camera/calibrate_camera.hpp"

#include <ctime>

#include <fmt/core.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/core/eigen.hpp>

#include "antpose/io/text_file.hpp"

namespace antpose::camera {
namespace fs = std::filesystem;

std::string format_camera_file(const CameraCalibrationResult& r) {
  cv::FileStorage out(".yaml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY);
  char when[128] = {};
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  std::strftime(when, sizeof when, "%a %d %b %Y %H:%M:%S UTC", &tm);
  std::vector<std::size_t> used;
  for (std::size_t i = 0; i < r.images.size(); ++i)
    if (r.images[i].used) used.push_back(i);
  out << "calibration_time" << when;
  out << "nr_of_frames" << static_cast<int>(used.size());
  out << "image_width" << r.intrinsics.width;
  out << "image_height" << r.intrinsics.height;
  out << "board_width" << r.board.cols;
  out << "board_height" << r.board.rows;
  out << "square_size" << r.board.square_m;
  out << "board_type" << to_string(r.board.type);
  if (r.board.type == BoardType::kCharuco) {
    out << "marker_size" << r.board.marker_m;
    out << "aruco_dictionary" << r.board.dictionary;
  }
  if (r.flags & cv::CALIB_FIX_ASPECT_RATIO) out << "fix_aspect_ratio" << r.intrinsics.fx / r.intrinsics.fy;
  std::string names;
  for (const auto& n : r.flag_names) names += (names.empty() ? "" : " + ") + n;
  out.writeComment("flags: " + (names.empty() ? std::string("none") : names));
  out << "flags" << r.flags;
  cv::Mat K;
  cv::eigen2cv(Mat3(r.intrinsics.K()), K);
  out << "camera_matrix" << K;
  cv::Mat D(5, 1, CV_64F);
  for (int k = 0; k < 5; ++k) D.at<double>(k) = r.intrinsics.distortion[static_cast<std::size_t>(k)];
  out << "distortion_coefficients" << D;
  out << "avg_reprojection_error" << r.rms_px;
  cv::Mat per_view(static_cast<int>(used.size()), 1, CV_64F), extr(static_cast<int>(used.size()), 6, CV_64F);
  for (std::size_t j = 0; j < used.size(); ++j) {
    const auto& im = r.images[used[j]];
    per_view.at<double>(static_cast<int>(j)) = im.rms_px.value_or(0.0);
    for (int k = 0; k < 3; ++k) {
      extr.at<double>(static_cast<int>(j), k) = im.rvec[k];
      extr.at<double>(static_cast<int>(j), 3 + k) = im.tvec[k];
    }
  }
  if (!used.empty()) {
    out << "per_view_reprojection_errors" << per_view;
    out.writeComment("a set of 6-tuples (rotation vector + translation vector) for each view");
    out << "extrinsic_parameters" << extr;
  }
  out << "images"
      << "[";
  for (std::size_t i : used) out << r.images[i].image;
  out << "]";
  cv::Mat sd_k = (cv::Mat_<double>(4, 1) << r.sigma.fx, r.sigma.fy, r.sigma.cx, r.sigma.cy);
  cv::Mat sd_d(5, 1, CV_64F);
  for (int k = 0; k < 5; ++k) sd_d.at<double>(k) = r.sigma.distortion[static_cast<std::size_t>(k)];
  out.writeComment("1-sigma standard deviations from calibrateCameraExtended: fx, fy, cx, cy; k1, k2, p1, p2, k3");
  out << "camera_matrix_std_dev" << sd_k;
  out << "distortion_coefficients_std_dev" << sd_d;
  out << "rejected_images"
      << "[";
  for (const auto& im : r.images)
    if (!im.used)
      out << "{"
          << "image" << im.image << "reason" << im.reason << "}";
  out << "]";
  return out.releaseAndGetString();
}

void write_camera_file(const fs::path& file, const CameraCalibrationResult& result, bool force) {
  if (!force && fs::exists(file)) throw InputError(file, "exists already; pass --force to replace it");
  io::write_text_atomic(file, format_camera_file(result));
}

CameraFile read_camera_file(const fs::path& file) {
  if (!fs::exists(file)) throw InputError(file, "camera file not found");
  cv::FileStorage in;
  try {
    if (!in.open(file.string(), cv::FileStorage::READ))
      throw InputError(file, "cannot open it as an OpenCV FileStorage (YAML/XML) camera file");
  } catch (const cv::Exception& e) {
    throw InputError(file, fmt::format("not a valid OpenCV FileStorage camera file ({})", e.err));
  }
  CameraFile c;
  auto integer = [&](const char* name) {
    const cv::FileNode n = in[name];
    if (n.empty() || !n.isInt())
      throw InputError(file, fmt::format("{} is {}, expected a positive integer (pixels)", name,
                                         n.empty() ? "missing" : "not an integer"));
    const int v = static_cast<int>(n);
    if (v <= 0 || v > 100000)
      throw InputError(file, fmt::format("{} is {}, expected a positive number of pixels", name, v));
    return v;
  };
  c.intrinsics.width = integer("image_width");
  c.intrinsics.height = integer("image_height");
  cv::Mat K, D;
  try {
    in["camera_matrix"] >> K;
    in["distortion_coefficients"] >> D;
  } catch (const cv::Exception& e) {
    throw InputError(file, fmt::format("camera_matrix / distortion_coefficients unreadable ({})", e.err));
  }
  if (K.rows != 3 || K.cols != 3)
    throw InputError(file, fmt::format("camera_matrix is {}, expected a 3x3 !!opencv-matrix",
                                       K.empty() ? std::string("missing") : fmt::format("{}x{}", K.rows, K.cols)));
  K.convertTo(K, CV_64F);
  if (K.at<double>(0, 1) != 0.0 || K.at<double>(1, 0) != 0.0 || K.at<double>(2, 0) != 0.0 ||
      K.at<double>(2, 1) != 0.0 || K.at<double>(2, 2) != 1.0)
    throw InputError(file, "camera_matrix is not of the form [fx 0 cx; 0 fy cy; 0 0 1] (skew is not supported)");
  c.intrinsics.fx = K.at<double>(0, 0);
  c.intrinsics.fy = K.at<double>(1, 1);
  c.intrinsics.cx = K.at<double>(0, 2);
  c.intrinsics.cy = K.at<double>(1, 2);
  if (D.empty()) throw InputError(file, "distortion_coefficients is missing, expected 4 or 5 numbers");
  D.convertTo(D, CV_64F);
  const std::size_t nd = D.total();
  if (nd != 4 && nd != 5 && nd != 8 && nd != 12 && nd != 14)
    throw InputError(file, fmt::format("distortion_coefficients has {} entries, expected 4, 5, 8, 12 or 14", nd));
  for (std::size_t k = 0; k < nd; ++k) {
    const double v = D.at<double>(static_cast<int>(k));
    if (k < 5)
      c.intrinsics.distortion[k] = v;
    else if (v != 0.0)
      throw InputError(file, fmt::format("distortion_coefficients[{}] is {}, but antpose uses the 5-coefficient model "
                                         "(k1, k2, p1, p2, k3); expected 0",
                                         k, v));
  }
  if (const auto bad = c.intrinsics.invalid_reason()) throw InputError(file, "invalid intrinsics: " + *bad);
  if (const cv::FileNode e = in["avg_reprojection_error"]; !e.empty() && (e.isReal() || e.isInt()))
    c.rms_px = static_cast<double>(e);
  if (const cv::FileNode n = in["camera_matrix_std_dev"]; !n.empty()) {
    cv::Mat sd;
    n >> sd;
    if (sd.total() == 4 && sd.type() == CV_64F && sd.at<double>(2) >= 0 && sd.at<double>(3) >= 0)
      c.principal_point_sigma_px = Vec2(sd.at<double>(2), sd.at<double>(3));
  }
  return c;
}

}  // namespace antpose::camera
