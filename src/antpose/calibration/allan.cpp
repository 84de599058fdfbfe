#include "antpose/calibration/allan.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "antpose/core/statistics.hpp"

namespace antpose::calibration {

std::vector<std::size_t> octave_factors(std::size_t phase_points) {
  std::vector<std::size_t> m;
  for (std::size_t f = 1; 2 * f < phase_points; f *= 2) m.push_back(f);
  return m;
}

std::vector<std::size_t> all_factors(std::size_t phase_points) {
  std::vector<std::size_t> m;
  for (std::size_t f = 1; 2 * f < phase_points; ++f) m.push_back(f);
  return m;
}

std::vector<std::size_t> log_factors(std::size_t phase_points, int per_decade) {
  std::vector<std::size_t> m;
  for (int k = 0;; ++k) {
    const auto f = static_cast<std::size_t>(std::llround(std::pow(10.0, static_cast<double>(k) / per_decade)));
    if (2 * f >= phase_points) break;
    if (m.empty() || f != m.back()) m.push_back(f);
  }
  return m;
}

std::vector<AllanPoint> oadev_phase(const std::vector<double>& x, double tau0, const std::vector<std::size_t>& factors) {
  if (x.size() < 3) throw std::invalid_argument(fmt::format("Allan deviation needs at least 3 phase points, got {}", x.size()));
  if (!(tau0 > 0.0)) throw std::invalid_argument(fmt::format("Allan deviation: tau0 must be positive, got {}", tau0));
  const std::size_t N = x.size();
  std::vector<AllanPoint> out;
  for (const std::size_t m : factors) {
    if (m == 0 || 2 * m >= N) continue;
    long double sum = 0.0L;
    for (std::size_t i = 0; i + 2 * m < N; ++i) {
      const long double d = static_cast<long double>(x[i + 2 * m]) - 2.0L * x[i + m] + x[i];
      sum += d * d;
    }
    const std::size_t n = N - 2 * m;
    const double tau = static_cast<double>(m) * tau0;
    out.push_back({m, tau, n, static_cast<double>(std::sqrt(sum / (2.0L * n * tau * tau)))});
  }
  return out;
}

namespace {
// Phase of frequency data. The mean is removed first: it does not change any second difference
// but keeps the running sum small, so the differences keep their precision on long logs.
std::vector<double> integrate(const std::vector<double>& y, double tau0) {
  long double mean = 0.0L;
  for (double v : y) mean += v;
  mean /= static_cast<long double>(std::max<std::size_t>(y.size(), 1));
  std::vector<double> x(y.size() + 1, 0.0);
  long double acc = 0.0L;
  for (std::size_t i = 0; i < y.size(); ++i) {
    acc += (static_cast<long double>(y[i]) - mean) * tau0;
    x[i + 1] = static_cast<double>(acc);
  }
  return x;
}
}  // namespace

std::vector<AllanPoint> oadev_frequency(const std::vector<double>& y, double tau0, const std::vector<std::size_t>& m) {
  if (y.size() < 2) throw std::invalid_argument(fmt::format("Allan deviation needs at least 2 frequency values, got {}", y.size()));
  return oadev_phase(integrate(y, tau0), tau0, m);
}

std::vector<AllanPoint> adev_frequency(const std::vector<double>& y, double tau0, const std::vector<std::size_t>& factors) {
  const std::vector<double> x = integrate(y, tau0);
  std::vector<AllanPoint> out;
  for (const std::size_t m : factors) {
    if (m == 0 || 2 * m >= x.size()) continue;
    long double sum = 0.0L;
    std::size_t n = 0;
    for (std::size_t i = 0; i + 2 * m < x.size(); i += m, ++n) {
      const long double d = static_cast<long double>(x[i + 2 * m]) - 2.0L * x[i + m] + x[i];
      sum += d * d;
    }
    const double tau = static_cast<double>(m) * tau0;
    out.push_back({m, tau, n, static_cast<double>(std::sqrt(sum / (2.0L * n * tau * tau)))});
  }
  return out;
}

NoiseFit fit_noise(const std::vector<AllanPoint>& curve) {
  NoiseFit fit;
  std::vector<AllanPoint> c;
  for (const auto& p : curve)
    if (p.deviation > 0.0 && std::isfinite(p.deviation)) c.push_back(p);
  if (c.size() < 3) return fit;
  const std::size_t n = c.size();
  std::vector<double> slope(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t a = i == 0 ? 0 : i - 1, b = i + 1 == n ? n - 1 : i + 1;
    slope[i] = std::log(c[b].deviation / c[a].deviation) / std::log(c[b].tau / c[a].tau);
  }
  // The points whose local slope is nearest `target` (within 0.1 of the best, and within 0.25
  // of target) give the line's level; `at` converts σ(τ) on the line to the coefficient.
  auto line = [&](double target, auto&& at) -> std::optional<double> {
    double best = 1e9;
    for (double s : slope) best = std::min(best, std::abs(s - target));
    if (best > 0.25) return std::nullopt;
    double log_sum = 0.0;
    int count = 0;
    for (std::size_t i = 0; i < n; ++i)
      if (std::abs(slope[i] - target) <= std::min(best + 0.1, 0.25)) {
        log_sum += std::log(at(c[i]));
        ++count;
      }
    return std::exp(log_sum / count);
  };
  fit.white = line(-0.5, [](const AllanPoint& p) { return p.deviation * std::sqrt(p.tau); });
  fit.random_walk = line(0.5, [](const AllanPoint& p) { return p.deviation * std::sqrt(3.0 / p.tau); });
  const auto min_it = std::min_element(c.begin(), c.end(), [](const auto& a, const auto& b) { return a.deviation < b.deviation; });
  if (min_it + 1 != c.end()) {
    // 0.664 = sqrt(2 ln 2 / π): the flicker floor of the Allan deviation (IEEE 952 C.1.3).
    fit.bias_instability = min_it->deviation / 0.664;
    fit.bias_instability_tau = min_it->tau;
  }
  return fit;
}

std::string allan_svg(const std::vector<AllanSeries>& series, const std::string& title, const std::string& unit) {
  double tmin = 1e300, tmax = 0, smin = 1e300, smax = 0;
  for (const auto& s : series)
    for (const auto& p : s.curve) {
      if (!(p.deviation > 0)) continue;
      tmin = std::min(tmin, p.tau), tmax = std::max(tmax, p.tau);
      smin = std::min(smin, p.deviation), smax = std::max(smax, p.deviation);
    }
  if (tmax <= 0) throw std::invalid_argument("allan_svg: no points to plot");
  const double lx0 = std::floor(std::log10(tmin)), lx1 = std::max(lx0 + 1, std::ceil(std::log10(tmax)));
  const double ly0 = std::floor(std::log10(smin)), ly1 = std::max(ly0 + 1, std::ceil(std::log10(smax)));
  const double W = 720, H = 520, L = 80, R = 20, T = 40, B = 60;
  auto X = [&](double tau) { return L + (std::log10(tau) - lx0) / (lx1 - lx0) * (W - L - R); };
  auto Y = [&](double s) { return H - B - (std::log10(s) - ly0) / (ly1 - ly0) * (H - T - B); };
  std::string svg = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{}\" height=\"{}\" font-family=\"sans-serif\" font-size=\"12\">\n"
      "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n<text x=\"{}\" y=\"24\" font-size=\"15\">{}</text>\n",
      W, H, L, title);
  for (double e = lx0; e <= lx1; ++e)
    svg += fmt::format("<line x1=\"{0}\" y1=\"{1}\" x2=\"{0}\" y2=\"{2}\" stroke=\"#ddd\"/><text x=\"{0}\" y=\"{3}\" "
                       "text-anchor=\"middle\">1e{4}</text>\n",
                       X(std::pow(10, e)), T, H - B, H - B + 18, e);
  for (double e = ly0; e <= ly1; ++e)
    svg += fmt::format("<line x1=\"{0}\" y1=\"{1}\" x2=\"{2}\" y2=\"{1}\" stroke=\"#ddd\"/><text x=\"{3}\" y=\"{4}\" "
                       "text-anchor=\"end\">1e{5}</text>\n",
                       L, Y(std::pow(10, e)), W - R, L - 6, Y(std::pow(10, e)) + 4, e);
  svg += fmt::format("<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">τ (s)</text>\n", (L + W - R) / 2, H - 15);
  svg += fmt::format("<text x=\"18\" y=\"{}\" transform=\"rotate(-90 18 {})\" text-anchor=\"middle\">Allan deviation ({})</text>\n",
                     (T + H - B) / 2, (T + H - B) / 2, unit);
  const char* colours[] = {"#d62728", "#2ca02c", "#1f77b4", "#9467bd", "#ff7f0e", "#8c564b"};
  const double t_lo = std::pow(10, lx0), t_hi = std::pow(10, lx1);
  for (std::size_t k = 0; k < series.size(); ++k) {
    const auto& s = series[k];
    const char* colour = colours[k % 6];
    std::string pts;
    for (const auto& p : s.curve)
      if (p.deviation > 0) pts += fmt::format("{:.1f},{:.1f} ", X(p.tau), Y(p.deviation));
    svg += fmt::format("<polyline fill=\"none\" stroke=\"{}\" stroke-width=\"2\" points=\"{}\"/>\n", colour, pts);
    auto dashed = [&](auto&& sigma) {
      const double s0 = sigma(t_lo), s1 = sigma(t_hi);
      svg += fmt::format("<line x1=\"{}\" y1=\"{:.1f}\" x2=\"{}\" y2=\"{:.1f}\" stroke=\"{}\" stroke-dasharray=\"5,4\" "
                         "clip-path=\"url(#plot)\"/>\n",
                         X(t_lo), Y(s0), X(t_hi), Y(s1), colour);
    };
    if (s.fit.white) dashed([&](double tau) { return *s.fit.white / std::sqrt(tau); });
    if (s.fit.random_walk) dashed([&](double tau) { return *s.fit.random_walk * std::sqrt(tau / 3.0); });
    if (s.fit.bias_instability) dashed([&](double) { return *s.fit.bias_instability * 0.664; });
    svg += fmt::format("<text x=\"{}\" y=\"{}\" fill=\"{}\">{}</text>\n", W - R - 260, T + 16 + 16 * k, colour, s.label);
  }
  svg += fmt::format("<clipPath id=\"plot\"><rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\"/></clipPath>\n</svg>\n", L, T,
                     W - L - R, H - T - B);
  return svg;
}

}  // namespace antpose::calibration

