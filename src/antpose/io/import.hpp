// Importers: phone-logger exports and the thesis's collection-app project → native Capture
// (../shared/notes/capture-format.md §2–3).
//
// Every importer returns a Capture in the native conventions (t in s on one clock, Android device
// frame, accelerometer = specific force in m/s^2, gyroscope rad/s, magnetometer µT), runs
// validate_capture on it, and records in metadata `source:` which files it read, which it
// skipped and what it assumed (units, sign conventions, gravity). The capture's `root` is the
// input folder; write it with write_capture.
#pragma once

#include <filesystem>
#include <string_view>

#include "antpose/io/capture.hpp"

namespace antpose {

enum class CaptureFormat {
  kNative,          // capture.yaml + sensors/*.csv
  kThesisProject,   // collection-proj.xml + sensor_N.xml + pic_N.jpg
  kSensorLogger,    // Sensor Logger CSV export (Metadata.csv, Accelerometer.csv: time,seconds_elapsed,z,y,x)
  kPhyphox,         // phyphox CSV export ("Time (s)" headers, meta/time.csv)
};

/// "native", "thesis-project", "sensor-logger", "phyphox".
std::string_view to_string(CaptureFormat format);

/// The layout of `in` (a folder, or the collection-proj.xml / capture.yaml inside one). Throws
/// InputError naming `in` and listing the accepted layouts when none matches.
CaptureFormat detect_capture_format(const std::filesystem::path& in);

/// Thesis collection-app project. Times (UTC s since 1970, doubles) become t = utc − origin with
/// time_origin the earliest sample or shot (to the µs, rounded down). Frames of overlapping
/// sensor_N.xml files are merged per channel: exact duplicates (same time, same values) are
/// dropped, disagreeing ones (same time, different values) keep the first file's frame and are
/// reported. Pictures become shots with images/pic_N.jpg (Shot::source: the original).
Capture import_thesis_project(const std::filesystem::path& folder, Diagnostics& diagnostics,
                              const CaptureReadOptions& options = {});

/// Sensor Logger (Kelvin Choi) CSV export. `time` is read as integer ns; t = (time − origin)/1e9
/// with the origin the earliest kept sample. Android's "Accelerometer" is linear acceleration:
/// specific force = Accelerometer + Gravity (or TotalAcceleration when exported).
Capture import_sensor_logger(const std::filesystem::path& folder, Diagnostics& diagnostics,
                             const CaptureReadOptions& options = {});

/// phyphox CSV export. Units are read from the headers ("X (m/s^2)") and converted to the
/// capture's; an unknown unit is an error. time_origin = START "system time" of meta/time.csv.
Capture import_phyphox(const std::filesystem::path& folder, Diagnostics& diagnostics, const CaptureReadOptions& options = {});

/// Detects the format of `in` and reads it (read_capture for a native folder).
Capture import_capture(const std::filesystem::path& in, Diagnostics& diagnostics, const CaptureReadOptions& options = {});

}  // namespace antpose
