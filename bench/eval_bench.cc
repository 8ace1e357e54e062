// Evaluation throughput (issue 4 targets: APE with SE(3) alignment on a 200,000-pose pair <= 0.25 s
// end to end including reading both files; RPE <= 0.3 s). The pair is written once as TUM files
// (a 200 Hz helix-like flight and a noisy, jittered copy); each iteration reads both files and
// evaluates, as `cheval ape` does (which also reads the two files on two threads). Scaling over n:
//   build-eval/bench/eval_bench --benchmark_filter='EndToEnd|Associate'
// Memory up to 10 million poses (in memory, one child process per n; peak RSS and bytes per pose):
//   build-eval/bench/eval_bench --memory [N ...]
// The `cheval` executable itself on the same pair: bench/eval_cli_timing.sh (uses --write-pair N DIR).
#include <cmath>
#include <filesystem>
#include <map>
#include <random>
#include <string>

#include <benchmark/benchmark.h>
#include <fmt/format.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>

#include "cheval/eval/evaluate.h"
#include "cheval/traj/io.h"

namespace {

using namespace cheval;

// A smooth 3D flight sampled at 200 Hz (reference, with exact stamps) and an estimate with 1 cm /
// 0.01 rad noise, 1 ms stamp jitter and a 1e-3 scale drift.
std::pair<traj::Trajectory, traj::Trajectory> Pair(int64_t n) {
  traj::Trajectory ref, est;
  ref.Reserve(n);
  est.Reserve(n);
  std::mt19937_64 rng(1);
  std::normal_distribution<double> g;
  for (int64_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / 200.0;
    const int64_t stamp = 1'403'636'580'000'000'000 + i * 5'000'000;
    const double p[3] = {10 * std::cos(0.1 * t), 5 * std::sin(0.2 * t), 1 + std::sin(0.05 * t)};
    const Eigen::Quaterniond q(Eigen::AngleAxisd(0.1 * t, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(0.2 * std::sin(t), Eigen::Vector3d::UnitX()));
    const double qr[4] = {q.x(), q.y(), q.z(), q.w()};
    ref.Append(stamp, p, qr);
    const double scale = 1 + 1e-3 * t / 1000;
    const double pe[3] = {scale * p[0] + 0.01 * g(rng), scale * p[1] + 0.01 * g(rng), scale * p[2] + 0.01 * g(rng)};
    const Eigen::Quaterniond qe = q * Eigen::Quaterniond(Eigen::AngleAxisd(0.01 * g(rng), Eigen::Vector3d::UnitY()));
    const double qer[4] = {qe.x(), qe.y(), qe.z(), qe.w()};
    est.Append(stamp + static_cast<int64_t>(1e6 * g(rng)), pe, qer);
  }
  return {std::move(ref), std::move(est)};
}

// The pair as TUM files in the temporary folder, written once per n.
std::pair<std::string, std::string> Files(int64_t n) {
  static std::map<int64_t, std::pair<std::string, std::string>> cache;
  auto it = cache.find(n);
  if (it == cache.end()) {
    const auto [ref, est] = Pair(n);
    const std::string dir = std::filesystem::temp_directory_path().string();
    const std::string tag = std::to_string(::getpid()) + "_" + std::to_string(n);
    const std::string ref_path = dir + "/cheval_bench_ref_" + tag + ".txt";
    const std::string est_path = dir + "/cheval_bench_est_" + tag + ".txt";
    traj::WriteTrajectory(ref_path, ref.View(), traj::Format::kTum);
    traj::WriteTrajectory(est_path, est.View(), traj::Format::kTum);
    it = cache.emplace(n, std::make_pair(ref_path, est_path)).first;
  }
  return it->second;
}

void EndToEnd(benchmark::State& state, eval::MetricKind metric) {
  const auto [ref_path, est_path] = Files(state.range(0));
  eval::EvaluationOptions options;
  options.metric = metric;
  options.alignment.method = eval::AlignmentMethod::kSE3;
  for (auto _ : state) {
    const traj::Trajectory ref = traj::ReadTrajectory(ref_path);
    const traj::Trajectory est = traj::ReadTrajectory(est_path);
    const eval::EvaluationResult result = eval::Evaluate(ref.View(), est.View(), options);
    benchmark::DoNotOptimize(result.stats.rmse);
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
  state.SetComplexityN(state.range(0));
}

void BM_ApeSE3EndToEnd(benchmark::State& state) { EndToEnd(state, eval::MetricKind::kApe); }
BENCHMARK(BM_ApeSE3EndToEnd)->Arg(12'500)->Arg(50'000)->Arg(200'000)->Arg(800'000)->Unit(benchmark::kMillisecond);

void BM_RpeSE3EndToEnd(benchmark::State& state) { EndToEnd(state, eval::MetricKind::kRpe); }
BENCHMARK(BM_RpeSE3EndToEnd)->Arg(12'500)->Arg(50'000)->Arg(200'000)->Arg(800'000)->Unit(benchmark::kMillisecond);

// The evaluation alone (trajectories in memory): what is left once the files are read.
void BM_ApeSE3InMemory(benchmark::State& state) {
  const auto [ref, est] = Pair(state.range(0));
  eval::EvaluationOptions options;
  options.alignment.method = eval::AlignmentMethod::kSE3;
  for (auto _ : state) benchmark::DoNotOptimize(eval::Evaluate(ref.View(), est.View(), options).stats.rmse);
  state.SetItemsProcessed(state.iterations() * state.range(0));
  state.SetComplexityN(state.range(0));
}
BENCHMARK(BM_ApeSE3InMemory)->Arg(12'500)->Arg(50'000)->Arg(200'000)->Arg(800'000)->Arg(3'200'000)->Unit(benchmark::kMillisecond);

// Association alone: sorted lists (the usual case, O(n + m)) and a shuffled estimate (O(n log m)),
// against evo's O(n·m) scan which takes 55 s at 200,000 poses (docs/evaluation.md, "Association").
void Associate(benchmark::State& state, bool shuffled) {
  const int64_t n = state.range(0);
  std::vector<int64_t> ref(static_cast<size_t>(n)), est(static_cast<size_t>(n));
  std::mt19937_64 rng(2);
  for (int64_t i = 0; i < n; ++i) {
    ref[static_cast<size_t>(i)] = i * 5'000'000;
    est[static_cast<size_t>(i)] = i * 5'000'000 + static_cast<int64_t>(rng() % 2'000'000);
  }
  if (shuffled) std::shuffle(est.begin(), est.end(), rng);
  for (auto _ : state) benchmark::DoNotOptimize(eval::AssociateStamps(ref, est).size());
  state.SetItemsProcessed(state.iterations() * n);
  state.SetComplexityN(n);
}
void BM_AssociateSorted(benchmark::State& state) { Associate(state, false); }
BENCHMARK(BM_AssociateSorted)->Arg(10'000)->Arg(100'000)->Arg(1'000'000)->Arg(10'000'000)->Unit(benchmark::kMillisecond);
void BM_AssociateShuffled(benchmark::State& state) { Associate(state, true); }
BENCHMARK(BM_AssociateShuffled)->Arg(10'000)->Arg(100'000)->Arg(1'000'000)->Arg(10'000'000)->Unit(benchmark::kMillisecond);

double PeakRssMegabytes() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

// One row of the memory table, computed in a child process so that each n has its own peak RSS.
void MemoryRow(int64_t n) {
  using Clock = std::chrono::steady_clock;
  const double base = PeakRssMegabytes();
  const auto t0 = Clock::now();
  const auto [ref, est] = Pair(n);
  const double built = PeakRssMegabytes();
  const auto t1 = Clock::now();
  eval::EvaluationOptions options;
  options.alignment.method = eval::AlignmentMethod::kSE3;
  const double ape = eval::Evaluate(ref.View(), est.View(), options).stats.rmse;
  const double after_ape = PeakRssMegabytes();
  const auto t2 = Clock::now();
  options.metric = eval::MetricKind::kRpe;
  const double rpe = eval::Evaluate(ref.View(), est.View(), options).stats.rmse;
  const double after_rpe = PeakRssMegabytes();
  const auto t3 = Clock::now();
  auto seconds = [](auto a, auto b) { return std::chrono::duration<double>(b - a).count(); };
  fmt::print("{:>10}  {:>8.2f}  {:>8.3f}  {:>8.3f}  {:>10.0f}  {:>10.0f}  {:>10.0f}  {:>8.0f}  {:>8.0f}  (APE {:.4f} m, RPE {:.4f} m)\n",
             n, seconds(t0, t1), seconds(t1, t2), seconds(t2, t3), built - base, after_ape - base, after_rpe - base,
             (built - base) * 1048576.0 / static_cast<double>(n),
             (after_rpe - built) * 1048576.0 / static_cast<double>(n), ape, rpe);
}

int MemoryTable(const std::vector<int64_t>& sizes) {
  fmt::print("{:>10}  {:>8}  {:>8}  {:>8}  {:>10}  {:>10}  {:>10}  {:>8}  {:>8}\n", "poses", "build s", "APE s", "RPE s",
             "trajs MB", "+APE MB", "+RPE MB", "B/pose", "+eval B/pose");
  for (int64_t n : sizes) {
    std::fflush(stdout);
    const pid_t child = fork();
    if (child == 0) {
      MemoryRow(n);
      std::fflush(stdout);
      _exit(0);
    }
    int status = 0;
    waitpid(child, &status, 0);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 4 && std::strcmp(argv[1], "--write-pair") == 0) {  // the files bench/eval_cli_timing.sh times
    const auto [ref, est] = Pair(std::stoll(argv[2]));
    traj::WriteTrajectory(std::string(argv[3]) + "/ref.txt", ref.View(), traj::Format::kTum);
    traj::WriteTrajectory(std::string(argv[3]) + "/est.txt", est.View(), traj::Format::kTum);
    return 0;
  }
  if (argc > 1 && std::strcmp(argv[1], "--memory") == 0) {
    std::vector<int64_t> sizes;
    for (int i = 2; i < argc; ++i) sizes.push_back(std::stoll(argv[i]));
    if (sizes.empty()) sizes = {100'000, 1'000'000, 10'000'000};
    return MemoryTable(sizes);
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  // Remove the files Files() wrote.
  const std::string prefix = "cheval_bench_";
  const std::string pid = std::to_string(::getpid());
  for (const auto& entry : std::filesystem::directory_iterator(std::filesystem::temp_directory_path())) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(prefix, 0) == 0 && name.find("_" + pid + "_") != std::string::npos) {
      std::filesystem::remove(entry.path());
    }
  }
  return 0;
}
