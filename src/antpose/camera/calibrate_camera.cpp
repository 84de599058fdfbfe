#include "antpose/camera/calibrate_camera.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include <fmt/core.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgcodecs.hpp>
#include <yaml-cpp/yaml.h>

#include "antpose/camera/board_pose.hpp"
#include "antpose/io/text_file.hpp"
#include "antpose/io/yaml_util.hpp"
#include "antpose/io/photo_file.hpp"

namespace antpose::camera {
namespace fs = std::filesystem;

namespace {

// ---------------------------------------------------------------------------------------------
// Settings: OpenCV tutorial sample (FileStorage XML or YAML)

// Element access with messages "file: <Element> is 'x', expected ...". FileStorage gives no
// line numbers, so messages name the element.
class FsSettings {
 public:
  FsSettings(const cv::FileNode& node, fs::path file) : node_(node), file_(std::move(file)) {}

  bool has(const char* name) const { return !node_[name].empty() && !node_[name].isNone(); }

  [[noreturn]] void fail(const char* name, const std::string& value, const std::string& expected) const {
    throw InputError(file_, fmt::format("<{}> is {}, expected {}", name, value, expected));
  }

  std::string shown(const char* name) const {
    const cv::FileNode n = node_[name];
    if (n.isString()) return fmt::format("'{}'", static_cast<std::string>(n));
    if (n.isInt()) return fmt::format("{}", static_cast<int>(n));
    if (n.isReal()) return fmt::format("{}", static_cast<double>(n));
    if (n.isSeq()) return "a list";
    if (n.isMap()) return "a map";
    return "empty";
  }

  // Numbers may also come as strings (<X>"5"</X> in hand-written files).
  std::optional<double> number(const char* name) const {
    const cv::FileNode n = node_[name];
    if (n.isInt() || n.isReal()) return static_cast<double>(n);
    if (n.isString()) {
      const std::string s = static_cast<std::string>(n);
      try {
        std::size_t used = 0;
        const double v = std::stod(s, &used);
        if (used == s.size()) return v;
      } catch (const std::exception&) {
      }
    }
    return std::nullopt;
  }

  double real(const char* name, const std::string& expected) const {
    if (!has(name)) throw InputError(file_, fmt::format("<{}> is missing, expected {}", name, expected));
    const auto v = number(name);
    if (!v || !std::isfinite(*v)) fail(name, shown(name), expected);
    return *v;
  }

  int integer(const char* name, int lo, int hi, const std::string& what) const {
    const std::string expected = fmt::format("an integer from {} to {} ({})", lo, hi, what);
    const double v = real(name, expected);
    if (v != std::floor(v) || v < lo || v > hi) fail(name, shown(name), expected);
    return static_cast<int>(v);
  }

  bool flag(const char* name, bool fallback) const {
    if (!has(name)) return fallback;
    const auto v = number(name);
    if (!v || (*v != 0.0 && *v != 1.0)) fail(name, shown(name), "0 or 1");
    return *v != 0.0;
  }

  std::string text(const char* name, const std::string& expected) const {
    if (!has(name)) throw InputError(file_, fmt::format("<{}> is missing, expected {}", name, expected));
    if (!node_[name].isString()) fail(name, shown(name), expected);
    return static_cast<std::string>(node_[name]);
  }

  const fs::path& file() const { return file_; }

