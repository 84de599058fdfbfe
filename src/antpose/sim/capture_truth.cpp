// The simulated capture's truth files (capture_simulator.hpp): the device and the scene as YAML.
#include "antpose/sim/capture_simulator.hpp"

#include <algorithm>
#include <cmath>

#include <yaml-cpp/yaml.h>

#include "antpose/calibration/accelerometer.hpp"
#include "antpose/io/csv.hpp"
#include "antpose/io/yaml_util.hpp"
#include "antpose/sim/wide_site_truth.hpp"

namespace antpose::sim {

namespace {

using io::yaml_flow_matrix;
using io::yaml_flow_vector;
using io::yaml_scalar;

YAML::Node camera_node(const camera::CameraIntrinsics& K) {
  YAML::Node cam;
  cam["width_px"] = K.width;
  cam["height_px"] = K.height;
  cam["fx_px"] = yaml_scalar(K.fx);
  cam["fy_px"] = yaml_scalar(K.fy);
  cam["cx_px"] = yaml_scalar(K.cx);
  cam["cy_px"] = yaml_scalar(K.cy);
  YAML::Node dist;
  for (double k : K.distortion) dist.push_back(io::format_number(k));
  dist.SetStyle(YAML::EmitterStyle::Flow);
  cam["distortion"] = dist;
  return cam;
}

}  // namespace

std::string capture_device_yaml(const SimulatedDevice& d, const ImuSimulation& imu) {
  YAML::Node root = YAML::Load(device_yaml(imu));
  root["camera"] = camera_node(d.intrinsics);
  if (d.native_intrinsics) {
    root["photo_scale"] = yaml_scalar(d.photo_scale);
    root["native_camera"] = camera_node(*d.native_intrinsics);
  }
  YAML::Node ci;
  ci["R_device_camera"] = yaml_flow_matrix(d.R_device_camera);
  ci["mounting_error_deg"] = yaml_scalar(d.mounting_error_deg);
  // What an IMU calibration can recover: it defines the device frame by the accelerometer's own
  // axes, so the accelerometer's mounting rotation Q (R_device_calibrated) is invisible to it.
  {
    const auto& a = d.phone.accelerometer;
    Mat3 T, Q;
    Vec3 k;
    calibration::canonical_accelerometer((a.misalignment * a.scale.asDiagonal()).inverse(), T, k, &Q);
    ci["R_calibrated_camera"] = yaml_flow_matrix(Q.transpose() * d.R_device_camera);
    ci["calibrated_frame"] =
        "the device frame as an IMU calibration defines it (x along the accelerometer's x axis, y "
        "in its xy plane): R_calibrated_camera = R_device_calibratedᵀ R_device_camera";
  }
  ci["p_device_camera_m"] = yaml_flow_vector(d.p_device_camera);
  ci["time_offset_s"] = yaml_scalar(d.time_offset_s);
  ci["time_offset_definition"] = "IMU-clock instant of a photo = shots.csv t + time_offset_s";
  root["camera_imu"] = ci;
  YAML::Node ph;
  ph["exposure_s"] = yaml_scalar(d.sensor.exposure_s);
  ph["instant"] = "middle of the exposure (motion blur is centred on it)";
  ph["blur_sigma_px"] = yaml_scalar(d.sensor.blur_sigma_px);
  ph["noise_scale"] = yaml_scalar(d.sensor.noise_scale);
  ph["full_well_e"] = yaml_scalar(d.sensor.full_well_e);
  ph["read_noise_e"] = yaml_scalar(d.sensor.read_noise_e);
  ph["gain"] = yaml_scalar(d.sensor.gain);
  ph["gamma"] = yaml_scalar(d.sensor.gamma);
  ph["jpeg_quality"] = d.sensor.jpeg_quality;
  ph["supersampling"] = d.supersampling;
  root["photo"] = ph;
  return io::yaml_document(root);
}

std::string capture_scene_yaml(const SimulatedCapture& sim, const camera::BoardSpec& board) {
  YAML::Node root;
  root["world"] = "enu-magnetic";
  root["declination_deg"] = yaml_scalar(sim.declination_deg);
  root["note"] =
      "true azimuth = magnetic azimuth + declination; rotations as rows; board frame of board.yaml (camera/board.hpp)";
  if (!sim.placements.empty()) {
    YAML::Node b;
    b["type"] = camera::to_string(board.type);
    b["cols"] = board.cols;
    b["rows"] = board.rows;
    b["square_m"] = yaml_scalar(board.square_m);
    root["board"] = b;
  }
  for (const auto& pl : sim.placements) {
    YAML::Node n;
    n["name"] = pl.name;
    n["R_world_board"] = yaml_flow_matrix(pl.R_world_board);
    n["p_world_board_m"] = yaml_flow_vector(pl.p_world_board);
    double t0 = 0, t1 = 0;
    bool any = false;
    for (const auto& s : sim.shots)
      if (s.placement == pl.name) {
        t0 = any ? std::min(t0, s.t_true) : s.t_true;
        t1 = any ? std::max(t1, s.t_true) : s.t_true;
        any = true;
      }
    YAML::Node span;
    span.push_back(io::format_number(t0));
    span.push_back(io::format_number(t1));
    span.SetStyle(YAML::EmitterStyle::Flow);
    n["shots_t_true"] = span;
    root["placements"].push_back(n);
  }
  if (sim.antenna) {
    const AntennaTruth& at = *sim.antenna;
    const double decl = deg2rad(sim.declination_deg);
    root["setting"] = to_string(at.layout.setting);
    YAML::Node mast;
    mast["p_world_base_m"] = yaml_flow_vector(Vec3::Zero());
    mast["radius_m"] = yaml_scalar(at.layout.mast_radius_m);
    mast["height_m"] = yaml_scalar(at.layout.mast_top_m);
    if (at.layout.setting == AntennaSetting::kRooftop)
      mast["roof_above_street_m"] = yaml_scalar(at.layout.building_height_m);
    root["mast"] = mast;
    for (std::size_t k = 0; k < at.layout.antennas.size(); ++k) {
      const SimAntenna& a = at.layout.antennas[k];
      YAML::Node n;
      n["name"] = a.name;
      n["model"] = a.model_name;
      YAML::Node spec;
      spec["width_m"] = yaml_scalar(a.spec.width_m);
      spec["depth_m"] = yaml_scalar(a.spec.depth_m);
      spec["height_m"] = yaml_scalar(a.spec.height_m);
      spec["edge_radius_m"] = yaml_scalar(a.spec.edge_radius_m);
      spec["bracket"] = a.spec.bracket;
      spec["bracket_width_m"] = yaml_scalar(a.spec.bracket_width_m);
      spec["bracket_depth_m"] = yaml_scalar(a.spec.bracket_depth_m);
      spec["bracket_height_m"] = yaml_scalar(a.spec.bracket_height_m);
      spec["arc_segments"] = a.spec.arc_segments;
      n["panel"] = spec;
      n["R_world_antenna"] = yaml_flow_matrix(a.R_world_antenna);
      n["p_world_antenna_m"] = yaml_flow_vector(a.p_world_antenna);
      n["azimuth_magnetic_deg"] = yaml_scalar(rad2deg(a.azimuth_magnetic));
      n["azimuth_true_deg"] = yaml_scalar(rad2deg(wrap_2pi(a.azimuth_magnetic + decl)));
      n["downtilt_deg"] = yaml_scalar(rad2deg(a.downtilt));
      n["roll_deg"] = yaml_scalar(rad2deg(a.roll));
      n["radome"] = to_string(at.radome);
      if (k < at.roi.size()) {
        YAML::Node roi;
        roi["image"] = sim.shots.at(static_cast<std::size_t>(at.roi_shot[k])).image;
        roi["x"] = at.roi[k].x;
        roi["y"] = at.roi[k].y;
        roi["width"] = at.roi[k].width;
        roi["height"] = at.roi[k].height;
        roi.SetStyle(YAML::EmitterStyle::Flow);
        n["roi"] = roi;
      }
      if (k < at.viewing_span_deg.size()) n["viewing_span_deg"] = yaml_scalar(at.viewing_span_deg[k]);
      if (k < at.visible_fraction.size()) {
        YAML::Node vis;
        for (const double f : at.visible_fraction[k]) vis.push_back(io::format_number(std::round(f * 1000.0) / 1000.0));
        vis.SetStyle(YAML::EmitterStyle::Flow);
        n["visible_fraction"] = vis;
      }
      root["antennas"].push_back(n);
    }
    YAML::Node dist;
    if (at.dipoles.empty()) {
      dist["model"] = "none";
    } else {
      dist["model"] = "dipole-line";
      dist["description"] =
          "a magnetised steel mast: equal point dipoles on its axis, B = 1e-7 (3 r^ (r^.m) - m) / |r|^3 T, "
          "evaluated at the phone (device origin); also in truth/device.yaml dipoles";
      for (const auto& dp : at.dipoles) {
        YAML::Node n;
        n["p_world_m"] = yaml_flow_vector(dp.p_world);
        n["moment_Am2"] = yaml_flow_vector(dp.moment_Am2);
        dist["dipoles"].push_back(n);
      }
    }
    dist["north_shift_definition"] =
        "clockwise turn of the horizontal field at the phone, deg; a magnetometer heading is too "
        "small by it: heading_error_deg = -north_shift_deg";
    YAML::Node shift, err;
    for (const double v : at.north_shift) {
      shift.push_back(io::format_number(std::round(rad2deg(v) * 1e4) / 1e4));
      err.push_back(io::format_number(std::round(-rad2deg(v) * 1e4) / 1e4 + 0.0));  // no "-0"
    }
    shift.SetStyle(YAML::EmitterStyle::Flow);
    err.SetStyle(YAML::EmitterStyle::Flow);
    dist["north_shift_deg"] = shift;
    dist["heading_error_deg"] = err;
    root["disturbance"] = dist;
    for (const auto& m : sim.meshes) root["objects"].push_back(m.name);
    if (at.wide) add_wide_site_truth(root, at);
  }
  for (const auto& p : sim.surfaces) {
    YAML::Node n;
    n["name"] = p.name;
    n["R_world_plane"] = yaml_flow_matrix(p.R_world_patch);
    n["p_world_plane_m"] = yaml_flow_vector(p.p_world_patch);
    YAML::Node lo, hi;
    lo.push_back(io::format_number(p.min_xy.x()));
    lo.push_back(io::format_number(p.min_xy.y()));
    hi.push_back(io::format_number(p.max_xy.x()));
    hi.push_back(io::format_number(p.max_xy.y()));
    lo.SetStyle(YAML::EmitterStyle::Flow);
    hi.SetStyle(YAML::EmitterStyle::Flow);
    n["min_xy_m"] = lo;
    n["max_xy_m"] = hi;
    root["planes"].push_back(n);
  }
  for (const auto& s : sim.shots) {
    YAML::Node n;
    n["index"] = s.index;
    n["image"] = s.image;
    if (!s.placement.empty()) n["placement"] = s.placement;
    n["t_true"] = yaml_scalar(s.t_true);
    n["t"] = yaml_scalar(s.t_shot);
    n["R_world_device"] = yaml_flow_matrix(s.R_world_device);
    n["p_world_device_m"] = yaml_flow_vector(s.p_world_device);
    n["R_world_camera"] = yaml_flow_matrix(s.R_world_camera);
    n["p_world_camera_m"] = yaml_flow_vector(s.p_world_camera);
    n["angular_rate_deg_s"] = yaml_scalar(s.angular_rate_deg_s);
    root["shots"].push_back(n);
  }
  return io::yaml_document(root);
}

}  // namespace antpose::sim