namespace antpose::calibration {

StreamAllan allan_of_stream(const Stream& stream, Diagnostics& diagnostics, const std::filesystem::path& source,
                            int per_decade) {
  if (stream.size() < 100)
    throw MeasurementError(fmt::format("{}{}Allan deviation: stream '{}' has {} samples, need at least 100 (a static log "
                                       "of an hour or more gives the bias instability and random walk)",
                                       source.string(), source.empty() ? "" : ": ", stream.name, stream.size()));
  StreamAllan out;
  out.stream = stream.name;
  std::vector<double> dt(stream.size() - 1);
  for (std::size_t i = 0; i + 1 < stream.size(); ++i) dt[i] = stream.t[i + 1] - stream.t[i];
  out.tau0 = median(dt);
  std::size_t gaps = 0;
  for (double d : dt) gaps += d > 1.5 * out.tau0 ? 1 : 0;
  if (gaps > 0)
    diagnostics.warn(source, 0, fmt::format("stream '{}' has {} gaps longer than 1.5 sample intervals ({:.4f} s); the "
                                            "Allan deviation treats the samples as equally spaced",
                                            stream.name, gaps, out.tau0));
  const auto factors = log_factors(stream.size() + 1, per_decade);
  for (std::size_t c = 0; c < stream.columns.size(); ++c) {
    std::vector<double> y(stream.size());
    for (std::size_t i = 0; i < stream.size(); ++i)
      y[i] = stream.values(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(c));
    out.axes.push_back(stream.columns[c]);
    out.curves.push_back(oadev_frequency(y, out.tau0, factors));
    out.fits.push_back(fit_noise(out.curves.back()));
  }
  return out;
}

}  // namespace antpose::calibration
