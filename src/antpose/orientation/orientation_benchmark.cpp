#include "antpose/orientation/orientation_benchmark.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <thread>

#include <fmt/format.h>

#include "antpose/io/report_text.hpp"
#include "antpose/orientation/filters.hpp"
#include "antpose/orientation/static_orientation.hpp"

namespace antpose::orientation {
namespace {

std::ptrdiff_t find_column(const Stream& s, const char* name) {
  const auto it = std::find(s.columns.begin(), s.columns.end(), name);
  return it == s.columns.end() ? -1 : it - s.columns.begin();
}

}  // namespace

ScoredTruth scored_truth(const Capture& capture, const std::vector<geomag::MagneticModel>& models,
                         Diagnostics& diagnostics, const ScoringOptions& options) {
  const std::filesystem::path where = capture.root / "capture.yaml";
  if (!capture.truth_orientation) throw InputError(where, "no truth orientation (truth: orientation:) to score against");
  const Stream& truth = *capture.truth_orientation;
  std::array<std::ptrdiff_t, 4> c{};
  const char* names[4] = {"qw", "qx", "qy", "qz"};
  for (int k = 0; k < 4; ++k)
    if ((c[static_cast<std::size_t>(k)] = find_column(truth, names[k])) < 0)
      throw InputError(where, fmt::format("the truth has no '{}' column (needs t,qw,qx,qy,qz[,valid,moving])", names[k]));
  const std::ptrdiff_t c_valid = find_column(truth, "valid"), c_moving = find_column(truth, "moving");

  ScoredTruth out;
  out.world = capture.truth_world;
  if (out.world == "enu-true") {
    if (!capture.site)
      throw InputError(where, "truth world is enu-true but the capture has no site: the declination cannot be applied");
    if (models.empty()) throw std::invalid_argument("scored_truth: no magnetic model given");
    double year = 0.0;
    try {
      year = geomag::decimal_year_from_iso(capture.site->date);
    } catch (const std::invalid_argument& e) {
      throw InputError(where, fmt::format("site: {}", e.what()));
    }
    // The model valid for the date, else the one whose epoch is nearest (shortest extrapolation).
    const geomag::MagneticModel* model = &models.front();
    for (const auto& m : models) {
      if (m.valid_for(year)) {
        model = &m;
        break;
      }
      if (std::abs(m.epoch() - year) < std::abs(model->epoch() - year)) model = &m;
    }
    geomag::SiteField field;
    try {
      field = geomag::site_field(*model, *capture.site);
    } catch (const std::invalid_argument& e) {
      throw InputError(where, fmt::format("site: {}", e.what()));
    }
    if (field.validity_warning) diagnostics.warn(where, 0, *field.validity_warning);
    out.declination = field.declination;
    out.declination_model = model->name();
  } else if (out.world != "enu-magnetic") {
    throw InputError(where, fmt::format("truth world is '{}'; the orientation benchmark compares directly and needs "
                                        "'enu-magnetic' or 'enu-true' (with a site)",
                                        out.world));
  }

  auto value = [&](std::size_t i, std::ptrdiff_t col) { return truth.values(static_cast<Eigen::Index>(i), col); };
  out.protocol = c_moving >= 0 ? "moving" : "after-skip";
  const double t_from = truth.empty() ? 0.0 : truth.t.front() + options.skip_s;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    if (c_moving >= 0 ? value(i, c_moving) == 0.0 : truth.t[i] < t_from) continue;
    if (c_valid >= 0 && value(i, c_valid) == 0.0) continue;
    const Quat q(value(i, c[0]), value(i, c[1]), value(i, c[2]), value(i, c[3]));
    if (!q.coeffs().allFinite() || !(q.norm() > 0.0)) continue;
    out.t.push_back(truth.t[i]);
    out.q_world_device.push_back(q.normalized());
  }
  if (out.t.empty()) throw MeasurementError(fmt::format("{}: no truth sample to score", where.string()));
  return out;
}

TrackScore score_track(const OrientationTrack& track_in, const ScoredTruth& truth) {
  if (track_in.world != "enu-magnetic")
    throw std::invalid_argument("score_track: the estimate must be enu-magnetic (the truth's declination is applied here)");
  const Quat r = magnetic_to_true(truth.world == "enu-true" ? truth.declination : 0.0);
  TrackScore s;
  double st = 0, sh = 0, si = 0, mt = 0, my = 0, mp = 0, mr = 0;
  for (std::size_t i = 0; i < truth.t.size(); ++i) {
    if (!track_in.contains(truth.t[i])) {
      ++s.outside;
      continue;
    }
    const Quat q_est = r * track_in.at(truth.t[i]).q_world_device;
    const BroadErrors e = broad_errors(q_est, truth.q_world_device[i]);
    st += e.total * e.total, sh += e.heading * e.heading, si += e.inclination * e.inclination, mt += e.total;
    const AndroidOrientation a = android_orientation(q_est.toRotationMatrix());
    const AndroidOrientation b = android_orientation(truth.q_world_device[i].toRotationMatrix());
    my += std::abs(wrap_pi(a.azimuth - b.azimuth));
    mp += std::abs(a.pitch - b.pitch);
    mr += std::abs(wrap_pi(a.roll - b.roll));
    ++s.samples;
  }
  if (s.samples == 0) throw MeasurementError(fmt::format("no truth instant lies inside the '{}' track", track_in.method));
  const double n = static_cast<double>(s.samples);
  s.rmse = {std::sqrt(st / n), std::sqrt(sh / n), std::sqrt(si / n)};
  s.mean_total = mt / n;
  s.yaw_mae = my / n, s.pitch_mae = mp / n, s.roll_mae = mr / n;
  return s;
}

