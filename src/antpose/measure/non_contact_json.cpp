// The JSON of `antpose measure` (docs/non-contact.md, *Output*).
#include <cmath>

#include <nlohmann/json.hpp>

#include "antpose/io/report_text.hpp"
#include "antpose/measure/non_contact.hpp"

namespace antpose::measure {
namespace {

nlohmann::json deg_or_null(const std::optional<double>& rad) {
  return rad ? nlohmann::json(rad2deg(*rad)) : nlohmann::json(nullptr);
}

nlohmann::json comparison_json(const std::optional<registration::Comparison>& c) {
  if (!c) return nullptr;
  return {{"score_difference", c->difference},
          {"score_standard_error", c->standard_error},
          {"paired_units", c->units},
          {"decisive", c->decisive}};
}

nlohmann::json board_json(const BoardWorldAttitude& b) {
  return {{"R_world_board", io::matrix_rows_json(b.R_world_board)},
          {"photos_used", b.used},
          {"heading_scatter_deg", b.heading_scatter_deg},
          {"compass_turn_deg", deg_or_null(b.compass_turn_rad)},
          {"view_spread_deg", b.view_spread_deg},
          {"heading_sigma_deg", rad2deg(std::sqrt(b.covariance(2, 2)))},
          {"tilt_sigma_deg", rad2deg(std::sqrt((b.covariance(0, 0) + b.covariance(1, 1)) / 2))}};
}

nlohmann::json field_json(const FieldCheck& f) {
  std::vector<double> dip_deg;
  for (const double d : f.dip_rad) dip_deg.push_back(rad2deg(d));
  nlohmann::json vectors = nlohmann::json::array(), positions = nlohmann::json::array();
  for (const Vec3& b : f.field_world_uT) vectors.push_back({b.x(), b.y(), b.z()});
  for (const Vec3& p : f.p_world_m) positions.push_back({p.x(), p.y(), p.z()});
  return {{"field_world_uT", vectors},
          {"position_world_m", positions},
          {"strength_uT", f.strength_uT},
          {"dip_deg", dip_deg},
          {"wmm_strength_uT", f.wmm_strength_uT ? nlohmann::json(*f.wmm_strength_uT) : nullptr},
          {"wmm_dip_deg", deg_or_null(f.wmm_dip_rad)},
          {"strength_spread_percent", 100 * f.strength_spread_fraction},
          {"dip_spread_deg", rad2deg(f.dip_spread_rad)},
          {"strength_trend_percent", 100 * f.strength_trend_fraction},
          {"strength_gradient_uT_per_m", f.strength_gradient_uT_per_m},
          {"trend_f_statistic", f.trend_f_statistic},
          {"vector_trend_percent", 100 * f.vector_trend_fraction},
          {"vector_trend_f_statistic", f.vector_trend_f_statistic},
          {"median_dip_offset_deg", f.wmm_dip_rad ? nlohmann::json(rad2deg(f.median_dip_offset_rad)) : nullptr},
          {"test_ratios", f.test_ratios},
          {"joint_ratio", f.joint_ratio},
          {"disturbed", f.disturbed},
          {"heading_sigma_deg", rad2deg(f.heading_sigma_rad)}};
}

nlohmann::json time_offset_json(const TimeOffsetCheck& t) {
  return {{"device_s", t.device_s},
          {"used_s", t.used_s},
          {"checked", t.checked},
          {"device_consistent", t.device_consistent},
          {"consistent_s", {t.consistent_low_s, t.consistent_high_s}},
          {"spread_at_device_deg", rad2deg(t.spread_at_device_rad)},
          {"least_spread_deg", rad2deg(t.least_spread_rad)}};
}

nlohmann::json antenna_json(const AntennaMeasurement& m) {
  nlohmann::json a;
  // As drawn, on the photo shown upright (the measurement's own rectangle is in the stored pixels).
  a["roi"] = {
      {"image", m.roi.image},          {"x_px", m.roi.drawn.x},           {"y_px", m.roi.drawn.y},
      {"width_px", m.roi.drawn.width}, {"height_px", m.roi.drawn.height}, {"exif_orientation", m.roi.exif_orientation}};
  a["error"] = m.error ? nlohmann::json(*m.error) : nlohmann::json(nullptr);
  const bool ok = !m.error;
  const auto& at = m.attitude;
  a["method"] = m.method;
  a["verdict"] = ok ? nlohmann::json(registration::to_string(m.verdict)) : nullptr;  // no pose, no verdict
  a["azimuth_magnetic_deg"] = ok ? deg_or_null(at.magnetic.azimuth) : nullptr;
  a["azimuth_true_deg"] = ok ? deg_or_null(at.azimuth_true) : nullptr;
  a["downtilt_deg"] = ok ? nlohmann::json(rad2deg(at.magnetic.downtilt)) : nullptr;
  a["roll_deg"] = ok ? deg_or_null(at.magnetic.roll) : nullptr;
  // 1σ of each angle, under the angle's own key.
  a["sigma"] = {{"azimuth_magnetic_deg", ok ? deg_or_null(at.sigma.azimuth) : nullptr},
                {"azimuth_true_deg", ok ? deg_or_null(at.azimuth_true_sigma) : nullptr},
                {"downtilt_deg", ok ? nlohmann::json(rad2deg(at.sigma.downtilt)) : nullptr},
                {"roll_deg", ok ? deg_or_null(at.sigma.roll) : nullptr}};
  nlohmann::json budget = nlohmann::json::array();
  if (ok)
    for (const auto& share : at.budget)
      budget.push_back({{"source", share.source},
                        {"azimuth_magnetic_deg", deg_or_null(share.sigma.azimuth)},
                        {"downtilt_deg", rad2deg(share.sigma.downtilt)},
                        {"roll_deg", deg_or_null(share.sigma.roll)}});
  a["sigma_budget"] = budget;
  a["fit_rmse_m"] = ok ? nlohmann::json(m.fit_rmse_m) : nullptr;
  a["fitness"] = ok ? nlohmann::json(m.fitness) : nullptr;
  nlohmann::json poses = nlohmann::json::array();
  for (const auto& c : m.registration_candidates)
    poses.push_back({{"strategy", registration::to_string(c.strategy)},
                     {"score", c.score},
                     {"faint_outline", c.faint_outline},
                     {"R_board_antenna", io::matrix_rows_json(c.T_board_antenna.linear())},
                     {"p_board_antenna_m",
                      {c.T_board_antenna.translation().x(), c.T_board_antenna.translation().y(),
                       c.T_board_antenna.translation().z()}}});
  nlohmann::json faces = nlohmann::json::array();
  for (const auto& f : m.face_planes)
    faces.push_back({{"face", registration::face_name(f.normal_antenna)},
                     {"points", f.points},
                     {"rms_m", f.rms_m},
                     {"turn_deg", rad2deg(f.turn_board.norm())},
                     {"chi2", f.chi2},
                     {"disagrees", f.disagrees}});
  nlohmann::json long_edges = nlohmann::json::array();
  for (const auto& e : m.long_edges_left_out)
    long_edges.push_back({{"edge", registration::long_edge_name(e.edge)},
                          {"turn_deg", rad2deg(e.turn_rad)},
                          {"distance_sigma", e.distance},
                          {"disagrees", e.disagrees},
                          {"samples", e.samples},
                          {"whole_samples", e.whole_samples},
                          {"R_board_antenna", io::matrix_rows_json(e.T_board_antenna.linear())}});
  a["registration"] = {{"candidates", m.candidates},
                       {"face_planes", faces},
                       {"long_edges_left_out", long_edges},
                       {"poses", poses},
                       {"rivals", m.rivals_board.size()},
                       {"runner_up", comparison_json(m.runner_up)},
                       {"mast_rival", comparison_json(m.mast_rival)},
                       {"front_back", comparison_json(m.front_back)},
                       {"front_back_cue", registration::to_string(m.front_back_cue)},
                       {"edge_radius_m", m.edge_radius_m ? nlohmann::json(*m.edge_radius_m) : nullptr},
                       {"end_cap_rim_m", m.end_cap_rim_m ? nlohmann::json(*m.end_cap_rim_m) : nullptr},
                       {"shapes_within_m", m.shapes_within_m}};
  if (m.mast)
    a["mast"] = {{"axis_point_board_m",
                  {m.mast->axis_point_board.x(), m.mast->axis_point_board.y(), m.mast->axis_point_board.z()}},
                 {"radius_m", m.mast->radius_m},
                 {"points", m.mast->points},
                 {"photos", m.mast->views},
                 {"edge_rms_px", m.mast->edge_rms_px}};
  a["outline_rms_px"] = m.silhouette_rms_px ? nlohmann::json(*m.silhouette_rms_px) : nullptr;
  a["model_shape_sigma_m"] = m.model_shape_sigma_m ? nlohmann::json(*m.model_shape_sigma_m) : nullptr;
  a["photos_used"] = m.region.views_used;
  a["points"] = m.region.cloud_board.size();
  a["reconstruction"] = m.region.method;
  if (ok) {
    a["R_world_antenna"] = io::matrix_rows_json(at.R_world_antenna);
    a["R_board_antenna"] = io::matrix_rows_json(m.R_board_antenna);
  }
  std::vector<std::string> warnings = ok ? at.warnings : std::vector<std::string>{};
  warnings.insert(warnings.end(), m.warnings.begin(), m.warnings.end());
  a["warnings"] = warnings;
  return a;
}

}  // namespace

nlohmann::json to_json(const NonContactResult& r) {
  nlohmann::json j;
  j["photos"] = r.photos.size();
  j["photos_with_board"] = r.posed.size();
  j["skipped"] = r.skipped;
  j["photo_size_px"] = {r.intrinsics.width, r.intrinsics.height};
  j["camera_poses"] = {{"board_rms_px", r.poses.board_rms_px},
                       {"scene_rms_px", r.poses.scene_rms_px},
                       {"tracks", r.poses.tracks},
                       {"observations", r.poses.observations}};
  j["time_offset"] = time_offset_json(r.time_offset);
  j["board"] = board_json(r.board);
  j["magnetic_field"] = field_json(r.field);
  j["world"] = "enu-magnetic";
  j["declination_deg"] = r.site ? nlohmann::json(rad2deg(r.site->declination)) : nlohmann::json(nullptr);
  j["warnings"] = r.warnings;
  j["antennas"] = nlohmann::json::array();
  for (const auto& m : r.antennas) j["antennas"].push_back(antenna_json(m));
  return j;
}

}  // namespace antpose::measure
