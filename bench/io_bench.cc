// Reader and writer throughput. BM_ParseTumBaseline is the obvious std::istringstream reader a
// script-writer would produce, measured in the same run as cheval's reader for a ratio:
//   build/bench/io_bench --benchmark_filter=Tum
#include <map>
#include <sstream>
#include <string>

#include <benchmark/benchmark.h>

#include "cheval/sim/motion.h"
#include "cheval/traj/io.h"
#include "cheval/traj/stamp.h"

namespace {

using namespace cheval;

const traj::Trajectory& Motion(int64_t poses) {
  static std::map<int64_t, traj::Trajectory> cache;
  auto it = cache.find(poses);
  if (it == cache.end()) {
    sim::MotionOptions options;
    options.rate_hz = 200.0;
    options.duration_s = static_cast<double>(poses - 1) / *options.rate_hz;
    it = cache.emplace(poses, sim::AddPositionNoise(sim::GenerateMotion(options).View(), 0.001, 1)).first;
  }
  return it->second;
}

void BM_ParseTum(benchmark::State& state) {
  const std::string text = traj::FormatTrajectory(Motion(state.range(0)).View(), traj::Format::kTum);
  for (auto _ : state) {
    benchmark::DoNotOptimize(traj::ParseTrajectory(text, "bench.txt"));
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(text.size()));
}
BENCHMARK(BM_ParseTum)->Arg(10'000)->Arg(200'000)->Unit(benchmark::kMillisecond);

// Baseline: line by line with std::istringstream and doubles (stamps lose precision this way).
void BM_ParseTumBaseline(benchmark::State& state) {
  const std::string text = traj::FormatTrajectory(Motion(state.range(0)).View(), traj::Format::kTum);
  for (auto _ : state) {
    std::istringstream in(text);
    std::vector<double> values;
    values.reserve(8 * state.range(0));
    std::string line;
    while (std::getline(in, line)) {
      std::istringstream fields(line);
      double v;
      while (fields >> v) values.push_back(v);
    }
    benchmark::DoNotOptimize(values.data());
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(text.size()));
}
BENCHMARK(BM_ParseTumBaseline)->Arg(10'000)->Arg(200'000)->Unit(benchmark::kMillisecond);

void BM_ParseEuroc(benchmark::State& state) {
  const std::string text = traj::FormatTrajectory(Motion(state.range(0)).View(), traj::Format::kEuroc);
  for (auto _ : state) {
    benchmark::DoNotOptimize(traj::ParseTrajectory(text, "bench.csv"));
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(text.size()));
}
BENCHMARK(BM_ParseEuroc)->Arg(200'000)->Unit(benchmark::kMillisecond);

void BM_FormatTum(benchmark::State& state) {
  const traj::Trajectory& trajectory = Motion(state.range(0));
  for (auto _ : state) {
    benchmark::DoNotOptimize(traj::FormatTrajectory(trajectory.View(), traj::Format::kTum));
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_FormatTum)->Arg(200'000)->Unit(benchmark::kMillisecond);

// The block-by-block form the file writers use; in wall time, as its blocks are formatted on two threads.
void BM_FormatTumBlocks(benchmark::State& state) {
  const traj::Trajectory& trajectory = Motion(state.range(0));
  for (auto _ : state) {
    size_t bytes = 0;
    traj::FormatTrajectory(trajectory.View(), traj::Format::kTum, [&](std::string_view block) { bytes += block.size(); });
    benchmark::DoNotOptimize(bytes);
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_FormatTumBlocks)->Arg(200'000)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ParseDecimalStamp(benchmark::State& state) {
  for (auto _ : state) {
    benchmark::DoNotOptimize(traj::ParseDecimalStamp("1403715529.112143517", 9));
  }
}
BENCHMARK(BM_ParseDecimalStamp);

}  // namespace

BENCHMARK_MAIN();
