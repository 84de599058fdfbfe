#include "antpose/measure/non_contact.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <tuple>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "antpose/camera/board_pose.hpp"
#include "antpose/model/sampling.hpp"
#include "antpose/orientation/estimator.hpp"

namespace antpose::measure {
namespace {
namespace fs = std::filesystem;
using reconstruction::PosedView;

void report(const NonContactOptions& options, const std::string& stage, int done, int total) {
  if (options.progress) options.progress(stage, done, total);
}

// The shot an ROI names: its shots.csv path, or just the file name when that is unique.
std::size_t roi_shot(const Capture& capture, const AntennaRoi& roi) {
  std::vector<std::size_t> by_name;
  for (std::size_t i = 0; i < capture.shots.size(); ++i) {
    if (capture.shots[i].image == roi.image) return i;
    if (fs::path(capture.shots[i].image).filename() == roi.image) by_name.push_back(i);
  }
  if (by_name.size() == 1) return by_name.front();
  std::string known;
  for (std::size_t i = 0; i < capture.shots.size() && i < 4; ++i) known += (i ? ", " : "") + capture.shots[i].image;
  if (capture.shots.size() > 4) known += ", ...";
  throw InputError("--roi", fmt::format("'{}' {} (photos: {})", roi.image,
                                        by_name.empty() ? "is no photo of the capture" : "names several photos",
                                        known.empty() ? "none" : known));
}

Vec3 camera_centre(const Mat3& R_camera_board, const Vec3& t_camera_board) {
  return -R_camera_board.transpose() * t_camera_board;
}

// The reconstruction's rotation uncertainty from the camera poses (board frame, rad²): each
// pose's rotation covariance carried into the board frame, averaged, over the number of views
// (their errors are independent between photos and average in the triangulation).
Mat3 pose_rotation_covariance(const reconstruction::RefinedPoses& poses) {
  Mat3 sum = Mat3::Zero();
  const auto n = poses.R_camera_board.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Mat3 R_bc = poses.R_camera_board[i].transpose();
    sum += R_bc * poses.covariance[i].topLeftCorner<3, 3>() * R_bc.transpose();
  }
  return n ? Mat3(sum / static_cast<double>(n * n)) : Mat3(Mat3::Zero());
}

// Spatial block bootstrap of the fine registration (file comment of non_contact.hpp): rotation
// covariance of T_antenna_board as a left perturbation in the antenna frame, rad².
Mat3 bootstrap_covariance(const PointCloud& scene, const registration::PreparedCloud& model, const Iso3& T_model_scene,
                          const NonContactOptions& options) {
  std::map<std::tuple<long, long, long>, std::vector<std::size_t>> blocks;
  for (std::size_t i = 0; i < scene.size(); ++i) {
    const Vec3 k = (scene.points[i] / options.bootstrap_block_m).array().floor();
    blocks[{static_cast<long>(k.x()), static_cast<long>(k.y()), static_cast<long>(k.z())}].push_back(i);
  }
  std::vector<const std::vector<std::size_t>*> list;
  for (const auto& [key, idx] : blocks) list.push_back(&idx);
  if (list.size() < 3 || options.bootstrap_replicas < 2) return Mat3::Zero();
  std::mt19937_64 rng(options.seed);
  std::uniform_int_distribution<std::size_t> pick(0, list.size() - 1);
  registration::IcpOptions icp = options.registration.fine;
  icp.max_iterations = 20;
  Mat3 sum = Mat3::Zero();
  for (int r = 0; r < options.bootstrap_replicas; ++r) {
    PointCloud sample;
    for (std::size_t b = 0; b < list.size(); ++b)
      for (const auto i : *list[pick(rng)]) sample.points.push_back(scene.points[i]);
    const auto prepared = registration::prepare(std::move(sample), icp);
    const auto fit = registration::align(prepared, model, T_model_scene, icp);
    const Vec3 d = log_so3(fit.T_target_source.rotation() * T_model_scene.rotation().transpose());
    sum += d * d.transpose();
  }
  return sum / static_cast<double>(options.bootstrap_replicas);
}

double extent_along(const PointCloud& cloud, const Vec3& axis) {
  double lo = 1e300, hi = -1e300;
  for (const auto& p : cloud.points) lo = std::min(lo, p.dot(axis)), hi = std::max(hi, p.dot(axis));
  return cloud.empty() ? 0.0 : hi - lo;
}

void register_model(AntennaMeasurement& m, const model::AntennaModel& model, const PointCloud& model_cloud,
                    const registration::PreparedCloud& model_prepared, const std::vector<Vec3>& viewpoints,
                    const Vec3& up_board, const NonContactOptions& options) {
  auto gopts = options.registration;
  gopts.viewpoints_scene = viewpoints;
  const auto scene = registration::prepare(m.region.cloud_board, gopts.fine);
  const auto g = registration::global_align(scene, model_prepared, up_board, gopts);
  const Iso3 T_antenna_board = g.fit.T_target_source;
  m.method = "model " + model.name;
  m.R_board_antenna = T_antenna_board.rotation().transpose();
  m.p_board_antenna = T_antenna_board.inverse().translation();
  m.fit_rmse_m = g.fit.rmse_m;
  m.fitness = g.fit.fitness;
  m.front_back_margin = g.front_back_margin;
  if (!(m.fitness >= options.fail_fitness) || !(m.fit_rmse_m <= options.fail_rmse_m))
    throw MeasurementError(fmt::format(
        "the region's {} points do not fit the model '{}': {:.0f} % of them lie within {:.0f} mm of it, RMS {:.1f} mm "
        "(at least {:.0f} % and at most {:.0f} mm expected). Is the rectangle on the antenna, and is the model this "
        "antenna's?",
        m.region.cloud_board.size(), model.name, 100 * m.fitness, 1e3 * gopts.fine.max_correspondence_distance_m,
        1e3 * m.fit_rmse_m, 100 * options.fail_fitness, 1e3 * options.fail_rmse_m));
  if (m.fit_rmse_m > options.warn_rmse_m)
    m.warnings.push_back(fmt::format("poor registration fit: RMS {:.1f} mm (more than {:.0f} mm)", 1e3 * m.fit_rmse_m,
                                     1e3 * options.warn_rmse_m));
  if (g.front_back_ambiguous)
    m.warnings.push_back(fmt::format(
        "front and back are ambiguous: the model turned 180° fits nearly as well (margin {:.3f}); photograph the "
        "antenna from further round its side, or check the azimuth by eye",
        g.front_back_margin));
  const double covered = extent_along(m.region.cloud_board, m.R_board_antenna.col(2));
  if (covered < 0.6 * model.size_m.z())
    m.warnings.push_back(
        fmt::format("the points cover {:.2f} m of the {:.2f} m long panel: enlarge the rectangle to "
                    "the whole antenna",
                    covered, model.size_m.z()));
  const Mat3 cov_antenna = bootstrap_covariance(m.region.cloud_board, model_prepared, T_antenna_board, options);
  m.cov_board = m.R_board_antenna * cov_antenna * m.R_board_antenna.transpose();
  m.model_board = transformed(model_cloud, T_antenna_board.inverse());
}

nlohmann::json deg_or_null(const std::optional<double>& rad) {
  return rad ? nlohmann::json(rad2deg(*rad)) : nlohmann::json(nullptr);
}

nlohmann::json matrix_json(const Mat3& R) {
  nlohmann::json j = nlohmann::json::array();
  for (int r = 0; r < 3; ++r) j.push_back({R(r, 0), R(r, 1), R(r, 2)});
  return j;
}

}  // namespace

