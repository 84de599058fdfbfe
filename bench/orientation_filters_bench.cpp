// Throughput of the antpose filter (per gyroscope sample, 9-D, 285.7 Hz like BROAD) alone and of
// the whole-log estimators `antpose` and `antpose-smoother` (track output included).
#include <benchmark/benchmark.h>

#include "antpose/orientation/antpose_filter.hpp"
#include "antpose/orientation/smoother.hpp"
#include "antpose/sim/imu_simulator.hpp"

namespace {

using namespace antpose;
using namespace antpose::orientation;

ImuData tumble_data() {
  sim::ImuSimulation s;
  s.trajectory = sim::tumble(60.0, 1.0, 1).with_tremor(0.002, 1e-5, 1);
  s.phone = sim::PhoneModel::typical();
  s.phone.accelerometer.rate_hz = s.phone.gyroscope.rate_hz = s.phone.magnetometer.rate_hz = 285.714;
  Diagnostics diag;
  return imu_data_from_capture(sim::simulate_imu(s), diag);
}

void BM_AntposeFilterUpdate(benchmark::State& state) {
  const ImuData d = tumble_data();
  AntposeFilter f(AntposeFilterParams{}, d.gyroscope.median_interval());
  const std::size_t n = std::min({d.gyroscope.size(), d.accelerometer.size(), d.magnetometer.size()});
  std::size_t i = 0, samples = 0;
  for (auto _ : state) {
    f.update(0.0035, d.gyroscope.v[i], &d.accelerometer.v[i], &d.magnetometer.v[i]);
    benchmark::DoNotOptimize(f.gyro_bias());
    if (++i == n) i = 0;
    ++samples;
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(samples));
}
BENCHMARK(BM_AntposeFilterUpdate);

void BM_Estimator(benchmark::State& state, const char* name) {
  const ImuData d = tumble_data();
  const auto est = make_estimator(name);
  Diagnostics diag;
  for (auto _ : state) benchmark::DoNotOptimize(est->estimate(d, diag).size());
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * d.gyroscope.size()));
}
BENCHMARK_CAPTURE(BM_Estimator, antpose, "antpose")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Estimator, antpose_smoother, "antpose-smoother")->Unit(benchmark::kMillisecond);

}  // namespace
