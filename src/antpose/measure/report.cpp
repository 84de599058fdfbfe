#include "antpose/measure/report.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "antpose/io/exif_orientation.hpp"
#include "antpose/io/report_text.hpp"
#include "antpose/io/text_file.hpp"
#include "antpose/model/mesh.hpp"
#include "antpose/io/photo_file.hpp"

namespace antpose::measure {
namespace {
namespace fs = std::filesystem;

constexpr int kOverlayWidth = 1600;  // px; photos are drawn at most this wide

// The antenna's box in its own frame: the model's size, or (model-free) the points' extent.
std::pair<Vec3, Vec3> antenna_box(const AntennaMeasurement& m, const model::AntennaModel* model) {
  if (model) return {-model->size_m / 2, model->size_m / 2};
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  for (const auto& p : m.region.cloud_board.points) {
    const Vec3 q = m.R_board_antenna.transpose() * (p - m.p_board_antenna);
    lo = lo.cwiseMin(q), hi = hi.cwiseMax(q);
  }
  return {lo, hi};
}

void draw_overlay(cv::Mat& image, double scale, const camera::CameraIntrinsics& in, const Mat3& R_cb, const Vec3& t_cb,
                  const AntennaMeasurement& m, const model::AntennaModel* model, int number) {
  const auto [lo, hi] = antenna_box(m, model);
  auto px = [&](const Vec3& p_antenna) -> std::optional<cv::Point> {
    const Vec3 p_board = m.R_board_antenna * p_antenna + m.p_board_antenna;
    const auto uv = in.project(R_cb * p_board + t_cb);
    if (!uv) return std::nullopt;
    return cv::Point(static_cast<int>(std::lround(uv->x() * scale)), static_cast<int>(std::lround(uv->y() * scale)));
  };
  std::array<Vec3, 8> c;
  for (int k = 0; k < 8; ++k) c[k] = Vec3(k & 1 ? hi.x() : lo.x(), k & 2 ? hi.y() : lo.y(), k & 4 ? hi.z() : lo.z());
  const int thickness = std::max(1, static_cast<int>(std::lround(2 * scale * in.width / kOverlayWidth)));
  for (int a = 0; a < 8; ++a)
    for (int b = a + 1; b < 8; ++b) {
      const int diff = a ^ b;
      if (diff != 1 && diff != 2 && diff != 4) continue;
      const bool front = (a & 2) && (b & 2);  // both on the radome's face (+y)
      const auto pa = px(c[a]), pb = px(c[b]);
      if (pa && pb)
        cv::line(image, *pa, *pb, front ? cv::Scalar(0, 230, 0) : cv::Scalar(0, 140, 255), thickness, cv::LINE_AA);
    }
  // The mast found beside it (the outline's occluder or masked background), magenta.
  if (m.mast)
    for (const auto& line : reconstruction::mast_outline(*m.mast, in, R_cb, t_cb)) {
      std::vector<cv::Point> pts;
      for (const auto& q : line)
        pts.emplace_back(static_cast<int>(std::lround(q.x * scale)), static_cast<int>(std::lround(q.y * scale)));
      if (pts.size() >= 2) cv::polylines(image, pts, false, cv::Scalar(255, 0, 255), thickness, cv::LINE_AA);
    }
  const Vec3 face(0.0, hi.y(), 0.0);
  const auto p0 = px(face), p1 = px(face + Vec3(0.0, 0.5 * (hi.z() - lo.z()), 0.0));
  if (p0 && p1) cv::arrowedLine(image, *p0, *p1, cv::Scalar(0, 255, 255), thickness, cv::LINE_AA, 0, 0.15);
  if (p0)
    cv::putText(image, std::to_string(number), *p0 + cv::Point(8, -8), cv::FONT_HERSHEY_SIMPLEX, 0.9,
                cv::Scalar(0, 255, 255), 2, cv::LINE_AA);
}

std::string angle_cell(const std::optional<double>& value, const std::optional<double>& sigma, int digits) {
  if (!value) return "–";
  return fmt::format("{:.{}f}° ± {:.{}f}°", rad2deg(*value), digits, rad2deg(sigma.value_or(0.0)), digits);
}

std::string sigma_cell(const std::optional<double>& sigma) {
  return sigma ? fmt::format("{:.2f}°", rad2deg(*sigma)) : std::string("–");
}

// Each answered antenna's σ by source (antenna_attitude.hpp's budget): what limits it.
std::string budget_table(const std::vector<AntennaMeasurement>& antennas) {
  std::string h = "<table><tr><th>#</th><th>source</th><th>azimuth</th><th>downtilt</th><th>roll</th></tr>";
  for (std::size_t k = 0; k < antennas.size(); ++k) {
    if (antennas[k].error) continue;
    for (const auto& share : antennas[k].attitude.budget)
      h += fmt::format("<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>", k + 1,
                       io::xml_escape(share.source), sigma_cell(share.sigma.azimuth), sigma_cell(share.sigma.downtilt),
                       sigma_cell(share.sigma.roll));
  }
  return h + "</table>";
}

// Plan view (east right, north up) of one antenna in the world frame: its points, the model and
// the boresight, with a north arrow; metres around the antenna's centre.
std::string plan_svg(const AntennaMeasurement& m, const BoardWorldAttitude& board) {
  const Mat3& R_wb = board.R_world_board;
  const Vec3 centre = R_wb * m.p_board_antenna;
  const double half = 1.0;  // m shown each side
  const double size = 360.0, s = size / (2 * half);
  auto xy = [&](const Vec3& p_board) {
    const Vec3 w = R_wb * p_board - centre;
    return std::pair<double, double>(size / 2 + s * w.x(), size / 2 - s * w.y());
  };
  std::string svg =
      fmt::format(R"(<svg xmlns="http://www.w3.org/2000/svg" width="{0}" height="{0}" viewBox="0 0 {0} {0}">)"
                  R"(<rect width="{0}" height="{0}" fill="#fafafa" stroke="#ccc"/>)",
                  size);
  auto dots = [&](const PointCloud& cloud, const char* colour) {
    const std::size_t step = std::max<std::size_t>(1, cloud.size() / 2500);
    for (std::size_t i = 0; i < cloud.size(); i += step) {
      const auto [x, y] = xy(cloud.points[i]);
      if (x >= 0 && x <= size && y >= 0 && y <= size)
        svg += fmt::format(R"(<circle cx="{:.1f}" cy="{:.1f}" r="1.2" fill="{}"/>)", x, y, colour);
    }
  };
  if (m.mast) {
    const auto [x, y] = xy(m.mast->axis_point_board);
    svg += fmt::format(R"(<circle cx="{:.1f}" cy="{:.1f}" r="{:.1f}" fill="none" stroke="#c020c0" stroke-width="2"/>)",
                       x, y, s * m.mast->radius_m);
  }
  dots(m.model_board, "#f0a040");
  dots(m.region.cloud_board, "#2060c0");
  const Vec3 b = R_wb * m.R_board_antenna.col(1);
  const Vec3 h = Vec3(b.x(), b.y(), 0.0).normalized();
  svg += fmt::format(R"(<line x1="{0}" y1="{0}" x2="{1:.1f}" y2="{2:.1f}" stroke="#d02020" stroke-width="3"/>)",
                     size / 2, size / 2 + 0.8 * half * s * h.x(), size / 2 - 0.8 * half * s * h.y());
  svg +=
      R"(<line x1="30" y1="60" x2="30" y2="15" stroke="black" stroke-width="2"/><text x="25" y="12" font-size="12">N</text>)";
  svg += fmt::format(
      R"(<text x="8" y="{}" font-size="11">1 m ┤ blue: points, orange: model, red: boresight (magnetic), magenta: mast</text>)",
      size - 8);
  return svg + "</svg>";
}

// Each photo's board heading and tilt against the median: a disturbed magnetometer shows as
// headings that stray, an outlier in red.
std::string residual_svg(const BoardWorldAttitude& board) {
  const double width = 640, height = 220, mid = height / 2;
  double span = 1.0;
  for (const auto& p : board.photos) span = std::max({span, std::abs(p.heading_deg), std::abs(p.tilt_deg)});
  const double s = (mid - 20) / span;
  const double bar = std::max(2.0, (width - 60) / std::max<std::size_t>(1, board.photos.size()) / 2.5);
  std::string svg = fmt::format(R"(<svg xmlns="http://www.w3.org/2000/svg" width="{0}" height="{1}">)"
                                R"(<line x1="40" y1="{2}" x2="{0}" y2="{2}" stroke="#888"/>)"
                                R"(<text x="2" y="14" font-size="11">±{3:.2f}°</text>)",
                                width, height, mid, span);
  for (std::size_t i = 0; i < board.photos.size(); ++i) {
    const auto& p = board.photos[i];
    const double x = 50 + i * 2.5 * bar;
    auto rect = [&](double x0, double value, const char* colour) {
      const double y0 = value >= 0 ? mid - s * value : mid;
      svg += fmt::format(R"(<rect x="{:.1f}" y="{:.1f}" width="{:.1f}" height="{:.1f}" fill="{}"/>)", x0, y0, bar,
                         std::max(0.5, s * std::abs(value)), colour);
    };
    rect(x, p.heading_deg, p.outlier ? "#d02020" : "#2060c0");
    rect(x + bar, p.tilt_deg, p.outlier ? "#f08080" : "#80a0e0");
  }
  svg += fmt::format(
      R"(<text x="50" y="{}" font-size="11">per photo: heading (dark) and tilt (light) against the median; red: left out</text>)",
      height - 4);
  return svg + "</svg>";
}

// What produced the report: antpose, the inputs by content, the device, the options.
std::string provenance_table(const store::Provenance& p) {
  std::string h = "<h2>Provenance</h2><table>";
  const auto row = [&](const std::string& key, const std::string& value) {
    h += fmt::format("<tr><th>{}</th><td style=\"text-align:left\">{}</td></tr>", io::xml_escape(key),
                     io::xml_escape(value));
  };
  row("antpose", p.antpose);
  row("made (UTC)", p.created_utc);
  row("command", "antpose " + p.command);
  for (const auto& i : p.inputs) row(i.role, fmt::format("{} (SHA-256 {})", i.path, i.sha256));
  if (p.device_id)
    row("device", fmt::format("{} (profile SHA-256 {})", *p.device_id, p.device_profile_sha256.value_or("")));
  for (const auto& [name, value] : p.options.items())
    row(name, value.is_string() ? value.get<std::string>() : value.dump());
  return h + "</table>";
}

std::string html_page(const Capture& capture, const NonContactResult& r, const std::vector<std::string>& overlays,
                      const store::Provenance& provenance) {
  std::string h =
      "<!doctype html><html><head><meta charset=\"utf-8\"><title>antpose measurement</title><style>"
      "body{font-family:sans-serif;margin:2em;max-width:1200px}table{border-collapse:collapse}"
      "td,th{border:1px solid #ccc;padding:4px 8px;text-align:right}th{background:#eee}"
      ".warn{color:#a04000}.err{color:#c00000}img{max-width:48%;margin:2px}</style></head><body>";
  h += fmt::format("<h1>Antenna attitude: {}</h1>", io::xml_escape(capture.root.filename().string()));
  h += fmt::format(
      "<p>{} photos, the board found in {}; board attitude from {} photos (heading scatter {:.2f}°, views "
      "spread {:.0f}°); camera poses: board {:.2f} px, scene {:.2f} px RMS over {} tracks.{}</p>",
      r.photos.size(), r.posed.size(), r.board.used, r.board.heading_scatter_deg, r.board.view_spread_deg,
      r.poses.board_rms_px, r.poses.scene_rms_px, r.poses.tracks,
      r.site ? fmt::format(" Declination {:.2f}° (WMM2025).", rad2deg(r.site->declination))
             : std::string(" No site: no true azimuth."));
  h += "<table><tr><th>#</th><th>photo</th><th>azimuth magnetic</th><th>azimuth true</th><th>downtilt</th>"
       "<th>roll</th><th>fit RMS</th><th>points</th><th>method</th></tr>";
  for (std::size_t k = 0; k < r.antennas.size(); ++k) {
    const auto& m = r.antennas[k];
    if (m.error) {
      h += fmt::format("<tr><td>{}</td><td>{}</td><td colspan=7 class=err>{}</td></tr>", k + 1,
                       io::xml_escape(m.roi.image), io::xml_escape(*m.error));
      continue;
    }
    const auto& a = m.attitude;
    h += fmt::format(
        "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{:.1f} mm</td><td>{}"
        "</td><td>{}</td></tr>",
        k + 1, io::xml_escape(m.roi.image), angle_cell(a.magnetic.azimuth, a.sigma.azimuth, 2),
        angle_cell(a.azimuth_true, a.azimuth_true_sigma, 2), angle_cell(a.magnetic.downtilt, a.sigma.downtilt, 2),
        angle_cell(a.magnetic.roll, a.sigma.roll, 2), 1e3 * m.fit_rmse_m, m.region.cloud_board.size(),
        io::xml_escape(m.method));
  }
  h += "</table><p>Uncertainties are 1σ. Azimuth clockwise from north, downtilt positive when the antenna points "
       "down, roll positive clockwise seen from behind (docs/non-contact.md).</p>";
  h += "<h2>Uncertainty budget</h2><p>The σ each independent source alone gives each angle (magnetic azimuth); "
       "their squares add up to the σ² above.</p>" +
       budget_table(r.antennas);
  std::vector<std::string> warnings = r.warnings;
  for (const auto& m : r.antennas) {
    if (!m.error) warnings.insert(warnings.end(), m.attitude.warnings.begin(), m.attitude.warnings.end());
    warnings.insert(warnings.end(), m.warnings.begin(), m.warnings.end());
  }
  std::sort(warnings.begin(), warnings.end());
  warnings.erase(std::unique(warnings.begin(), warnings.end()), warnings.end());
  if (!warnings.empty()) {
    h += "<h2>Warnings</h2><ul>";
    for (const auto& w : warnings) h += "<li class=warn>" + io::xml_escape(w) + "</li>";
    h += "</ul>";
  }
  h += "<h2>Plan view</h2>";
  for (std::size_t k = 0; k < r.antennas.size(); ++k)
    if (!r.antennas[k].error)
      h += fmt::format("<figure style=\"display:inline-block\">{}<figcaption>antenna {}</figcaption></figure>",
                       plan_svg(r.antennas[k], r.board), k + 1);
  h += "<h2>Board attitude per photo</h2>" + residual_svg(r.board);
  h += "<h2>Photos with the registered model</h2><p>Green: the front (radome) face; orange: the rest of the box; "
       "yellow: the boresight; magenta: the mast found beside it.</p>";
  for (const auto& o : overlays) h += fmt::format("<a href=\"{0}\"><img src=\"{0}\"></a>", o);
  if (!r.skipped.empty()) {
    h += "<h2>Photos not used</h2><ul>";
    for (const auto& s : r.skipped) h += "<li>" + io::xml_escape(s) + "</li>";
    h += "</ul>";
  }
  return h + provenance_table(provenance) + "</body></html>\n";
}

}  // namespace

void write_report(const fs::path& folder, const Capture& capture, const NonContactSetup& setup,
                  const NonContactResult& result, const store::Provenance& provenance, bool overwrite) {
  if (fs::exists(folder) && !fs::is_empty(folder) && !overwrite)
    throw InputError(folder, "already exists and is not empty; choose a new report folder or add --force");
  io::write_folder_atomic(folder, true, [&](const fs::path& tmp) {
    std::vector<std::string> overlays;
    for (std::size_t i = 0; i < result.posed.size(); ++i) {
      const auto& shot = capture.shots[result.posed[i]];
      cv::Mat image = io::read_photo(capture.root / shot.image, cv::IMREAD_COLOR).image;
      if (image.empty()) continue;
      const double scale = std::min(1.0, static_cast<double>(kOverlayWidth) / image.cols);
      if (scale < 1.0) cv::resize(image, image, cv::Size(), scale, scale, cv::INTER_AREA);
      for (std::size_t k = 0; k < result.antennas.size(); ++k) {
        const auto& m = result.antennas[k];
        if (m.region.rois.size() == result.posed.size() && m.region.rois[i]) {
          const auto& roi = *m.region.rois[i];
          cv::rectangle(
              image, cv::Rect(cv::Point(roi.x * scale, roi.y * scale), cv::Size(roi.width * scale, roi.height * scale)),
              m.roi.image == shot.image ? cv::Scalar(255, 0, 255) : cv::Scalar(200, 200, 0), 1);
        }
        if (!m.error)
          draw_overlay(image, scale, result.intrinsics, result.poses.R_camera_board[i], result.poses.t_camera_board[i],
                       m, setup.model_for(k), static_cast<int>(k + 1));
      }
      // Drawn in the stored pixels, shown upright.
      if (const auto header = io::read_photo_header(capture.root / shot.image); header.ok())
        image = io::upright_image(image, header.exif_orientation);
      const auto name = fmt::format("overlay_{:02d}.jpg", i + 1);
      if (!cv::imwrite((tmp / name).string(), image, {cv::IMWRITE_JPEG_QUALITY, 88}))
        throw Error(fmt::format("could not write {}", (tmp / name).string()));
      overlays.push_back(name);
    }
    for (std::size_t k = 0; k < result.antennas.size(); ++k) {
      const auto& m = result.antennas[k];
      if (!m.region.cloud_board.empty())
        model::write_ply(m.region.cloud_board, tmp / fmt::format("antenna_{}_points.ply", k + 1));
      if (!m.model_board.empty()) model::write_ply(m.model_board, tmp / fmt::format("antenna_{}_model.ply", k + 1));
    }
    nlohmann::json j = to_json(result);
    j["provenance"] = store::to_json(provenance);
    io::write_text_atomic(tmp / "result.json", j.dump(2) + "\n");
    io::write_text_atomic(tmp / "index.html", html_page(capture, result, overlays, provenance));
  });
}

}  // namespace antpose::measure