AntennaRoi parse_roi(const std::string& text) {
  const auto colon = text.rfind(':');
  AntennaRoi r;
  int w = 0, h = 0, x = 0, y = 0;
  char tail = 0;
  if (colon == std::string::npos || colon == 0 ||
      std::sscanf(text.c_str() + colon + 1, "%d,%d,%d,%d%c", &x, &y, &w, &h, &tail) != 4)
    throw InputError("--roi", fmt::format("'{}' is not IMAGE:x,y,w,h (e.g. images/img_003.jpg:1200,300,400,1500, "
                                          "pixels of that photo)",
                                          text));
  if (x < 0 || y < 0 || w < 8 || h < 8)
    throw InputError("--roi", fmt::format("'{}': x and y must be ≥ 0 and the width and height at least 8 px", text));
  r.image = text.substr(0, colon);
  r.roi = {x, y, w, h};
  return r;
}

NonContactResult measure_non_contact(const Capture& capture, const NonContactSetup& setup,
                                     const NonContactOptions& options, Diagnostics& diagnostics) {
  NonContactResult result;
  std::vector<std::size_t> roi_shots;
  for (const auto& roi : setup.rois) roi_shots.push_back(roi_shot(capture, roi));
  for (std::size_t k = 0; k < setup.rois.size(); ++k) {
    const auto& r = setup.rois[k].roi;
    if (r.x + r.width > setup.intrinsics.width || r.y + r.height > setup.intrinsics.height)
      throw InputError("--roi", fmt::format("{}:{},{},{},{} reaches outside the {}×{} image", setup.rois[k].image, r.x,
                                            r.y, r.width, r.height, setup.intrinsics.width, setup.intrinsics.height));
  }
  for (const auto& s : capture.shots) result.photos.push_back(s.image);

  // Board poses, and the photos as posed views.
  report(options, "board poses", 0, 1);
  const auto board_poses = camera::board_poses(capture, setup.board, setup.intrinsics, diagnostics);
  std::vector<PosedView> views;
  for (const auto& p : board_poses) {
    if (!p.pose) {
      result.skipped.push_back(p.image + ": " + p.reason);
      continue;
    }
    PosedView v;
    v.name = fmt::format("shot {} ({})", p.shot_index, p.image);
    v.image = cv::imread((capture.root / p.image).string(), cv::IMREAD_GRAYSCALE);
    v.R_camera_board = p.pose->R_camera_board;
    v.t_camera_board = p.pose->t_camera_board;
    v.board_image_px = p.image_points_px;
    v.board_points_m = p.board_points_m;
    views.push_back(std::move(v));
    result.posed.push_back(p.shot_index);
  }
  report(options, "board poses", 1, 1);
  if (views.size() < 2) {
    std::string why;
    for (const auto& s : result.skipped) why += "\n  " + s;
    throw MeasurementError(fmt::format("the board was found in {} of {} photos; at least 2 are needed{}", views.size(),
                                       capture.shots.size(), why));
  }

  result.poses = reconstruction::refine_camera_poses(
      views, setup.intrinsics, options.poses, [&](const std::string& s, int d, int t) { report(options, s, d, t); });
  for (std::size_t i = 0; i < views.size(); ++i) {
    views[i].R_camera_board = result.poses.R_camera_board[i];
    views[i].t_camera_board = result.poses.t_camera_board[i];
  }
  for (const auto& w : result.poses.warnings) result.warnings.push_back(w);

  // The board in the world.
  report(options, "phone orientation", 0, 1);
  const auto data = orientation::imu_data_from_capture(capture, diagnostics);
  const auto track = orientation::make_estimator(options.orientation)->estimate(data, diagnostics);
  report(options, "phone orientation", 1, 1);
  std::vector<BoardPhoto> photos;
  for (std::size_t i = 0; i < views.size(); ++i)
    photos.push_back({views[i].name, capture.shots[result.posed[i]].t, result.poses.R_camera_board[i],
                      result.poses.t_camera_board[i], result.poses.covariance[i].topLeftCorner<3, 3>()});
  result.board = board_world_attitude(photos, track, setup.camera_imu, options.board_world, diagnostics);
  if (capture.site) result.site = geomag::site_field(geomag::MagneticModel::wmm2025(), *capture.site);

  std::vector<Vec3> viewpoints;
  for (std::size_t i = 0; i < views.size(); ++i)
    viewpoints.push_back(camera_centre(result.poses.R_camera_board[i], result.poses.t_camera_board[i]));
  const Vec3 up_board = result.board.R_world_board.transpose() * Vec3::UnitZ();
  const Mat3 cov_poses = pose_rotation_covariance(result.poses);

  PointCloud model_cloud;
  std::optional<registration::PreparedCloud> model_prepared;
  if (setup.model) {
    model_cloud = model::sample_surface(setup.model->mesh_antenna, options.model_spacing_m, options.seed);
    model_prepared = registration::prepare(model_cloud, options.registration.fine);
  }

  for (std::size_t k = 0; k < setup.rois.size(); ++k) {
    AntennaMeasurement m;
    m.roi = setup.rois[k];
    const auto name = fmt::format("antenna {} ({})", k + 1, m.roi.image);
    try {
      const auto at = std::find(result.posed.begin(), result.posed.end(), roi_shots[k]);
      if (at == result.posed.end())
        throw MeasurementError(
            fmt::format("the board was not found in {} ({}): mark the antenna in a photo that shows "
                        "the board",
                        m.roi.image, board_poses[roi_shots[k]].reason));
      const auto view = static_cast<std::size_t>(at - result.posed.begin());
      m.region = reconstruction::reconstruct_region(
          views, result.poses, view, m.roi.roi, setup.intrinsics, options.region,
          [&](const std::string& s, int d, int t) { report(options, name + ": " + s, d, t); });
      for (const auto& w : m.region.warnings) m.warnings.push_back(w);
      report(options, name + ": registration", 0, 1);
      if (setup.model) {
        register_model(m, *setup.model, model_cloud, *model_prepared, viewpoints, up_board, options);
      } else {
        const FaceFit fit = fit_front_face(m.region.cloud_board, viewpoints, up_board, options.model_free);
        m.method = "model-free (front face + long axis)";
        m.R_board_antenna = fit.R_scene_antenna;
        m.p_board_antenna = fit.centre_scene;
        m.cov_board = fit.covariance;
        m.fit_rmse_m = fit.rmse_m;
        m.fitness = fit.inlier_share;
        for (const auto& w : fit.warnings) m.warnings.push_back(w);
      }
      report(options, name + ": registration", 1, 1);
      m.cov_board += cov_poses;
      m.attitude = antenna_attitude(result.board, m.R_board_antenna, m.cov_board, result.site);
    } catch (const MeasurementError& e) {
      m.error = e.what();
    }
    result.antennas.push_back(std::move(m));
  }
  return result;
}