 private:
  cv::FileNode node_;
  fs::path file_;
};

// Square_Size of the tutorial is "in some user defined metric system"; ours is metres. A board
// square is between a millimetre and a metre, so a value above 1 is read as millimetres (the
// tutorial's defaults are 50 and 25), with a warning.
double square_in_metres(double v, const char* name, const fs::path& file, bool in_mm, Diagnostics& diagnostics) {
  if (in_mm) {
    diagnostics.warn(
        file, 0,
        fmt::format("<{}> {} read as millimetres (= {} m); give metres to avoid this guess", name, v, v / 1000.0));
    return v / 1000.0;
  }
  return v;
}

CalibrationSettings read_opencv_settings(const fs::path& file, Diagnostics& diagnostics) {
  cv::FileStorage storage;
  try {
    if (!storage.open(file.string(), cv::FileStorage::READ))
      throw InputError(file, "cannot open it as an OpenCV FileStorage (XML/YAML) settings file");
  } catch (const cv::Exception& e) {
    throw InputError(file, fmt::format("not a valid OpenCV FileStorage settings file ({})", e.err));
  }
  const cv::FileNode node = storage["Settings"];
  if (node.empty() || !node.isMap())
    throw InputError(file,
                     "no <Settings> element, expected the settings of OpenCV's camera calibration sample "
                     "(<opencv_storage><Settings>...</Settings></opencv_storage>)");
  const FsSettings s(node, file);
  CalibrationSettings out;
  out.board_source = file;

  BoardSpec b;
  b.cols = s.integer("BoardSize_Width", 2, 1000, "inner corners, circles or squares per row");
  b.rows = s.integer("BoardSize_Height", 2, 1000, "inner corners, circles or squares per column");
  const std::string pattern_expected =
      "\"CHESSBOARD\", \"CIRCLES_GRID\", \"ASYMMETRIC_CIRCLES_GRID\" or \"CHARUCOBOARD\"";
  const std::string pattern = s.text("Calibrate_Pattern", pattern_expected);
  if (pattern == "CHESSBOARD")
    b.type = BoardType::kChessboard;
  else if (pattern == "CIRCLES_GRID")
    b.type = BoardType::kCircles;
  else if (pattern == "ASYMMETRIC_CIRCLES_GRID")
    b.type = BoardType::kAsymmetricCircles;
  else if (pattern == "CHARUCOBOARD")
    b.type = BoardType::kCharuco;
  else
    s.fail("Calibrate_Pattern", s.shown("Calibrate_Pattern"), pattern_expected);
  if (b.type == BoardType::kCharuco && (b.cols < 3 || b.rows < 3))
    throw InputError(file, fmt::format("<BoardSize_Width>x<BoardSize_Height> is {}x{}, expected at least 3x3 squares "
                                       "for a ChArUco board",
                                       b.cols, b.rows));
  const std::string square_expected = "a positive square side (metres; a value above 1 is read as millimetres)";
  const double square = s.real("Square_Size", square_expected);
  if (!(square > 0.0) || square > 10000.0) s.fail("Square_Size", s.shown("Square_Size"), square_expected);
  const bool in_mm = square > 1.0;
  b.square_m = square_in_metres(square, "Square_Size", file, in_mm, diagnostics);
  if (b.type == BoardType::kCharuco) {
    const double marker = s.real("Marker_Size", "the ArUco marker side, in the unit of <Square_Size>");
    if (!(marker > 0.0 && marker < square))
      s.fail("Marker_Size", s.shown("Marker_Size"),
             fmt::format("a marker side between 0 and <Square_Size> = {}", square));
    b.marker_m = in_mm ? marker / 1000.0 : marker;
    b.dictionary = s.text("ArUco_Dict_Name", "an OpenCV ArUco dictionary name such as \"DICT_6X6_250\"");
    if (aruco_dictionary_id(b.dictionary) < 0)
      s.fail("ArUco_Dict_Name", s.shown("ArUco_Dict_Name"), "an OpenCV ArUco dictionary name such as \"DICT_6X6_250\"");
  }
  out.board = b;

  out.flip_vertical = s.flag("Input_FlipAroundHorizontalAxis", false);
  if (s.has("Calibrate_NrOfFrameToUse"))
    out.max_images = s.integer("Calibrate_NrOfFrameToUse", 1, 100000, "the number of photos to calibrate with");
  if (s.has("Calibrate_FixAspectRatio")) {
    const std::string expected = "0 (fx, fy free) or the fixed ratio fx/fy between 0.1 and 10";
    const double ratio = s.real("Calibrate_FixAspectRatio", expected);
    if (ratio != 0.0 && !(ratio >= 0.1 && ratio <= 10.0))
      s.fail("Calibrate_FixAspectRatio", s.shown("Calibrate_FixAspectRatio"), expected);
    out.fix_aspect_ratio = ratio != 0.0;
    if (out.fix_aspect_ratio) out.aspect_ratio = ratio;
  }
  out.zero_tangent = s.flag("Calibrate_AssumeZeroTangentialDistortion", false);
  out.fix_principal_point = s.flag("Calibrate_FixPrincipalPointAtTheCenter", false);
  if (s.flag("Calibrate_UseFisheyeModel", false))
    throw InputError(file,
                     "<Calibrate_UseFisheyeModel> is 1, but antpose models phone lenses with OpenCV's "
                     "5-coefficient (k1, k2, p1, p2, k3) model; expected 0");
  const bool k1 = s.flag("Fix_K1", false), k2 = s.flag("Fix_K2", false), k3 = s.flag("Fix_K3", false);
  s.flag("Fix_K4", true);  // rational-model coefficients: not estimated in the 5-coefficient model
  s.flag("Fix_K5", true);
  out.fix_k = {k1, k2, k3};
  // Checked, then ignored: the capture supplies the photos, -o names the output.
  if (s.has("Input") && !node["Input"].isString() && !node["Input"].isInt())
    s.fail("Input", s.shown("Input"), "a camera id, video or image-list file name");
  if (s.has("Input_Delay")) s.integer("Input_Delay", 0, 1000000, "ms between frames");
  for (const char* name :
       {"Write_DetectedFeaturePoints", "Write_extrinsicParameters", "Write_gridPoints", "Show_UndistortedImage"})
    s.flag(name, false);
  if (s.has("Write_outputFileName")) s.text("Write_outputFileName", "a file name");
  return out;
}

// ---------------------------------------------------------------------------------------------
// Settings: our YAML config

bool yaml_bool(const YAML::Node& n, const fs::path& file, const std::string& key) {
  if (n.IsScalar()) {
    const std::string v = n.Scalar();
    if (v == "true" || v == "yes" || v == "1") return true;
    if (v == "false" || v == "no" || v == "0") return false;
  }
  throw InputError(file, io::line_of(n), fmt::format("{} is {}, expected true or false", key, io::show(n)));
}

void check_keys(const YAML::Node& map, const std::set<std::string>& known, const fs::path& file,
                const std::string& where) {
  for (const auto& kv : map) {
    if (!kv.first.IsScalar())
      throw InputError(
          file, io::line_of(kv.first),
          fmt::format("a key{} is {}, expected a name",
                      where.empty() ? "" : " in '" + where.substr(0, where.size() - 1) + "'", io::show(kv.first)));
    const std::string key = kv.first.Scalar();
    if (!known.count(key)) {
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      throw InputError(file, io::line_of(kv.first),
                       fmt::format("unknown key '{}{}', expected one of {}", where, key, list));
    }
  }
}

CalibrationSettings read_yaml_settings(const fs::path& file, const std::string& text, Diagnostics& diagnostics) {
  const YAML::Node d = io::load_yaml(text, file);
  if (!d.IsMap())
    throw InputError(file,
                     "expected a YAML map of calibration settings (board, fix_aspect_ratio, ...) or an OpenCV "
                     "<opencv_storage><Settings> file");
  check_keys(d,
             {"board", "fix_aspect_ratio", "zero_tangent_distortion", "fix_principal_point", "distortion_coefficients",
              "intrinsics_guess", "flip_vertical", "max_images", "detection", "robust"},
             file, "");
  CalibrationSettings s;
  s.board_source = file;
  if (const YAML::Node b = d["board"]) {
    if (!b.IsMap())
      throw InputError(file, io::line_of(b), "board is " + io::show(b) + ", expected a map as board.yaml");
    try {
      s.board = parse_board(YAML::Dump(b), file);
    } catch (const InputError& e) {
      // The board's own lines are relative to the dumped map; name the key path instead.
      throw InputError(file, io::line_of(b), "board: " + e.detail());
    }
  }
  if (const YAML::Node n = d["fix_aspect_ratio"]) {
    if (n.IsScalar() && (n.Scalar() == "true" || n.Scalar() == "false")) {
      s.fix_aspect_ratio = n.Scalar() == "true";
    } else {
      const double r = io::yaml_number(n, file, "fix_aspect_ratio");
      if (!(r >= 0.1 && r <= 10.0))
        throw InputError(file, io::line_of(n),
                         fmt::format("fix_aspect_ratio is {}, expected true/false or the ratio fx/fy (0.1 to 10)", r));
      s.fix_aspect_ratio = true;
      s.aspect_ratio = r;
    }
  }
  if (const YAML::Node n = d["zero_tangent_distortion"]) s.zero_tangent = yaml_bool(n, file, "zero_tangent_distortion");
  if (const YAML::Node n = d["fix_principal_point"]) s.fix_principal_point = yaml_bool(n, file, "fix_principal_point");
  if (const YAML::Node n = d["flip_vertical"]) s.flip_vertical = yaml_bool(n, file, "flip_vertical");
  if (const YAML::Node n = d["distortion_coefficients"]) {
    const long long c = io::yaml_integer(n, file, "distortion_coefficients");
    if (c != 1 && c != 2 && c != 4 && c != 5)
      throw InputError(file, io::line_of(n),
                       fmt::format("distortion_coefficients is {}, expected 5 (k1 k2 p1 p2 k3), 4 (k3 = 0), 2 (k1 k2) "
                                   "or 1 (k1)",
                                   c));
    s.distortion_coefficients = static_cast<int>(c);
  }
  if (const YAML::Node n = d["max_images"]) {
    const long long c = io::yaml_integer(n, file, "max_images");
    if (c < 0) throw InputError(file, io::line_of(n), fmt::format("max_images is {}, expected 0 (all) or more", c));
    s.max_images = static_cast<int>(c);
  }
  if (const YAML::Node n = d["intrinsics_guess"]) {
    fs::path guess = io::yaml_string(n, file, "intrinsics_guess");
    if (guess.is_relative()) guess = file.parent_path() / guess;
    s.intrinsics_guess = read_camera_file(guess).intrinsics;
  }
  if (const YAML::Node det = d["detection"]) {
    if (!det.IsMap()) throw InputError(file, io::line_of(det), "detection is " + io::show(det) + ", expected a map");
    check_keys(
        det,
        {"adaptive_threshold", "normalize_image", "fast_check", "filter_quads", "subpix_window", "subpix_iterations",
         "subpix_epsilon", "min_laplacian_variance", "border_margin_px", "charuco_min_corners", "charuco_camera_pass"},
        file, "detection.");
    auto& o = s.detection;
    auto flag = [&](const char* k, bool& v) {
      if (const YAML::Node n = det[k]) v = yaml_bool(n, file, std::string("detection.") + k);
    };
    auto integer = [&](const char* k, int& v, int lo, int hi) {
      if (const YAML::Node n = det[k]) {
        const long long x = io::yaml_integer(n, file, std::string("detection.") + k);
        if (x < lo || x > hi)
          throw InputError(file, io::line_of(n),
                           fmt::format("detection.{} is {}, expected an integer from {} to {}", k, x, lo, hi));
        v = static_cast<int>(x);
      }
    };
    auto real = [&](const char* k, double& v, double lo, double hi) {
      if (const YAML::Node n = det[k]) {
        const double x = io::yaml_number(n, file, std::string("detection.") + k);
        if (!(x >= lo && x <= hi))
          throw InputError(file, io::line_of(n), fmt::format("detection.{} is {}, expected {} to {}", k, x, lo, hi));
        v = x;
      }
    };
    flag("adaptive_threshold", o.adaptive_threshold);
    flag("normalize_image", o.normalize_image);
    flag("fast_check", o.fast_check);
    flag("filter_quads", o.filter_quads);
    flag("charuco_camera_pass", o.charuco_camera_pass);
    integer("subpix_window", o.subpix_window, 1, 100);
    integer("subpix_iterations", o.subpix_iterations, 1, 1000);
    integer("charuco_min_corners", o.charuco_min_corners, 4, 100000);
    real("subpix_epsilon", o.subpix_epsilon, 1e-9, 10.0);
    real("min_laplacian_variance", o.min_laplacian_variance, 0.0, 1e9);
    real("border_margin_px", o.border_margin_px, 0.0, 1000.0);
  }
  if (const YAML::Node r = d["robust"]) {
    if (!r.IsMap()) throw InputError(file, io::line_of(r), "robust is " + io::show(r) + ", expected a map");
    check_keys(r, {"outlier_factor", "outlier_min_px", "min_images"}, file, "robust.");
    if (const YAML::Node n = r["outlier_factor"]) {
      s.outlier_factor = io::yaml_number(n, file, "robust.outlier_factor");
      if (!(s.outlier_factor >= 1.0))
        throw InputError(file, io::line_of(n),
                         fmt::format("robust.outlier_factor is {}, expected a factor ≥ 1", s.outlier_factor));
    }
    if (const YAML::Node n = r["outlier_min_px"]) {
      s.outlier_min_px = io::yaml_number(n, file, "robust.outlier_min_px");
      if (!(s.outlier_min_px >= 0.0))
        throw InputError(file, io::line_of(n),
                         fmt::format("robust.outlier_min_px is {}, expected a distance ≥ 0 px", s.outlier_min_px));
    }
    if (const YAML::Node n = r["min_images"]) {
      const long long m = io::yaml_integer(n, file, "robust.min_images");
      if (m < 3 || m > 100000)
        throw InputError(file, io::line_of(n),
                         fmt::format("robust.min_images is {}, expected at least 3 (Zhang's method needs 3 views "
                                     "of a plane for the 5 intrinsics without fixed parameters)",
                                     m));
      s.min_images = static_cast<int>(m);
    }
  }
  (void)diagnostics;
  return s;
}

// ---------------------------------------------------------------------------------------------
// Solver

struct FlagSet {
  int flags = 0;
  std::vector<std::string> names;
  void add(int f, const char* name) {
    if (flags & f) return;
    flags |= f;
    names.emplace_back(name);
  }
};

FlagSet make_flags(const CalibrationSettings& s) {
  FlagSet f;
  if (s.intrinsics_guess) f.add(cv::CALIB_USE_INTRINSIC_GUESS, "CALIB_USE_INTRINSIC_GUESS");
  if (s.fix_aspect_ratio) f.add(cv::CALIB_FIX_ASPECT_RATIO, "CALIB_FIX_ASPECT_RATIO");
  if (s.fix_principal_point) f.add(cv::CALIB_FIX_PRINCIPAL_POINT, "CALIB_FIX_PRINCIPAL_POINT");
  if (s.zero_tangent || s.distortion_coefficients <= 2) f.add(cv::CALIB_ZERO_TANGENT_DIST, "CALIB_ZERO_TANGENT_DIST");
  if (s.fix_k[0]) f.add(cv::CALIB_FIX_K1, "CALIB_FIX_K1");
  if (s.fix_k[1] || s.distortion_coefficients <= 1) f.add(cv::CALIB_FIX_K2, "CALIB_FIX_K2");
  if (s.fix_k[2] || s.distortion_coefficients <= 4) f.add(cv::CALIB_FIX_K3, "CALIB_FIX_K3");
  return f;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::string list_reasons(const std::vector<CalibrationImage>& images) {
  std::string s;
  for (const auto& im : images)
    if (!im.used && !im.reason.empty()) s += fmt::format("\n  {}: {}", im.image, im.reason);
  return s;
}

}  // namespace

// ---------------------------------------------------------------------------------------------

CalibrationSettings read_calibration_settings(const fs::path& file, Diagnostics& diagnostics) {
  const std::string text = io::read_text(file);
  const auto first = text.find_first_not_of(" \t\r\n\xEF\xBB\xBF");
  const bool opencv = text.find("<opencv_storage") != std::string::npos ||
                      (first != std::string::npos && text.compare(first, 5, "%YAML") == 0) ||
                      (first != std::string::npos && text.compare(first, 5, "<?xml") == 0);
  return opencv ? read_opencv_settings(file, diagnostics) : read_yaml_settings(file, text, diagnostics);
}

std::size_t CameraCalibrationResult::used_count() const {
  return static_cast<std::size_t>(std::count_if(images.begin(), images.end(), [](const auto& i) { return i.used; }));
}

std::vector<std::pair<std::string, std::string>> CameraCalibrationResult::rejected() const {
  std::vector<std::pair<std::string, std::string>> r;
  for (const auto& im : images)
    if (!im.used) r.emplace_back(im.image, im.reason);
  return r;
}

CameraCalibrationResult calibrate_views(const std::vector<CalibrationView>& views, int width, int height,
                                        const CalibrationSettings& settings, std::vector<CalibrationImage> images) {
  if (width <= 0 || height <= 0) throw Error("calibrate_views: image size must be positive");
  if (images.empty()) {
    for (std::size_t i = 0; i < views.size(); ++i) {
      CalibrationImage im;
      im.shot_index = i;
      im.image = views[i].name;
      images.push_back(im);
    }
  }
  if (images.size() != views.size()) throw Error("calibrate_views: one CalibrationImage per view expected");
  CameraCalibrationResult result;
  const FlagSet flags = make_flags(settings);
  result.flags = flags.flags;
  result.flag_names = flags.names;
  if (settings.board) result.board = *settings.board;

  // Views that can take part: enough points; then at most max_images of them, in order.
  std::vector<bool> active(views.size(), false);
  int taken = 0;
  for (std::size_t i = 0; i < views.size(); ++i) {
    auto& im = images[i];
    im.points = views[i].image_points.size();
    if (views[i].image_points.size() != views[i].object_points.size())
      throw Error("calibrate_views: image and object point counts differ");
    if (im.points == 0) {
      if (im.reason.empty()) im.reason = "no board found";
      continue;
    }
    if (im.points < 4) {
      im.reason = fmt::format("only {} points (need at least 4)", im.points);
      continue;
    }
    if (settings.max_images > 0 && taken >= settings.max_images) {
      im.reason = fmt::format(
          "not used: the first {} usable photos were enough (max_images / "
          "Calibrate_NrOfFrameToUse)",
          settings.max_images);
      continue;
    }
    active[i] = true;
    ++taken;
  }

  cv::Mat K = cv::Mat::eye(3, 3, CV_64F), D = cv::Mat::zeros(5, 1, CV_64F);
  if (settings.intrinsics_guess) {
    const auto& g = *settings.intrinsics_guess;
    if (g.width != width || g.height != height)
      throw InputError(fs::path(), fmt::format("the intrinsics guess is for {}x{} px but the photos are {}x{} px",
                                               g.width, g.height, width, height));
    cv::eigen2cv(Mat3(g.K()), K);
    for (int k = 0; k < 5; ++k) D.at<double>(k) = g.distortion[static_cast<std::size_t>(k)];
  } else if (settings.fix_aspect_ratio) {
    // Without a guess OpenCV reads only the ratio fx/fy from the matrix (as the samples set it).
    K.at<double>(0, 0) = settings.aspect_ratio;
  }
  const cv::Mat K0 = K.clone(), D0 = D.clone();

  for (int round = 1;; ++round) {
    std::vector<std::size_t> idx;
    for (std::size_t i = 0; i < views.size(); ++i)
      if (active[i]) idx.push_back(i);
    if (static_cast<int>(idx.size()) < settings.min_images)
      throw MeasurementError(fmt::format("camera calibration: {} usable photo{} (need at least {}); refused:{}",
                                         idx.size(), idx.size() == 1 ? "" : "s", settings.min_images,
                                         list_reasons(images)));
    std::vector<std::vector<cv::Point3f>> obj;
    std::vector<std::vector<cv::Point2f>> img;
    for (std::size_t i : idx) {
      auto& o = obj.emplace_back();
      auto& p = img.emplace_back();
      for (const auto& P : views[i].object_points)
        o.emplace_back(static_cast<float>(P.x()), static_cast<float>(P.y()), static_cast<float>(P.z()));
      for (const auto& u : views[i].image_points) p.emplace_back(static_cast<float>(u.x()), static_cast<float>(u.y()));
    }
    K = K0.clone();
    D = D0.clone();
    std::vector<cv::Mat> rvecs, tvecs;
    cv::Mat sd_intr, sd_extr, per_view;
    double rms = 0.0;
    try {
      rms = cv::calibrateCamera(obj, img, cv::Size(width, height), K, D, rvecs, tvecs, sd_intr, sd_extr, per_view,
                                flags.flags);
    } catch (const cv::Exception& e) {
      throw MeasurementError(fmt::format("camera calibration: cv::calibrateCamera failed: {}", e.err));
    }
    result.rounds = round;
    result.rms_px = rms;
    CameraIntrinsics& in = result.intrinsics;
    in.width = width;
    in.height = height;
    in.fx = K.at<double>(0, 0);
    in.fy = K.at<double>(1, 1);
    in.cx = K.at<double>(0, 2);
    in.cy = K.at<double>(1, 2);
    for (int k = 0; k < 5; ++k) in.distortion[static_cast<std::size_t>(k)] = D.at<double>(k);
    if (const auto bad = in.invalid_reason(); bad || !std::isfinite(rms))
      throw MeasurementError(fmt::format("camera calibration diverged: {}", bad ? *bad : "RMS is not finite"));
    auto sd = [&](int k) { return sd_intr.total() > static_cast<std::size_t>(k) ? sd_intr.at<double>(k) : 0.0; };
    result.sigma = {sd(0), sd(1), sd(2), sd(3), {sd(4), sd(5), sd(6), sd(7), sd(8)}};

    std::vector<double> errs;
    for (std::size_t j = 0; j < idx.size(); ++j) {
      auto& im = images[idx[j]];
      im.used = true;
      im.rms_px = per_view.at<double>(static_cast<int>(j));
      errs.push_back(*im.rms_px);
      for (int k = 0; k < 3; ++k) {
        im.rvec[k] = rvecs[j].at<double>(k);
        im.tvec[k] = tvecs[j].at<double>(k);
      }
    }
    const double med = median(errs);
    const double limit = std::max(settings.outlier_factor * med, settings.outlier_min_px);
    std::vector<std::size_t> outliers;
    for (std::size_t j = 0; j < idx.size(); ++j)
      if (errs[j] > limit) outliers.push_back(idx[j]);
    if (outliers.empty()) break;
    for (std::size_t i : outliers) {
      active[i] = false;
      auto& im = images[i];
      im.used = false;
      im.reason = fmt::format(
          "reprojection outlier: RMS {:.3f} px > {:.3f} px (max of {:g} × median {:.3f} px and "
          "{:g} px)",
          *im.rms_px, limit, settings.outlier_factor, med, settings.outlier_min_px);
    }
    if (round >= 10) throw MeasurementError("camera calibration: outlier rejection did not settle in 10 rounds");
  }
  result.images = std::move(images);
  return result;
}

CameraCalibrationResult calibrate_camera(const Capture& capture, const CalibrationSettings& settings,
                                         Diagnostics& diagnostics, const CalibrationProgress& progress) {
  // Board: the config's wins over board.yaml (the user chose the config for this run).
  std::optional<BoardSpec> board_file;
  const fs::path board_path = capture_file(capture.root, "board.yaml");
  if (fs::exists(board_path)) board_file = read_board(board_path);
  BoardSpec board;
  if (settings.board) {
    board = *settings.board;
    if (board_file && format_board(*board_file) != format_board(board))
      diagnostics.warn(
          settings.board_source, 0,
          fmt::format("the settings' board ({} {}x{}, square {} m) differs from {} ({} {}x{}, square {} "
                      "m); using the settings' board",
                      to_string(board.type), board.cols, board.rows, board.square_m, board_path.string(),
                      to_string(board_file->type), board_file->cols, board_file->rows, board_file->square_m));
  } else if (board_file) {
    board = *board_file;
  } else {
    throw InputError(board_path, "missing: the capture has no board.yaml and the settings name no board");
  }
  if (capture.shots.empty()) throw InputError(capture.root / "shots.csv", "no photos listed");

  CalibrationSettings s = settings;
  s.board = board;
  DetectionOptions detection = s.detection;
  if (s.intrinsics_guess && !detection.intrinsics) detection.intrinsics = s.intrinsics_guess;

  // One detection pass over all photos; warnings and progress only when asked (final pass).
  std::vector<CalibrationView> views;
  std::vector<CalibrationImage> images;
  // One camera mode per calibration: the size most photos' headers give (else the first decoded).
  const std::vector<io::PhotoHeader> headers = io::read_photo_headers(capture);
  const std::optional<cv::Size> common_size = io::common_photo_size(headers);
  int width = 0, height = 0;
  auto detect_all = [&](const DetectionOptions& options, Diagnostics* warn, const CalibrationProgress* report) {
    views.clear();
    images.clear();
    width = common_size ? common_size->width : 0;
    height = common_size ? common_size->height : 0;
    bool any_read = false;
    for (std::size_t i = 0; i < capture.shots.size(); ++i) {
      const Shot& shot = capture.shots[i];
      const fs::path file = capture.root / shot.image;
      CalibrationImage im;
      im.shot_index = i;
      im.image = shot.image;
      CalibrationView view;
      view.name = shot.image;
      const io::PhotoHeader& header = headers[i];
      const bool other_size = common_size && header.ok() && cv::Size(header.width_px, header.height_px) != *common_size;
      io::Photo photo = other_size ? io::Photo{} : io::read_photo(file, cv::IMREAD_UNCHANGED);
      cv::Mat image = std::move(photo.image);
      if (other_size) {
        im.reason = fmt::format("image is {}x{} px, most photos are {}x{} px (one camera mode per calibration)",
                                header.width_px, header.height_px, width, height);
      } else if (!photo.ok()) {
        im.reason = photo.problem;
      } else if (image.depth() != CV_8U) {
        im.reason = "unsupported image (not 8 bits per channel)";
      } else {
        any_read = true;
        if (width == 0) {
          width = image.cols;
          height = image.rows;
        }
        if (image.cols != width || image.rows != height) {
          im.reason = fmt::format("image is {}x{} px, most photos are {}x{} px (one camera mode per calibration)",
                                  image.cols, image.rows, width, height);
        } else {
          if (s.flip_vertical) cv::flip(image, image, 0);
          const BoardDetection d = detect_board(image, board, options);
          im.reason = d.reason;
          if (d.found) {
            view.image_points = d.image_points;
            view.object_points = d.object_points;
            im.points = d.image_points.size();
          }
        }
      }
      if (warn && !im.reason.empty())
        warn->warn(file, 0, (view.image_points.empty() ? "photo refused: " : "photo used, but ") + im.reason);
      if (report && *report) (*report)(im, i + 1, capture.shots.size());
      views.push_back(std::move(view));
      images.push_back(std::move(im));
    }
    if (!any_read)
      throw MeasurementError(fmt::format("camera calibration: none of the {} photos could be read{}", images.size(),
                                         list_reasons(images)));
  };

  // ChArUco without known intrinsics: as OpenCV's ChArUco calibration sample, calibrate once
  // with the corners interpolated from the markers' local homographies, then interpolate again
  // with that camera (corners next to missed markers, and lens distortion taken into account)
  // and calibrate on those. Skipping the second pass moves fx by ~4 px on the tutorial images.
  if (board.type == BoardType::kCharuco && detection.charuco_camera_pass && !detection.intrinsics) {
    detect_all(detection, nullptr, &progress);
    CalibrationSettings first = s;
    first.outlier_factor = std::numeric_limits<double>::infinity();  // outliers: judged in the final pass
    detection.intrinsics = calibrate_views(views, width, height, first, images).intrinsics;
    detect_all(detection, &diagnostics, nullptr);
  } else {
    detect_all(detection, &diagnostics, &progress);
  }
  CameraCalibrationResult result = calibrate_views(views, width, height, s, std::move(images));
  for (const auto& im : result.images)
    if (!im.used && im.reason.rfind("reprojection outlier", 0) == 0)
      diagnostics.warn(capture.root / im.image, 0, "photo refused: " + im.reason);
  return result;
}

CameraCalibrationResult calibrate_camera(const fs::path& folder, const CalibrationSettings& settings,
                                         Diagnostics& diagnostics, const CalibrationProgress& progress) {
  return calibrate_camera(read_capture(folder, diagnostics), settings, diagnostics, progress);
}

ProfileCamera profile_camera(const CameraCalibrationResult& r) {
  return {r.intrinsics, r.rms_px, Vec2(r.sigma.cx, r.sigma.cy)};
}

std::string describe(const CameraCalibrationResult& r) {
  std::string s = fmt::format("{:<28} {:>6}  {}\n", "image", "points", "RMS px / reason");
  for (const auto& im : r.images) {
    std::string what;
    if (im.used)
      what = fmt::format("{:.4f}", im.rms_px.value_or(0.0));
    else
      what = "refused: " + im.reason;
    if (im.used && !im.reason.empty()) what += "  (" + im.reason + ")";
    s += fmt::format("{:<28} {:>6}  {}\n", im.image, im.points, what);
  }
  const auto& in = r.intrinsics;
  const auto& sg = r.sigma;
  std::string flags;
  for (const auto& n : r.flag_names) flags += (flags.empty() ? "" : " + ") + n;
  s += fmt::format("{} of {} photos used, {} calibration round{}, flags {}\n", r.used_count(), r.images.size(),
                   r.rounds, r.rounds == 1 ? "" : "s", flags.empty() ? "none" : flags);
  s += fmt::format("image {}x{} px\n", in.width, in.height);
  s += fmt::format("fx = {:.4f} ± {:.4f} px   fy = {:.4f} ± {:.4f} px\n", in.fx, sg.fx, in.fy, sg.fy);
  s += fmt::format("cx = {:.4f} ± {:.4f} px   cy = {:.4f} ± {:.4f} px\n", in.cx, sg.cx, in.cy, sg.cy);
  const char* names[5] = {"k1", "k2", "p1", "p2", "k3"};
  for (int k = 0; k < 5; ++k)
    s += fmt::format("{} = {:.6g} ± {:.3g}{}", names[k], in.distortion[static_cast<std::size_t>(k)],
                     sg.distortion[static_cast<std::size_t>(k)], k == 4 ? "\n" : "   ");
  s += fmt::format("RMS reprojection error {:.4f} px\n", r.rms_px);
  return s;
}

}  // namespace antpose::camera
