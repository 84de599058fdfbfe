// UTC instants as the capture format writes them (capture.yaml: time_origin), ISO-8601 with a
// 'Z' suffix, e.g. 2024-03-27T07:13:15.018936600Z. Instants are kept as integer nanoseconds
// since 1970-01-01T00:00:00Z (no leap seconds, like Unix time), so phone-logger time stamps in
// ns survive without rounding.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace antpose::io {

/// "YYYY-MM-DDTHH:MM:SS[.fff…]Z" for `unix_ns`, with `fraction_digits` (0–9) digits after the
/// seconds, truncated (not rounded) so the text never lies after the instant.
std::string format_utc_iso8601(std::int64_t unix_ns, int fraction_digits = 9);

/// Parses "YYYY-MM-DDTHH:MM:SS[.fraction](Z|±HH:MM)" (a space instead of 'T' is accepted) into
/// ns since 1970 UTC. Digits beyond ns are dropped. Returns nullopt when the text is not such an
/// instant (wrong layout, month 13, hour 25, ...) or one that int64 ns cannot hold (before 1678
/// or after 2262).
std::optional<std::int64_t> parse_utc_iso8601(std::string_view text);

enum class Rounding { kNearest, kDown };

/// The Unix times (s) that int64 ns since 1970 hold, with a margin: 1970 to about 2261.
inline constexpr double kMaxUnixSeconds = 9.2e9;

/// `unix_seconds`, read from `file` at `line` as `what`, checked to lie in [0, kMaxUnixSeconds]:
/// InputError otherwise (a phone's clock never reads before 1970, and a value past 2261 is no time
/// the format can hold).
double checked_unix_seconds(double unix_seconds, const std::filesystem::path& file, std::size_t line,
                            std::string_view what);

/// Converts a Unix time in seconds held as a double (as the thesis app and phyphox write it) to
/// ns, rounded to a whole µs: a double near 1.7e9 s resolves 2.4e-7 s, so digits below the µs
/// are noise of the binary representation, not data. kDown keeps the result ≤ the input (an
/// origin that no sample precedes).
/// `unix_seconds` must be in [0, kMaxUnixSeconds] (std::invalid_argument otherwise: check it
/// with checked_unix_seconds where it is read).
std::int64_t unix_seconds_to_ns_us(double unix_seconds, Rounding rounding = Rounding::kNearest);

/// `unix_seconds` − `origin_ns` in seconds. The whole seconds are subtracted as integers and only
/// the fractions in floating point, so the result carries the full resolution of the input
/// double (error < 1e-15 s for captures shorter than a day) instead of the 2.4e-7 s of a
/// difference of two rounded epochs.
/// The same precondition on `unix_seconds`.
double seconds_since(double unix_seconds, std::int64_t origin_ns);

}  // namespace antpose::io
