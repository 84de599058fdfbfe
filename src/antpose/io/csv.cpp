#include "antpose/io/csv.hpp"

#include <charconv>
#include <cmath>

#include <fmt/format.h>

#include "antpose/core/error.hpp"
#include "antpose/io/text_file.hpp"

namespace antpose::io {

std::ptrdiff_t CsvText::find_column(std::string_view name) const {
  for (std::size_t i = 0; i < header.size(); ++i)
    if (header[i] == name) return static_cast<std::ptrdiff_t>(i);
  return -1;
}

std::size_t CsvText::column(std::string_view name) const {
  const auto i = find_column(name);
  if (i < 0) throw InputError(file, 1, fmt::format("missing column '{}' (header has: {})", name, fmt::join(header, ",")));
  return static_cast<std::size_t>(i);
}

std::vector<std::string> split_csv_line(std::string_view line) {
  std::vector<std::string> fields;
  std::string field;
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        field += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        field += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      fields.push_back(std::move(field));
      field.clear();
    } else {
      field += c;
    }
  }
  fields.push_back(std::move(field));
  return fields;
}

CsvText read_csv(const std::filesystem::path& file) {
  const std::string text = read_text(file);
  CsvText out;
  out.file = file;
  std::size_t line_no = 0;
  std::size_t pos = 0;
  bool have_header = false;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    std::string_view line(text.data() + pos, end - pos);
    pos = end + 1;
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (line_no == 1 && line.starts_with("\xEF\xBB\xBF")) line.remove_prefix(3);  // UTF-8 BOM
    if (line.find_first_not_of(" \t") == std::string_view::npos) continue;
    auto fields = split_csv_line(line);
    for (auto& f : fields) {  // tolerate spaces after commas
      const auto a = f.find_first_not_of(' ');
      const auto b = f.find_last_not_of(' ');
      f = a == std::string::npos ? std::string() : f.substr(a, b - a + 1);
    }
    if (!have_header) {
      out.header = std::move(fields);
      have_header = true;
      continue;
    }
    if (fields.size() < out.header.size())
      throw InputError(file, line_no,
                       fmt::format("{} fields, expected {} ({})", fields.size(), out.header.size(), fmt::join(out.header, ",")));
    out.rows.push_back(std::move(fields));
    out.lines.push_back(line_no);
  }
  if (!have_header) throw InputError(file, "empty file, expected a CSV header line");
  return out;
}

double parse_number(std::string_view text, const std::filesystem::path& file, std::size_t line,
                    std::string_view column, NonFinite non_finite) {
  std::string_view s = text;
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  double value = 0.0;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (s.empty() || ec == std::errc::invalid_argument || ptr != s.data() + s.size())
    throw InputError(file, line, fmt::format("column '{}': '{}' is not a number", column, text));
  if (ec == std::errc::result_out_of_range)
    throw InputError(file, line, fmt::format("column '{}': '{}' is out of the range of a double", column, text));
  if (!std::isfinite(value) && non_finite == NonFinite::kReject)
    throw InputError(file, line, fmt::format("column '{}': '{}' is not a finite number (NaN/Inf not allowed here)", column, text));
  return value;
}

std::optional<double> parse_finite(std::string_view s) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  double v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

std::int64_t parse_int64(std::string_view text, const std::filesystem::path& file, std::size_t line, std::string_view column) {
  std::string_view s = text;
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  std::int64_t value = 0;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (s.empty() || ec == std::errc::invalid_argument || ptr != s.data() + s.size())
    throw InputError(file, line, fmt::format("column '{}': '{}' is not an integer", column, text));
  if (ec == std::errc::result_out_of_range)
    throw InputError(file, line, fmt::format("column '{}': '{}' is out of the range of a 64-bit integer", column, text));
  return value;
}

std::string format_number(double value) {
  char buffer[64];
  const auto [ptr, ec] = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, ptr);
}

std::string join_csv_line(const std::vector<std::string>& fields) {
  std::string out;
  for (std::size_t i = 0; i < fields.size(); ++i) {
    if (i) out += ',';
    const auto& f = fields[i];
    if (f.find_first_of(",\"\n") == std::string::npos) {
      out += f;
    } else {
      out += '"';
      for (char c : f) out += c == '"' ? std::string("\"\"") : std::string(1, c);
      out += '"';
    }
  }
  return out;
}

}  // namespace antpose::io
