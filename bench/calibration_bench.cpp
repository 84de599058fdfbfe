// Time of each calibration fit: on the Xsens MTi recording (38 static frames, 51 175 samples)
// and the HMC5883L tumble (8 190 magnetometer samples), from ../shared/data/imu-calibration.
// Run: ANTPOSE_SHARED_DIR=/path/to/shared build/bench/antpose_bench --benchmark_filter=Calibration
// (default ../shared).
#include <cstdlib>
#include <filesystem>

#include <benchmark/benchmark.h>

#include "antpose/calibration/allan.hpp"
#include "antpose/calibration/calibrate_imu.hpp"


namespace {
using namespace antpose;

std::filesystem::path shared() {
  const char* env = std::getenv("ANTPOSE_SHARED_DIR");
  return env ? env : "../shared";
}

const Capture& xsens() {
  static const Capture c = [] {
    Diagnostics d;
    return read_capture(shared() / "data/imu-calibration/xsens-mti", d);
  }();
  return c;
}
const Capture& hmc() {
  static const Capture c = [] {
    Diagnostics d;
    return read_capture(shared() / "data/imu-calibration/hmc5883l-mpu6050-full-sphere", d);
  }();
  return c;
}
std::vector<Vec3> means(const std::vector<calibration::StaticFrame>& frames) {
  std::vector<Vec3> m;
  for (const auto& f : frames) m.push_back(f.acc_mean);
  return m;
}

void BM_CalibrationStaticFrames(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(calibration::collect_static_frames(xsens()));
}
void BM_CalibrationAccThesis(benchmark::State& state) {
  const auto m = means(calibration::collect_static_frames(xsens()));
  for (auto _ : state) benchmark::DoNotOptimize(calibration::fit_accelerometer_thesis(m, 9.81744));
}
void BM_CalibrationAccFull(benchmark::State& state) {
  const auto m = means(calibration::collect_static_frames(xsens()));
  const auto start = calibration::fit_accelerometer_thesis(m, 9.81744);
  for (auto _ : state) benchmark::DoNotOptimize(calibration::fit_accelerometer_full(m, 9.81744, start));
}
void BM_CalibrationGyroFull(benchmark::State& state) {
  const auto frames = calibration::collect_static_frames(xsens());
  const auto m = means(frames);
  const auto acc = calibration::fit_accelerometer_full(m, 9.81744, calibration::fit_accelerometer_thesis(m, 9.81744));
  for (auto _ : state)
    benchmark::DoNotOptimize(calibration::fit_gyroscope(xsens().require(streams::kGyroscope), frames, acc));
}
void BM_CalibrationMagEllipsoid(benchmark::State& state) {
  calibration::MagnetometerOptions o;
  o.refine = state.range(0) != 0;
  for (auto _ : state) {
    Diagnostics d;
    benchmark::DoNotOptimize(calibration::fit_magnetometer(hmc().require(streams::kMagnetometer), o, d));
  }
}
void BM_CalibrationAllanGyro(benchmark::State& state) {
  for (auto _ : state) {
    Diagnostics d;
    benchmark::DoNotOptimize(calibration::allan_of_stream(xsens().require(streams::kGyroscope), d));
  }
}

BENCHMARK(BM_CalibrationStaticFrames)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CalibrationAccThesis)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_CalibrationAccFull)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_CalibrationGyroFull)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CalibrationMagEllipsoid)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CalibrationAllanGyro)->Unit(benchmark::kMillisecond);

}  // namespace
