#include "antpose/io/time.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

#include "antpose/core/error.hpp"

namespace antpose::io {
namespace {

constexpr std::int64_t kNsPerSecond = 1'000'000'000;

// Floor division, so instants before 1970 split into a negative second and a positive fraction.
std::int64_t floor_div(std::int64_t a, std::int64_t b) { return a / b - ((a % b != 0) && ((a < 0) != (b < 0))); }

bool digits(std::string_view s, std::size_t pos, std::size_t n, int& out) {
  if (pos + n > s.size()) return false;
  out = 0;
  for (std::size_t i = pos; i < pos + n; ++i) {
    if (s[i] < '0' || s[i] > '9') return false;
    out = out * 10 + (s[i] - '0');
  }
  return true;
}

}  // namespace

std::string format_utc_iso8601(std::int64_t unix_ns, int fraction_digits) {
  using namespace std::chrono;
  const std::int64_t secs = floor_div(unix_ns, kNsPerSecond);
  const std::int64_t ns = unix_ns - secs * kNsPerSecond;
  const sys_seconds tp{seconds{secs}};
  const auto day = floor<days>(tp);
  const year_month_day ymd{day};
  const hh_mm_ss hms{tp - day};
  std::string out = fmt::format("{:04}-{:02}-{:02}T{:02}:{:02}:{:02}", static_cast<int>(ymd.year()),
                                static_cast<unsigned>(ymd.month()), static_cast<unsigned>(ymd.day()), hms.hours().count(),
                                hms.minutes().count(), hms.seconds().count());
  fraction_digits = std::clamp(fraction_digits, 0, 9);
  if (fraction_digits > 0) {
    std::int64_t div = 1;
    for (int i = fraction_digits; i < 9; ++i) div *= 10;
    out += fmt::format(".{:0{}}", ns / div, fraction_digits);
  }
  return out + "Z";
}

std::optional<std::int64_t> parse_utc_iso8601(std::string_view s) {
  using namespace std::chrono;
  int y = 0, mo = 0, d = 0, h = 0, mi = 0, sec = 0;
  if (!digits(s, 0, 4, y) || s.size() < 19 || s[4] != '-' || !digits(s, 5, 2, mo) || s[7] != '-' || !digits(s, 8, 2, d) ||
      (s[10] != 'T' && s[10] != 't' && s[10] != ' ') || !digits(s, 11, 2, h) || s[13] != ':' || !digits(s, 14, 2, mi) ||
      s[16] != ':' || !digits(s, 17, 2, sec))
    return std::nullopt;
  const year_month_day ymd{year{y}, month{static_cast<unsigned>(mo)}, day{static_cast<unsigned>(d)}};
  if (!ymd.ok() || h > 23 || mi > 59 || sec > 60) return std::nullopt;
  std::size_t pos = 19;
  std::int64_t frac_ns = 0;
  if (pos < s.size() && (s[pos] == '.' || s[pos] == ',')) {
    ++pos;
    int n = 0;
    std::int64_t scale = 100'000'000;
    while (pos < s.size() && s[pos] >= '0' && s[pos] <= '9') {
      frac_ns += (s[pos] - '0') * scale;
      scale /= 10;
      ++pos;
      ++n;
    }
    if (n == 0) return std::nullopt;
  }
  std::int64_t offset_s = 0;
  if (pos == s.size()) return std::nullopt;  // a local time without a zone is ambiguous
  if (s[pos] == 'Z' || s[pos] == 'z') {
    ++pos;
  } else if (s[pos] == '+' || s[pos] == '-') {
    int oh = 0, om = 0;
    const int sign = s[pos] == '-' ? -1 : 1;
    if (!digits(s, pos + 1, 2, oh)) return std::nullopt;
    pos += 3;
    if (pos < s.size() && s[pos] == ':') ++pos;
    if (!digits(s, pos, 2, om)) return std::nullopt;
    pos += 2;
    if (oh > 23 || om > 59) return std::nullopt;
    offset_s = sign * (oh * 3600 + om * 60);
  }
  if (pos != s.size()) return std::nullopt;
  const std::int64_t day_s = static_cast<std::int64_t>(sys_days{ymd}.time_since_epoch().count()) * 86400;
  const std::int64_t secs = day_s + h * 3600 + mi * 60 + sec - offset_s;
  constexpr std::int64_t kMaxSeconds = std::numeric_limits<std::int64_t>::max() / kNsPerSecond - 1;
  if (secs > kMaxSeconds || secs < -kMaxSeconds) return std::nullopt;  // no int64 ns for it
  return secs * kNsPerSecond + frac_ns;
}

namespace {

void require_unix_seconds(double unix_seconds, const char* function) {
  if (!(unix_seconds >= 0.0 && unix_seconds <= kMaxUnixSeconds))
    throw std::invalid_argument(
        fmt::format("{}: {} s is no Unix time from 1970 to 2261 (check it where it is read: "
                    "checked_unix_seconds)",
                    function, unix_seconds));
}

}  // namespace

double checked_unix_seconds(double unix_seconds, const std::filesystem::path& file, std::size_t line,
                            std::string_view what) {
  if (!(unix_seconds >= 0.0 && unix_seconds <= kMaxUnixSeconds))
    throw InputError(file, line,
                     fmt::format("{} {} is not a UTC time in seconds since 1970 (expected 0 to {:.1e})", what,
                                 unix_seconds, kMaxUnixSeconds));
  return unix_seconds;
}

std::int64_t unix_seconds_to_ns_us(double unix_seconds, Rounding rounding) {
  require_unix_seconds(unix_seconds, "unix_seconds_to_ns_us");
  const double whole = std::floor(unix_seconds);
  const double frac = unix_seconds - whole;  // exact (Sterbenz): no bits are lost by the split
  const double us_real = frac * 1e6;
  auto us = static_cast<std::int64_t>(rounding == Rounding::kDown ? std::floor(us_real) : std::nearbyint(us_real));
  return static_cast<std::int64_t>(whole) * kNsPerSecond + us * 1000;
}

double seconds_since(double unix_seconds, std::int64_t origin_ns) {
  require_unix_seconds(unix_seconds, "seconds_since");
  const double whole = std::floor(unix_seconds);
  const double frac = unix_seconds - whole;
  const std::int64_t origin_s = floor_div(origin_ns, kNsPerSecond);
  const std::int64_t origin_frac_ns = origin_ns - origin_s * kNsPerSecond;
  return static_cast<double>(static_cast<std::int64_t>(whole) - origin_s) + (frac - static_cast<double>(origin_frac_ns) * 1e-9);
}

}  // namespace antpose::io
