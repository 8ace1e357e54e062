// Chebyshev fitting speed. Target (velocity issue): m = 100,000 samples of a 3-vector at degree 400
// in <= 50 ms (numpy chebfit: 16.4 s; an O(m·N) numpy prototype: 0.24 s, CHEBYSHEV.md).
//   build/bench/cheb_bench
#include <cmath>
#include <random>

#include <benchmark/benchmark.h>

#include "cheval/cheb/fit.h"

namespace {

using namespace cheval::cheb;

void BM_FitLeastSquares(benchmark::State& state) {
  const auto m = static_cast<Eigen::Index>(state.range(0));
  const int degree = static_cast<int>(state.range(1));
  std::mt19937_64 rng(1);
  std::normal_distribution<double> noise(0.0, 1e-3);
  Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(m, 0.0, static_cast<double>(m) / 100.0);
  Eigen::MatrixXd z(m, 3);
  for (Eigen::Index i = 0; i < m; ++i) {
    z.row(i) << std::sin(0.3 * t[i]) + noise(rng), std::cos(0.2 * t[i]) + noise(rng), 0.01 * t[i] + noise(rng);
  }
  const Interval interval{t[0], t[m - 1]};
  for (auto _ : state) {
    benchmark::DoNotOptimize(FitLeastSquares(t, z, degree, interval));
  }
  state.SetItemsProcessed(state.iterations() * m);
}
BENCHMARK(BM_FitLeastSquares)->Args({100'000, 400})->Args({20'000, 200})->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
