// Throughput of the orientation estimators (ns per output sample = per gyroscope sample for the
// filters) on BROAD trial 02 (53 240 samples at 285.7 Hz; read once, outside the timing).
// Run: build/bench/antpose_bench --benchmark_filter=Orientation
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "antpose/orientation/estimator.hpp"
#include "antpose/orientation/filters.hpp"

namespace {

using namespace antpose;

const orientation::ImuData& broad_data() {
  static const orientation::ImuData data = [] {
    const char* env = std::getenv("ANTPOSE_SHARED_DIR");
    const std::filesystem::path shared = env ? env : "/work/shared";
    Diagnostics diag;
    return orientation::imu_data_from_capture(
        read_capture(shared / "data/orientation/broad/02_undisturbed_slow_rotation_B", diag), diag);
  }();
  return data;
}

void BM_OrientationEstimator(benchmark::State& state, const std::string& method) {
  const auto& data = broad_data();
  const auto estimator = orientation::make_estimator(method);
  Diagnostics diag;
  std::size_t samples = 0;
  for (auto _ : state) {
    const auto track = estimator->estimate(data, diag);
    samples += track.size();
    benchmark::DoNotOptimize(track.q_world_device.back());
  }
  state.counters["ns_per_sample"] =
      benchmark::Counter(static_cast<double>(samples), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK_CAPTURE(BM_OrientationEstimator, ecompass, std::string("ecompass"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_OrientationEstimator, madgwick, std::string("madgwick"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_OrientationEstimator, madgwick_broad, std::string("madgwick-broad"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_OrientationEstimator, mahony, std::string("mahony"))->Unit(benchmark::kMillisecond);

// The filter step alone (no track storage): what a filter costs per 9-D sample.
template <class Filter>
void BM_OrientationFilterStep(benchmark::State& state, Filter filter) {
  const auto& d = broad_data();
  filter.reset(Quat::Identity());
  std::size_t i = 0;
  const std::size_t n = std::min({d.gyroscope.size(), d.accelerometer.size(), d.magnetometer.size()});
  for (auto _ : state) {
    filter.update(0.0035, d.gyroscope.v[i], &d.accelerometer.v[i], &d.magnetometer.v[i]);
    benchmark::DoNotOptimize(filter);
    if (++i == n) i = 0;
  }
}
BENCHMARK_CAPTURE(BM_OrientationFilterStep, madgwick, orientation::MadgwickFilter({}));
BENCHMARK_CAPTURE(BM_OrientationFilterStep, madgwick_broad, orientation::MadgwickBroadFilter(0.12f, 285.714f));
BENCHMARK_CAPTURE(BM_OrientationFilterStep, mahony, orientation::MahonyFilter({}));

}  // namespace
