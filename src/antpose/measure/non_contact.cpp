#include "antpose/measure/non_contact.hpp"

#include <algorithm>
#include <filesystem>

#include <fmt/format.h>

#include "antpose/io/exif_orientation.hpp"
#include "antpose/io/photo_file.hpp"

namespace antpose::measure {
namespace {
namespace fs = std::filesystem;

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

void check_rois_inside(const NonContactSetup& setup, const camera::CameraIntrinsics& photos) {
  for (const auto& roi : setup.rois) {
    const auto& r = roi.drawn;
    const cv::Size shown = io::upright_size({photos.width, photos.height}, roi.exif_orientation);
    if (r.x + r.width > shown.width || r.y + r.height > shown.height)
      throw InputError("--roi", fmt::format("{}:{},{},{},{} reaches outside the {}×{} image{}", roi.image, r.x, r.y,
                                            r.width, r.height, shown.width, shown.height,
                                            roi.exif_orientation == 1 ? "" : " (as shown upright)"));
  }
}

// The ROI drawn on the photo shown upright, in the photo's stored pixels (io/exif_orientation.hpp).
AntennaRoi in_stored_pixels(AntennaRoi roi, const fs::path& photo) {
  const io::PhotoHeader header = io::read_photo_header(photo);
  if (!header.ok()) return roi;  // the photo's own reason comes with its board pose
  roi.exif_orientation = header.exif_orientation;
  const cv::Rect d(roi.drawn.x, roi.drawn.y, roi.drawn.width, roi.drawn.height);
  const cv::Rect s = io::stored_rect(d, {header.width_px, header.height_px}, header.exif_orientation);
  roi.roi = {s.x, s.y, s.width, s.height};
  return roi;
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

// A failed antenna's reason, followed by what says the lengths are wrong: the walk's speed, or
// its points' extent against the model. The reason itself stays, as the scale is only suspected.
void name_doubtful_scale(std::vector<AntennaMeasurement>& antennas, const NonContactSetup& setup, const WalkScale& walk,
                         const ScaleCheckOptions& options) {
  for (std::size_t k = 0; k < antennas.size(); ++k) {
    auto& m = antennas[k];
    if (!m.error) continue;
    if (walk.warning)
      *m.error += "; the board's scale is in doubt (see the warning on square_m)";
    else if (const auto* model = setup.model_for(k))
      if (const auto hint = model_scale_hint(m.region.cloud_board.points, *model, setup.board, options))
        *m.error += "; " + *hint;
  }
}

// Each antenna alone: its region, its registration, its attitude. An antenna that cannot be
// measured keeps its reason.
AntennaMeasurement measure_alone(std::size_t k, std::size_t shot, const NonContactSetup& setup,
                                 const CaptureContext& context, const NonContactOptions& options) {
  AntennaMeasurement m;
  m.roi = setup.rois[k];
  const auto name = fmt::format("antenna {} ({})", k + 1, m.roi.image);
  const auto view = context.poses->view_of_shot(shot);
  if (!view) {
    m.error =
        fmt::format("the board was not found in {}: mark the antenna in a photo that shows the board", m.roi.image);
    return m;
  }
  m.region_view = *view;
  try {
    m.region = antenna_region(context, m.region_view, m.roi, setup.model_for(k), options.antenna,
                              [&](const std::string& s, int d, int t) { report(options, name + ": " + s, d, t); });
  } catch (const MeasurementError& e) {
    m.error = e.what();
    return m;
  }
  m.warnings = m.region.warnings;
  report(options, name + ": registration", 0, 1);
  measure_antenna(m, setup.model_for(k), context, {}, options.antenna);
  report(options, name + ": registration", 1, 1);
  return m;
}

// Antenna k measured once more from its region and its earlier candidates, with `mast` and
// `neighbours` known.
AntennaMeasurement remeasured(std::size_t k, const AntennaMeasurement& before, std::optional<reconstruction::Mast> mast,
                              const std::vector<KnownBox>& neighbours, const NonContactSetup& setup,
                              const CaptureContext& context, const NonContactOptions& options,
                              const std::string& stage) {
  AntennaMeasurement again;
  again.roi = before.roi, again.region = before.region, again.region_view = before.region_view;
  again.mast = std::move(mast);
  again.warnings = again.region.warnings;
  report(options, fmt::format("antenna {}: {}", k + 1, stage), 0, 1);
  measure_antenna(again, setup.model_for(k), context, neighbours, options.antenna, before.registration_candidates);
  report(options, fmt::format("antenna {}: {}", k + 1, stage), 1, 1);
  return again;
}

// The antennas again, each with the others as registered known (their boxes in the photos, their
// points): a neighbour 0.3 m away is then explained by its own model.
void measure_jointly(std::vector<AntennaMeasurement>& antennas, const NonContactSetup& setup,
                     const CaptureContext& context, const NonContactOptions& options) {
  for (int round = 0; round < options.joint_rounds; ++round) {
    std::vector<AntennaMeasurement> next = antennas;
    for (std::size_t k = 0; k < antennas.size(); ++k) {
      if (!setup.model_for(k) || antennas[k].region.rois.empty()) continue;
      const auto neighbours = settled_neighbours(antennas, setup, k);
      if (neighbours.empty()) continue;
      auto mast =
          antennas[k].mast ? antennas[k].mast : neighbours_mast(antennas, setup, k, options.shared_mast_reach_m);
      next[k] =
          remeasured(k, antennas[k], std::move(mast), neighbours, setup, context, options, "with its neighbours known");
    }
    antennas = std::move(next);
  }
}

// The antennas front_back_masts names, measured once more with that mast.
void settle_front_back(std::vector<AntennaMeasurement>& antennas, const NonContactSetup& setup,
                       const CaptureContext& context, const NonContactOptions& options) {
  const auto masts = front_back_masts(antennas, setup, options.shared_mast_reach_m);
  std::vector<AntennaMeasurement> next = antennas;
  for (std::size_t k = 0; k < antennas.size(); ++k)
    if (masts[k])
      next[k] = remeasured(k, antennas[k], masts[k], settled_neighbours(antennas, setup, k), setup, context, options,
                           "with its neighbours' mast");
  antennas = std::move(next);
}

// Two rectangles whose registrations settled on one panel: the one whose rectangle the panel
// spans less of measured its neighbour, and says so.
void refuse_shared_panels(std::vector<AntennaMeasurement>& antennas, const NonContactSetup& setup,
                          const CameraPoses& poses) {
  const auto span = [&](const AntennaMeasurement& m, const model::AntennaModel& model) {
    const Iso3 T = m.T_board_antenna();
    const cv::Rect roi(m.roi.roi.x, m.roi.roi.y, m.roi.roi.width, m.roi.roi.height);
    registration::SilhouetteView v;
    v.R_camera_board = poses.views[m.region_view].R_camera_board;
    v.t_camera_board = poses.views[m.region_view].t_camera_board;
    return registration::roi_span(model.size_m, T, v, poses.intrinsics, roi).span;
  };
  for (std::size_t a = 0; a < antennas.size(); ++a)
    for (std::size_t b = a + 1; b < antennas.size(); ++b) {
      auto& A = antennas[a];
      auto& B = antennas[b];
      const auto* ma = setup.model_for(a);
      const auto* mb = setup.model_for(b);
      if (A.error || B.error || !ma || !mb) continue;
      const double apart = (A.p_board_antenna - B.p_board_antenna).norm();
      if (apart > 0.5 * std::min(ma->size_m.x(), mb->size_m.x())) continue;
      const bool a_lost = span(A, *ma) < span(B, *mb);
      auto& lost = a_lost ? A : B;
      lost.error = fmt::format(
          "its rectangle's registration settled on the same panel as antenna {} ({:.2f} m apart): another panel "
          "overlaps it in {}; draw its rectangle in a photo where it stands clear of its neighbours",
          (a_lost ? b : a) + 1, apart, lost.roi.image);
    }
}

}  // namespace

std::vector<KnownBox> settled_neighbours(const std::vector<AntennaMeasurement>& antennas, const NonContactSetup& setup,
                                         std::size_t k) {
  std::vector<KnownBox> out;
  for (std::size_t j = 0; j < antennas.size(); ++j) {
    const auto& a = antennas[j];
    if (j == k || a.error || !setup.model_for(j) || a.verdict == registration::RegistrationVerdict::kAmbiguousShape)
      continue;
    out.push_back({a.T_board_antenna(), setup.model_for(j)->size_m});
  }
  return out;
}

std::optional<reconstruction::Mast> neighbours_mast(const std::vector<AntennaMeasurement>& antennas,
                                                    const NonContactSetup& setup, std::size_t k, double reach_m) {
  const auto* model = setup.model_for(k);
  if (!model || k >= antennas.size()) return std::nullopt;
  const double footprint = 0.5 * model->size_m.head<2>().norm();
  std::optional<reconstruction::Mast> nearest;
  double best = reach_m;
  for (std::size_t j = 0; j < antennas.size(); ++j) {
    const auto& a = antennas[j];
    if (j == k || a.error || !a.mast) continue;
    const double d = reconstruction::distance_from_axis(*a.mast, antennas[k].p_board_antenna);
    if (d <= best && d > footprint + a.mast->radius_m) best = d, nearest = a.mast;
  }
  return nearest;
}

std::vector<std::optional<reconstruction::Mast>> front_back_masts(const std::vector<AntennaMeasurement>& antennas,
                                                                  const NonContactSetup& setup, double reach_m) {
  std::vector<std::optional<reconstruction::Mast>> out(antennas.size());
  for (std::size_t k = 0; k < antennas.size(); ++k)
    if (!antennas[k].mast && antennas[k].verdict == registration::RegistrationVerdict::kFrontBackOpen)
      out[k] = neighbours_mast(antennas, setup, k, reach_m);
  return out;
}

OptionProblems NonContactOptions::Check() const {
  OptionProblems p;
  p.nest("poses", poses.Check());
  p.nest("world", world.Check());
  p.nest("antenna", antenna.Check());
  p.nest("scale", scale.Check());
  p.require(joint_rounds >= 0 && joint_rounds <= 5, "joint_rounds", "0..5");
  p.require(shared_mast_reach_m >= 0, "shared_mast_reach_m", "≥ 0 (0: no mast shared)");
  return p;
}

NonContactResult measure_non_contact(const Capture& capture, const NonContactSetup& given,
                                     const NonContactOptions& options, Diagnostics& diagnostics) {
  throw_unless_ok(options.Check(), "NonContactOptions");
  require_android_frame(capture, "the non-contact measurement");
  if (given.models.size() > 1 && given.models.size() != given.rois.size())
    throw InputError("--model", fmt::format("{} models for {} regions: give one model for all, or one per --roi in "
                                            "the same order",
                                            given.models.size(), given.rois.size()));
  std::vector<std::size_t> roi_shots;
  for (const auto& roi : given.rois) roi_shots.push_back(roi_shot(capture, roi));
  NonContactSetup setup = given;  // the ROIs in the photos' stored pixels
  for (std::size_t k = 0; k < setup.rois.size(); ++k)
    setup.rois[k] = in_stored_pixels(given.rois[k], capture.root / capture.shots[roi_shots[k]].image);
  NonContactResult result;
  for (const auto& s : capture.shots) result.photos.push_back(s.image);
  const auto progress = [&](const std::string& s, int d, int t) { report(options, s, d, t); };
  CameraPoses poses =
      estimate_camera_poses(capture, setup.board, setup.intrinsics, options.poses, diagnostics, progress);
  const auto& refine = options.antenna.registration.refine;
  registration::EdgePyramidSettings edges;
  edges.gamma = refine.gamma, edges.smoothing_sigma_px = refine.smoothing_sigma_px;
  edges.min_levels = refine.max_level + 1;
  share_edge_images(poses, edges);
  check_rois_inside(setup, poses.intrinsics);
  result.posed = poses.shot_of_view, result.skipped = poses.skipped;
  result.intrinsics = poses.intrinsics, result.poses = poses.refined;
  result.warnings = poses.warnings;
  const WorldAlignment world = align_to_world(capture, poses, setup.camera_imu, options.world, diagnostics, progress);
  result.board = world.board, result.site = world.site, result.field = world.field;
  result.time_offset = world.time_offset;
  result.warnings.insert(result.warnings.end(), world.warnings.begin(), world.warnings.end());
  const CaptureContext context{&poses,
                               &result.board,
                               &result.site,
                               setup.board,
                               result.board.R_world_board.transpose() * Vec3::UnitZ(),
                               pose_rotation_covariance(poses.refined)};
  const WalkScale walk = check_walk_scale(capture, poses, setup.board, options.scale);
  if (walk.warning) result.warnings.push_back(*walk.warning);
  for (std::size_t k = 0; k < setup.rois.size(); ++k)
    result.antennas.push_back(measure_alone(k, roi_shots[k], setup, context, options));
  measure_jointly(result.antennas, setup, context, options);
  if (options.joint_rounds > 0) settle_front_back(result.antennas, setup, context, options);
  refuse_shared_panels(result.antennas, setup, poses);
  name_doubtful_scale(result.antennas, setup, walk, options.scale);
  return result;
}

}  // namespace antpose::measure
