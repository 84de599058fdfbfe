// The native capture folder (../shared/notes/capture-format.md §1): data model, reader, writer.
//
// Times are seconds on the capture clock (t = 0 at `time_origin`), vectors are in the sensor
// frame named by `sensor_frame`, accelerometer m/s^2 (specific force), gyroscope rad/s,
// magnetometer µT.
#pragma once

#include <cstddef>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>
#include <yaml-cpp/yaml.h>

#include "antpose/core/error.hpp"
#include "antpose/geometry/rotation.hpp"

namespace antpose {

/// One sensor stream: a time column and value columns, one row per sample.
struct Stream {
  using Values = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

  std::string name;                  // file stem: "accelerometer", "gyroscope", "magnetometer", ...
  std::vector<std::string> columns;  // value column names after "t", e.g. {"x", "y", "z"}
  std::vector<double> t;             // s, strictly increasing
  Values values;                     // size() × columns.size()
  bool gzip = false;                 // written as .csv.gz
  /// Where the rows were read from, for messages: the file and each row's 1-based line. Empty
  /// for streams built in memory (messages then name the native file the row would be written
  /// to). Importers set the source file; lines only when rows map 1:1 to lines of it.
  std::filesystem::path source_file;
  std::vector<std::size_t> source_lines;

  std::size_t size() const { return t.size(); }
  bool empty() const { return t.empty(); }
  /// True when the first three value columns are x, y, z.
  bool has_xyz() const;
  /// Row i's x, y, z (requires has_xyz()).
  Vec3 xyz(std::size_t i) const { return values.row(static_cast<Eigen::Index>(i)).head<3>().transpose(); }
  double duration() const { return empty() ? 0.0 : t.back() - t.front(); }
  /// 1-based line of row i in source_file (row index + 2 for an in-memory stream, i.e. the line
  /// it gets when written; 0 when the source has no line per row).
  std::size_t source_line(std::size_t i) const;

  /// A stream with columns x, y, z.
  static Stream vector3(std::string name, std::vector<double> t, const std::vector<Vec3>& xyz);
};

namespace streams {
inline constexpr std::string_view kAccelerometer = "accelerometer";
inline constexpr std::string_view kGyroscope = "gyroscope";
inline constexpr std::string_view kMagnetometer = "magnetometer";
/// The unit of a stream's x, y, z values (capture-format.md §1); empty where the format does not
/// fix one (other streams).
constexpr std::string_view unit_of(std::string_view stream) {
  if (stream == kAccelerometer || stream == "gravity" || stream == "linear_acceleration") return "m/s^2";
  if (stream == kGyroscope) return "rad/s";
  if (stream == kMagnetometer) return "uT";
  return {};
}
}  // namespace streams

struct Site {
  double lat_deg = 0.0;  // WGS84 geodetic latitude
  double lon_deg = 0.0;  // east positive
  double alt_m = 0.0;    // above the WGS84 ellipsoid
  std::string date;      // YYYY-MM-DD, for the magnetic model
};

struct Shot {
  int index = 0;
  double t = 0.0;                       // shutter opening, capture clock
  std::string image;                    // path relative to the capture folder
  std::optional<double> exposure_s;
  std::vector<std::string> extra;       // values of Capture::shot_extra_columns, in order
  std::filesystem::path source;         // where to copy the image from when writing (empty: capture root)
  std::size_t source_line = 0;          // 1-based line in Capture::shots_file (0: unknown / in memory)
};

struct Capture {
  static constexpr int kFormatVersion = 1;

  std::string kind = "imu-log";  // imu-log | contact | imu-calibration | camera-calibration | joint-calibration | antenna
  std::optional<std::string> time_origin;  // ISO-8601 UTC instant of t = 0
  std::string device_model;
  std::string device_id;
  std::string sensor_frame = "android";  // android | other
  std::optional<Site> site;

  std::map<std::string, Stream> streams;  // by name
  std::vector<Shot> shots;
  std::vector<std::string> shot_extra_columns;
  /// File the shots were read from, for messages (shots.csv, or an importer's source file).
  std::filesystem::path shots_file;

  std::optional<Stream> truth_orientation;  // t,qw,qx,qy,qz[,valid,moving]; q_world_body
  std::string truth_world;                  // enu-true | enu-magnetic | unaligned

  /// capture.yaml as read; unknown keys survive a rewrite. `source:` lives here too.
  YAML::Node metadata;
  /// Folder the capture was read from (images and other files are copied from here).
  std::filesystem::path root;
  /// Other files of the folder (board.yaml, truth/scene.yaml, ...), relative to root; copied as-is.
  std::vector<std::filesystem::path> other_files;
  /// Text files made in memory (e.g. a simulator's truth/device.yaml), relative path → content;
  /// written after other_files (replacing a copied file of the same name). A capture read back
  /// lists them in other_files.
  std::map<std::filesystem::path, std::string> generated_files;

  const Stream* find(std::string_view name) const;
  /// The stream, or an InputError naming capture.yaml's folder and the streams it has.
  const Stream& require(std::string_view name) const;
};

struct CaptureReadOptions {
  /// Convert a stream detected in the wrong unit (accelerometer in g, magnetometer in gauss
  /// or nT) with a warning. When false, such a stream is an error.
  bool repair_units = true;
  /// A gap between samples longer than this many median sample intervals is reported.
  double gap_factor = 10.0;
};

/// Reads and validates a native capture folder. Errors name the file and line; repairs and
/// doubts go to `diagnostics`.
Capture read_capture(const std::filesystem::path& folder, Diagnostics& diagnostics,
                     const CaptureReadOptions& options = {});

/// InputError naming capture.yaml unless the streams are in Android's device frame, which the
/// attitude of `what` ("the contact measurement") is defined in: with sensor_frame: other only
/// the truth relates the axes to the phone, so an attitude read from them would be silently wrong.
void require_android_frame(const Capture& capture, std::string_view what);

/// `folder / name` for a file a capture holds by a fixed name (board.yaml), refused (InputError)
/// when a symbolic link takes it out of the capture folder.
std::filesystem::path capture_file(const std::filesystem::path& folder, std::string_view name);

struct CaptureWriteOptions {
  bool overwrite = false;  // replace an existing folder (only after the new one is complete)
};

/// Writes a capture folder: built in a temporary sibling folder, then renamed into place, so a
/// failure never leaves a half-written capture or loses an existing one.
void write_capture(const Capture& capture, const std::filesystem::path& folder, const CaptureWriteOptions& options = {});

/// Checks the streams of an in-memory capture (as read_capture does after parsing): non-empty,
/// increasing time, plausible units (repairing them when allowed), shots inside the sensor span.
/// `folder` is used to name files in messages. Importers call this too.
void validate_capture(Capture& capture, const std::filesystem::path& folder, Diagnostics& diagnostics,
                      const CaptureReadOptions& options = {});

/// Path of a stream's file inside a capture folder (sensors/<name>.csv or .csv.gz).
std::filesystem::path stream_path(const std::filesystem::path& folder, const Stream& stream);

/// The file to name in messages about a stream: its source_file, else stream_path(folder, stream).
std::filesystem::path stream_source(const std::filesystem::path& folder, const Stream& stream);

}  // namespace antpose