BenchmarkTrial load_benchmark_trial(const std::filesystem::path& folder,
                                    const std::vector<geomag::MagneticModel>& models, Diagnostics& diagnostics,
                                    const ScoringOptions& options) {
  const Capture capture = read_capture(folder, diagnostics);
  BenchmarkTrial trial;
  const std::filesystem::path clean = folder.lexically_normal();
  trial.name = (clean.has_filename() ? clean : clean.parent_path()).filename().string();
  trial.dataset = (clean.has_filename() ? clean : clean.parent_path()).parent_path().filename().string();
  trial.data = imu_data_from_capture(capture, diagnostics);
  trial.truth = scored_truth(capture, models, diagnostics, options);
  return trial;
}

MethodScore run_method(const BenchmarkTrial& trial, const OrientationEstimator& estimator, Diagnostics& diagnostics) {
  MethodScore m;
  m.trial = trial.name;
  m.dataset = trial.dataset;
  m.method = estimator.name();
  const auto t0 = std::chrono::steady_clock::now();
  const OrientationTrack track = estimator.estimate(trial.data, diagnostics);
  const auto t1 = std::chrono::steady_clock::now();
  m.seconds = std::chrono::duration<double>(t1 - t0).count();
  m.track_samples = track.size();
  m.ns_per_sample = track.empty() ? 0.0 : 1e9 * m.seconds / static_cast<double>(track.size());
  m.score = score_track(track, trial.truth);
  return m;
}

TrackScore mean_score(const std::vector<MethodScore>& scores) {
  TrackScore m;
  if (scores.empty()) return m;
  for (const auto& s : scores) {
    m.samples += s.score.samples;
    m.outside += s.score.outside;
    m.rmse.total += s.score.rmse.total;
    m.rmse.heading += s.score.rmse.heading;
    m.rmse.inclination += s.score.rmse.inclination;
    m.mean_total += s.score.mean_total;
    m.yaw_mae += s.score.yaw_mae, m.pitch_mae += s.score.pitch_mae, m.roll_mae += s.score.roll_mae;
  }
  const double k = static_cast<double>(scores.size());
  m.rmse.total /= k, m.rmse.heading /= k, m.rmse.inclination /= k, m.mean_total /= k;
  m.yaw_mae /= k, m.pitch_mae /= k, m.roll_mae /= k;
  return m;
}

GridResult madgwick_grid(const std::vector<BenchmarkTrial>& trials, const std::vector<double>& beta,
                         const std::vector<double>& zeta, unsigned threads) {
  if (trials.empty() || beta.empty() || zeta.empty()) throw std::invalid_argument("madgwick_grid: empty trials or grid");
  GridResult g;
  g.beta = beta;
  g.zeta = zeta;
  g.trials = trials.size();
  const auto rows = static_cast<Eigen::Index>(beta.size()), cols = static_cast<Eigen::Index>(zeta.size());
  for (auto* m : {&g.yaw_mae, &g.pitch_mae, &g.roll_mae, &g.pitch_roll_mae, &g.total_rmse}) m->setZero(rows, cols);
  const std::size_t cells = beta.size() * zeta.size();
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    for (std::size_t c; (c = next.fetch_add(1)) < cells;) {
      const auto r = static_cast<Eigen::Index>(c / zeta.size()), k = static_cast<Eigen::Index>(c % zeta.size());
      MadgwickParams p;
      p.beta = beta[static_cast<std::size_t>(r)];
      p.zeta = zeta[static_cast<std::size_t>(k)];
      double y = 0, pi = 0, ro = 0, tot = 0;
      for (const auto& trial : trials) {
        MadgwickFilter filter(p);
        const OrientationTrack track = run_gyro_driven(filter, trial.data, initial_attitude(trial.data));
        const TrackScore s = score_track(track, trial.truth);
        y += s.yaw_mae, pi += s.pitch_mae, ro += s.roll_mae, tot += s.rmse.total;
      }
      const double n = static_cast<double>(trials.size());
      g.yaw_mae(r, k) = y / n;  // each cell written by exactly one worker
      g.pitch_mae(r, k) = pi / n;
      g.roll_mae(r, k) = ro / n;
      g.pitch_roll_mae(r, k) = (pi + ro) / n;
      g.total_rmse(r, k) = tot / n;
    }
  };
  std::vector<std::thread> pool;
  for (unsigned i = 1; i < std::max(1u, threads); ++i) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  return g;
}

