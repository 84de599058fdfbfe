// Reading a large gzip-compressed sensor stream (100 000 rows of t,x,y,z) through read_capture:
// decompression, CSV splitting, strict number parsing and validation. Reports rows/s.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <random>
#include <string>

#include "antpose/io/capture.hpp"
#include "antpose/io/csv.hpp"
#include "antpose/io/text_file.hpp"

namespace {

namespace fs = std::filesystem;

struct Fixture {
  fs::path dir;
  std::size_t rows;
  explicit Fixture(std::size_t n) : rows(n) {
    std::random_device rd;
    dir = fs::temp_directory_path() / ("antpose-bench-" + std::to_string(rd()));
    antpose::io::write_text_atomic(dir / "capture.yaml", "format: antpose-capture\nversion: 1\nkind: imu-log\n");
    std::mt19937_64 rng(1);
    std::normal_distribution<double> noise(0.0, 0.05);
    std::string csv = "t,x,y,z\n";
    for (std::size_t i = 0; i < n; ++i) {
      csv += antpose::io::format_number(static_cast<double>(i) * 0.005 + noise(rng) * 1e-4) + ',';
      csv += antpose::io::format_number(noise(rng)) + ',' + antpose::io::format_number(9.81 + noise(rng)) + ',' +
             antpose::io::format_number(noise(rng)) + '\n';
    }
    antpose::io::write_text_atomic(dir / "sensors" / "accelerometer.csv.gz", csv);
  }
  ~Fixture() {
    std::error_code ignored;
    fs::remove_all(dir, ignored);
  }
};

void BM_ReadCaptureCsvGz(benchmark::State& state) {
  const Fixture fx(static_cast<std::size_t>(state.range(0)));
  for (auto _ : state) {
    antpose::Diagnostics d;
    const auto c = antpose::read_capture(fx.dir, d);
    benchmark::DoNotOptimize(c.streams.size());
  }
  state.counters["rows/s"] = benchmark::Counter(static_cast<double>(fx.rows) * static_cast<double>(state.iterations()),
                                                benchmark::Counter::kIsRate);
}
BENCHMARK(BM_ReadCaptureCsvGz)->Arg(100000)->Unit(benchmark::kMillisecond);

}  // namespace
