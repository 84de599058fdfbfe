// CSV tables as the capture format uses them: a header line, then records. Quoted fields
// (phyphox) and CRLF line ends are accepted. Numbers are parsed strictly and every error
// names the file, the 1-based line and the column.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace antpose::io {

/// A CSV file split into fields, each record remembering its line number.
struct CsvText {
  std::filesystem::path file;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  std::vector<std::size_t> lines;  // 1-based line of each row

  /// Index of a header column; throws InputError naming the file and the columns it has.
  std::size_t column(std::string_view name) const;
  /// Index of a header column, or -1.
  std::ptrdiff_t find_column(std::string_view name) const;
};

/// Reads and splits a CSV file (plain or gzip). Blank lines are skipped. A file without a
/// header line is an error; rows with fewer fields than the header are an error naming the line.
CsvText read_csv(const std::filesystem::path& file);

/// Splits one CSV line; quotes are removed and "" inside quotes becomes ".
std::vector<std::string> split_csv_line(std::string_view line);

enum class NonFinite { kReject, kAllow };

/// Parses a decimal number ("1.920097500E-1", "-3", "nan" only with NonFinite::kAllow).
/// Throws InputError "<file>:<line>: column '<column>': '<text>' is not a number" etc.
double parse_number(std::string_view text, const std::filesystem::path& file, std::size_t line,
                    std::string_view column, NonFinite non_finite = NonFinite::kReject);

/// A finite decimal number ("+" allowed), or nullopt: for formats whose own errors say more
/// than a column name (mesh and box files).
std::optional<double> parse_finite(std::string_view text);

/// Parses a decimal integer (Sensor Logger's ns time stamps) without going through a double,
/// so 19-digit values keep every digit. Errors name the file, line, column and the text.
std::int64_t parse_int64(std::string_view text, const std::filesystem::path& file, std::size_t line, std::string_view column);

/// Shortest decimal text that reads back as exactly the same double.
std::string format_number(double value);

/// Formats a CSV line from fields, quoting fields that contain a comma, quote or newline.
std::string join_csv_line(const std::vector<std::string>& fields);

}  // namespace antpose::io