nlohmann::json to_json(const NonContactResult& r) {
  nlohmann::json j;
  j["photos"] = r.photos.size();
  j["photos_with_board"] = r.posed.size();
  j["skipped"] = r.skipped;
  j["camera_poses"] = {{"board_rms_px", r.poses.board_rms_px},
                       {"scene_rms_px", r.poses.scene_rms_px},
                       {"tracks", r.poses.tracks},
                       {"observations", r.poses.observations}};
  j["board"] = {{"R_world_board", matrix_json(r.board.R_world_board)},
                {"photos_used", r.board.used},
                {"heading_scatter_deg", r.board.heading_scatter_deg},
                {"view_spread_deg", r.board.view_spread_deg}};
  j["world"] = "enu-magnetic";
  j["declination_deg"] = r.site ? nlohmann::json(rad2deg(r.site->declination)) : nlohmann::json(nullptr);
  j["warnings"] = r.warnings;
  j["antennas"] = nlohmann::json::array();
  for (const auto& m : r.antennas) {
    nlohmann::json a;
    a["roi"] = {{"image", m.roi.image},
                {"x", m.roi.roi.x},
                {"y", m.roi.roi.y},
                {"width", m.roi.roi.width},
                {"height", m.roi.roi.height}};
    a["error"] = m.error ? nlohmann::json(*m.error) : nlohmann::json(nullptr);
    const bool ok = !m.error;
    const auto& at = m.attitude;
    a["method"] = m.method;
    a["azimuth_magnetic_deg"] = ok ? deg_or_null(at.magnetic.azimuth) : nullptr;
    a["azimuth_true_deg"] = ok ? deg_or_null(at.azimuth_true) : nullptr;
    a["downtilt_deg"] = ok ? nlohmann::json(rad2deg(at.magnetic.downtilt)) : nullptr;
    a["roll_deg"] = ok ? deg_or_null(at.magnetic.roll) : nullptr;
    a["uncertainty_deg"] = {{"azimuth", ok ? deg_or_null(at.sigma.azimuth) : nullptr},
                            {"azimuth_true", ok ? deg_or_null(at.azimuth_true_sigma) : nullptr},
                            {"downtilt", ok ? nlohmann::json(rad2deg(at.sigma.downtilt)) : nullptr},
                            {"roll", ok ? deg_or_null(at.sigma.roll) : nullptr}};
    a["fit_rmse_m"] = ok ? nlohmann::json(m.fit_rmse_m) : nullptr;
    a["fitness"] = ok ? nlohmann::json(m.fitness) : nullptr;
    a["front_back_margin"] = m.front_back_margin ? nlohmann::json(*m.front_back_margin) : nullptr;
    a["photos_used"] = m.region.views_used;
    a["points"] = m.region.cloud_board.size();
    a["reconstruction"] = m.region.method;
    if (ok) {
      a["R_world_antenna"] = matrix_json(at.R_world_antenna);
      a["R_board_antenna"] = matrix_json(m.R_board_antenna);
    }
    std::vector<std::string> warnings = ok ? at.warnings : std::vector<std::string>{};
    warnings.insert(warnings.end(), m.warnings.begin(), m.warnings.end());
    a["warnings"] = warnings;
    j["antennas"].push_back(a);
  }
  return j;
}

}  // namespace antpose::measure
