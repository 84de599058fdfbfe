// antpose <verb> ...: entry point. Errors end the program with a message and a non-zero status:
// 2 for bad input, 3 for a measurement that the data cannot support, 1 for anything else.
#include <cstdio>
#include <exception>
#include <sstream>

#include <fmt/core.h>

#include "antpose/core/allocator.hpp"
#include "commands.hpp"

namespace antpose::cli {

void print_warnings(const Diagnostics& diagnostics) {
  for (const auto& w : diagnostics.warnings()) fmt::print(stderr, "warning: {}\n", w.to_string());
}

std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

}  // namespace antpose::cli

int main(int argc, char** argv) {
  antpose::tune_allocator();  // before any work: see core/allocator.hpp
  CLI::App app{"antpose: antenna azimuth, downtilt and roll from a smartphone"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "antpose 0.1.0");
  antpose::cli::add_convert_command(app);
  antpose::cli::add_inspect_command(app);
  antpose::cli::add_wmm_command(app);
  antpose::cli::add_contact_command(app);
  antpose::cli::add_measure_command(app);
  antpose::cli::add_simulate_command(app);
  antpose::cli::add_bench_command(app);
  antpose::cli::add_orientation_command(app);
  antpose::cli::add_calibrate_command(app);
  antpose::cli::add_device_command(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const antpose::InputError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return 2;
  } catch (const antpose::MeasurementError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return 3;
  } catch (const std::exception& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return 1;
  }
  return 0;
}