namespace {

// Viridis at 0, .25, .5, .75, 1 (matplotlib), linear in between.
std::string colour(double u) {
  static constexpr double anchors[5][3] = {
      {68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}};
  u = std::clamp(std::isfinite(u) ? u : 0.0, 0.0, 1.0) * 4.0;
  const int i = std::min(3, static_cast<int>(u));
  const double f = u - i;
  int rgb[3];
  for (int k = 0; k < 3; ++k) rgb[k] = static_cast<int>(std::lround(anchors[i][k] + f * (anchors[i + 1][k] - anchors[i][k])));
  return fmt::format("#{:02x}{:02x}{:02x}", rgb[0], rgb[1], rgb[2]);
}


}  // namespace

std::string heatmap_svg(const Heatmap& map) {
  const auto rows = map.values.rows(), cols = map.values.cols();
  if (rows == 0 || cols == 0 || static_cast<std::size_t>(rows) != map.y_values.size() ||
      static_cast<std::size_t>(cols) != map.x_values.size())
    throw std::invalid_argument("heatmap_svg: values must be y_values × x_values and non-empty");
  const double cell_w = 58, cell_h = 30, left = 90, top = 50, bar_w = 18;
  const double width = left + cols * cell_w + 110, height = top + rows * cell_h + 70;
  double lo = map.values.minCoeff(), hi = map.values.maxCoeff();
  const double span = hi > lo ? hi - lo : 1.0;
  std::string s = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{:.0f}\" height=\"{:.0f}\" font-family=\"sans-serif\" "
      "font-size=\"11\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n",
      width, height);
  s += fmt::format("<text x=\"{:.0f}\" y=\"24\" font-size=\"15\" text-anchor=\"middle\">{}</text>\n",
                   left + cols * cell_w / 2, io::xml_escape(map.title));
  for (Eigen::Index r = 0; r < rows; ++r) {
    const double y = top + r * cell_h;
    s += fmt::format("<text x=\"{:.0f}\" y=\"{:.1f}\" text-anchor=\"end\">{}</text>\n", left - 6, y + cell_h / 2 + 4,
                     fmt::format("{:g}", map.y_values[static_cast<std::size_t>(r)]));
    for (Eigen::Index c = 0; c < cols; ++c) {
      const double x = left + c * cell_w, v = map.values(r, c), u = (v - lo) / span;
      s += fmt::format("<rect x=\"{:.0f}\" y=\"{:.0f}\" width=\"{:.0f}\" height=\"{:.0f}\" fill=\"{}\"/>", x, y, cell_w,
                       cell_h, colour(u));
      s += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"middle\" fill=\"{}\">{:.{}f}</text>\n",
                       x + cell_w / 2, y + cell_h / 2 + 4, u > 0.6 ? "black" : "white", v, map.value_decimals);
    }
  }
  for (Eigen::Index c = 0; c < cols; ++c)
    s += fmt::format("<text x=\"{:.1f}\" y=\"{:.0f}\" text-anchor=\"middle\">{:g}</text>\n", left + c * cell_w + cell_w / 2,
                     top + rows * cell_h + 16, map.x_values[static_cast<std::size_t>(c)]);
  s += fmt::format("<text x=\"{:.1f}\" y=\"{:.0f}\" text-anchor=\"middle\" font-size=\"13\">{}</text>\n",
                   left + cols * cell_w / 2, top + rows * cell_h + 40, io::xml_escape(map.x_label));
  s += fmt::format(
      "<text x=\"20\" y=\"{:.1f}\" text-anchor=\"middle\" font-size=\"13\" transform=\"rotate(-90 20 {:.1f})\">{}</text>\n",
      top + rows * cell_h / 2, top + rows * cell_h / 2, io::xml_escape(map.y_label));
  // Colour bar: top = max.
  const double bx = left + cols * cell_w + 24, bh = rows * cell_h;
  const int steps = 50;
  for (int i = 0; i < steps; ++i)
    s += fmt::format("<rect x=\"{:.0f}\" y=\"{:.2f}\" width=\"{:.0f}\" height=\"{:.2f}\" fill=\"{}\"/>\n", bx,
                     top + bh * i / steps, bar_w, bh / steps + 0.5, colour(1.0 - (i + 0.5) / steps));
  s += fmt::format("<text x=\"{:.0f}\" y=\"{:.0f}\">{:.{}f} {}</text>\n", bx + bar_w + 4, top + 10, hi,
                   map.value_decimals, io::xml_escape(map.unit));
  s += fmt::format("<text x=\"{:.0f}\" y=\"{:.0f}\">{:.{}f} {}</text>\n", bx + bar_w + 4, top + bh, lo,
                   map.value_decimals, io::xml_escape(map.unit));
  s += "</svg>\n";
  return s;
}

}  // namespace antpose::orientation
