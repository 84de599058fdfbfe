// The CLI is a thin layer: each verb parses its options and calls the library.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "antpose/core/error.hpp"

namespace antpose::cli {

/// Exit statuses, the contract scripts rely on (README "Exit codes"; `antpose --help`).
enum ExitStatus : int {
  kExitOk = 0,           // every requested result is usable
  kExitInternal = 1,     // an internal fault (a bug to report) or the machine out of memory
  kExitBadInput = 2,     // bad input, a command-line misuse, or an output that cannot be written
  kExitUnsupported = 3,  // the data cannot support the measurement
  kExitPartial = 4,      // results written, but some unusable (a failed antenna, σ over --max-sigma-deg)
};
inline constexpr const char* kExitStatusHelp =
    "Exit status: 0 every requested result is usable; 2 bad input, a command-line misuse or an output that "
    "cannot be written; 3 the data cannot support the measurement; 4 results written but some unusable "
    "(a failed antenna, a sigma over --max-sigma-deg); 1 an internal fault.";

void add_convert_command(CLI::App& app);
void add_inspect_command(CLI::App& app);
void add_wmm_command(CLI::App& app);
void add_contact_command(CLI::App& app);
void add_measure_command(CLI::App& app);
void add_simulate_command(CLI::App& app);
void add_bench_command(CLI::App& app);
void add_orientation_command(CLI::App& app);
void add_calibrate_command(CLI::App& app);
void add_device_command(CLI::App& app);
// Sub-verbs registered by their parent verb.
void add_calibrate_camera_command(CLI::App& calibrate);
void add_calibrate_joint_command(CLI::App& calibrate);
void add_simulate_capture_command(CLI::App& simulate);
void add_bench_measure_command(CLI::App& bench);

/// The warning for a device profile without an IMU calibration, where the compass matters.
inline constexpr const char* kNoImuCalibrationWarning =
    "the device has no IMU calibration: the magnetometer's hard iron turns the azimuth by degrees; run 'antpose "
    "calibrate imu --device' first";

/// Prints each warning as "warning: <file>:<line>: <message>" on stderr.
void print_warnings(const Diagnostics& diagnostics);

/// Capture folders (holding capture.yaml) and the capture folders inside other folders, sorted by
/// name within each; InputError for a folder that is neither.
std::vector<std::filesystem::path> capture_folders(const std::vector<std::string>& dirs);

}  // namespace antpose::cli
