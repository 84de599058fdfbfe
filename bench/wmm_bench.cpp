// Time of one World Magnetic Model evaluation (degree 12, field + secular variation).
#include <benchmark/benchmark.h>

#include "antpose/geomag/wmm.hpp"

namespace {

void BM_WmmEvaluate(benchmark::State& state) {
  const auto model = antpose::geomag::MagneticModel::wmm2025();
  double lat = -89.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(model.evaluate(lat, 120.0, 0.1, 2027.5));
    lat = lat > 89.0 ? -89.0 : lat + 0.37;  // vary the input so nothing is hoisted
  }
}
BENCHMARK(BM_WmmEvaluate);

void BM_WmmLoadBuiltIn(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(antpose::geomag::MagneticModel::wmm2025());
}
BENCHMARK(BM_WmmLoadBuiltIn);

}  // namespace
