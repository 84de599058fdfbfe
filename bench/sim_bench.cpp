// Simulator throughput: sensor samples (accelerometer + gyroscope + magnetometer) per second.
#include <benchmark/benchmark.h>

#include "antpose/sim/imu_simulator.hpp"

namespace {

using namespace antpose;

void BM_SimulateImuTumble(benchmark::State& state) {
  sim::ImuSimulation s;
  s.trajectory = sim::tumble(60.0, 1.0, 1).with_tremor(0.002, 1e-5, 1);
  s.phone = sim::PhoneModel::typical();
  s.phone.accelerometer.rate_hz = s.phone.gyroscope.rate_hz = static_cast<double>(state.range(0));
  std::size_t samples = 0;
  for (auto _ : state) {
    const Capture c = sim::simulate_imu(s);
    for (const auto& [name, stream] : c.streams) samples += stream.size();
    benchmark::DoNotOptimize(c.streams.size());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(samples));
  state.counters["sensor_samples/s"] = benchmark::Counter(static_cast<double>(samples), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SimulateImuTumble)->Arg(100)->Arg(400)->Unit(benchmark::kMillisecond);

void BM_TrajectoryQuery(benchmark::State& state) {
  const sim::Trajectory tr = sim::tumble(60.0, 1.0, 2).with_tremor(0.002, 1e-5, 2);
  double t = 0.0;
  for (auto _ : state) {
    t = t > 59.0 ? 0.0 : t + 0.0137;
    benchmark::DoNotOptimize(tr.R_world_device(t));
    benchmark::DoNotOptimize(tr.angular_velocity_device(t));
    benchmark::DoNotOptimize(tr.acceleration_world(t));
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_TrajectoryQuery);

}  // namespace
