#include "antpose/io/import.hpp"

#include <fmt/format.h>

#include "antpose/io/csv.hpp"
#include "antpose/io/import_detail.hpp"
#include "antpose/io/text_file.hpp"

namespace antpose {
namespace fs = std::filesystem;

namespace {

constexpr const char* kAccepted =
    "accepted layouts: (1) native capture folder: capture.yaml + sensors/*.csv[.gz]; "
    "(2) thesis collection-app project: collection-proj.xml + sensor_N.xml + pic_N.jpg; "
    "(3) Sensor Logger CSV export: Metadata.csv and Accelerometer.csv/Gyroscope.csv/Magnetometer.csv with columns "
    "time,seconds_elapsed,z,y,x; "
    "(4) phyphox CSV export: Accelerometer.csv/Gyroscope.csv/Magnetometer.csv with \"Time (s)\" headers and meta/time.csv";

// First line of a CSV file (BOM and quotes left in), or "" when unreadable.
std::string first_line(const fs::path& file) {
  try {
    const std::string text = io::read_text(file);
    return text.substr(0, text.find('\n'));
  } catch (const InputError&) {
    return {};
  }
}

}  // namespace

std::string_view to_string(CaptureFormat format) {
  switch (format) {
    case CaptureFormat::kNative: return "native";
    case CaptureFormat::kThesisProject: return "thesis-project";
    case CaptureFormat::kSensorLogger: return "sensor-logger";
    case CaptureFormat::kPhyphox: return "phyphox";
  }
  return "unknown";
}

CaptureFormat detect_capture_format(const fs::path& in) {
  if (!fs::exists(in)) throw InputError(in, "not found");
  if (fs::is_regular_file(in)) {
    if (in.filename() == "capture.yaml") return CaptureFormat::kNative;
    if (io::detail::lower(in.filename().string()) == "collection-proj.xml") return CaptureFormat::kThesisProject;
    throw InputError(in, fmt::format("is a file, expected a capture folder; {}", kAccepted));
  }
  if (fs::exists(in / "capture.yaml")) return CaptureFormat::kNative;
  if (fs::exists(in / "collection-proj.xml")) return CaptureFormat::kThesisProject;
  for (const char* sensor : {"Accelerometer.csv", "Gyroscope.csv", "Magnetometer.csv", "TotalAcceleration.csv"}) {
    if (!fs::exists(in / sensor)) continue;
    const std::string head = first_line(in / sensor);
    if (head.starts_with("time,seconds_elapsed")) return CaptureFormat::kSensorLogger;
    if (head.starts_with("\"Time (s)\"") || head.starts_with("Time (s)")) return CaptureFormat::kPhyphox;
  }
  if (fs::exists(in / "Metadata.csv")) return CaptureFormat::kSensorLogger;
  if (fs::exists(in / "meta" / "time.csv")) return CaptureFormat::kPhyphox;
  throw InputError(in, fmt::format("not a capture antpose can read; {}", kAccepted));
}

Capture import_capture(const fs::path& in, Diagnostics& diagnostics, const CaptureReadOptions& options) {
  const CaptureFormat format = detect_capture_format(in);
  switch (format) {
    case CaptureFormat::kNative: {
      const fs::path folder = fs::is_regular_file(in) ? in.parent_path() : in;
      return read_capture(folder.empty() ? fs::path(".") : folder, diagnostics, options);
    }
    case CaptureFormat::kThesisProject: return import_thesis_project(in, diagnostics, options);
    case CaptureFormat::kSensorLogger: return import_sensor_logger(in, diagnostics, options);
    case CaptureFormat::kPhyphox: return import_phyphox(in, diagnostics, options);
  }
  throw Error("unreachable capture format");
}

}  // namespace antpose
