#include "support/test_support.hpp"

#include <unistd.h>

#include <sys/wait.h>

#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>

namespace antpose::test {
namespace fs = std::filesystem;

fs::path shared_path(std::string_view relative) {
  const fs::path root = ANTPOSE_SHARED_DIR;
  if (!fs::is_directory(root))
    throw std::runtime_error(
        "shared reference folder not found: " + root.string() +
        " (set the CMake cache variable ANTPOSE_SHARED_DIR to the folder holding notes/ and data/)");
  const fs::path p = root / relative;
  if (!fs::exists(p))
    throw std::runtime_error("shared reference data missing: " + p.string() + " (ANTPOSE_SHARED_DIR=" + root.string() +
                             ")");
  return p;
}

fs::path source_path(std::string_view relative) { return fs::path(ANTPOSE_SOURCE_DIR) / relative; }

TempDir::TempDir() {
  std::random_device rd;
  path_ = fs::temp_directory_path() / ("antpose-test-" + std::to_string(rd()) + std::to_string(rd()));
  fs::create_directories(path_);
}

TempDir::~TempDir() {
  std::error_code ignored;
  fs::remove_all(path_, ignored);
}

void write_file(const fs::path& file, std::string_view content) {
  if (!file.parent_path().empty()) fs::create_directories(file.parent_path());
  std::ofstream out(file, std::ios::binary);
  out.write(content.data(), static_cast<std::streamsize>(content.size()));
  if (!out) throw std::runtime_error("cannot write test file " + file.string());
}

std::filesystem::path cli_path() { return ANTPOSE_CLI_PATH; }

namespace {

CliResult run_command(const std::string& prefix, const std::string& args) {
  TempDir dir;
  const std::string cmd = fmt::format("{}'{}' {} >'{}' 2>'{}'", prefix, cli_path().string(), args,
                                      (dir / "out").string(), (dir / "err").string());
  const int raw = std::system(cmd.c_str());
  CliResult r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  auto slurp = [](const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  };
  r.out = slurp(dir / "out");
  r.err = slurp(dir / "err");
  return r;
}

}  // namespace

CliResult run_cli(const std::string& args) { return run_command("", args); }

CliResult run_cli_unprivileged(const std::string& args) {
  // The output files are created by the shell before setpriv drops the privilege.
  return run_command(::geteuid() == 0 ? "setpriv --reuid=65534 --regid=65534 --clear-groups -- " : "", args);
}

std::string jpeg_claiming(int width, int height) {
  std::vector<uchar> bytes;
  cv::imencode(".jpg", cv::Mat(48, 64, CV_8UC1, cv::Scalar(100)), bytes);
  for (std::size_t i = 0; i + 8 < bytes.size(); ++i)
    if (bytes[i] == 0xFF && bytes[i + 1] == 0xC0) {  // length(2) precision(1) height(2) width(2)
      bytes[i + 5] = static_cast<uchar>(height >> 8), bytes[i + 6] = static_cast<uchar>(height & 0xFF);
      bytes[i + 7] = static_cast<uchar>(width >> 8), bytes[i + 8] = static_cast<uchar>(width & 0xFF);
      break;
    }
  return std::string(bytes.begin(), bytes.end());
}

}  // namespace antpose::test
