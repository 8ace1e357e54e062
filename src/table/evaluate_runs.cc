// Evaluating an experiment's runs: threads, the shared reference per sequence and the per-run
// cache (cheval/table/table.h).
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <numeric>
#include <regex>
#include <sstream>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cheval/common/error.h"
#include "cheval/common/output.h"
#include "cheval/eval/evaluate.h"
#include "cheval/table/table.h"
#include "cheval/traj/io.h"

namespace cheval::table {
namespace {

// A reference read once per sequence; its Chebyshev velocity (for ASE of estimates with velocity)
// fitted once on first use.
struct SharedReference {
  traj::Trajectory trajectory;
  RpgPoses rpg;
  std::once_flag velocity_once;
  std::optional<traj::Trajectory> with_velocity;
  std::string velocity_error;
};

class ReferenceCache {
 public:
  explicit ReferenceCache(TableMode mode) : mode_(mode) {}
  // Reads `path` once; later callers wait for the first read. Throws what the read threw.
  std::shared_ptr<SharedReference> Get(const std::string& path) {
    std::shared_future<std::shared_ptr<SharedReference>> future;
    bool mine = false;
    std::promise<std::shared_ptr<SharedReference>> promise;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      auto it = entries_.find(path);
      if (it == entries_.end()) {
        future = promise.get_future().share();
        entries_.emplace(path, future);
        mine = true;
      } else {
        future = it->second;
      }
    }
    if (mine) {
      try {
        auto shared = std::make_shared<SharedReference>();
        if (mode_ == TableMode::kRpg) {
          shared->rpg = ReadRpgPoses(path);
        } else {
          shared->trajectory = traj::ReadTrajectory(path);
        }
        promise.set_value(shared);
      } catch (...) {
        promise.set_exception(std::current_exception());
      }
    }
    return future.get();
  }

 private:
  TableMode mode_;
  std::mutex mutex_;
  std::map<std::string, std::shared_future<std::shared_ptr<SharedReference>>> entries_;
};

uint64_t Fnv1a(const std::string& bytes, uint64_t h = 1469598103934665603ULL) {
  for (unsigned char c : bytes) {
    h ^= c;
    h *= 1099511628211ULL;
  }
  return h;
}

std::string FileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, 0, 0, "cannot open the file");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Hashes of the references' contents, each file read once.
class ReferenceHashes {
 public:
  uint64_t Get(const std::string& path) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (auto it = hashes_.find(path); it != hashes_.end()) return it->second;
    }
    const uint64_t h = Fnv1a(FileBytes(path));
    std::lock_guard<std::mutex> lock(mutex_);
    hashes_[path] = h;
    return h;
  }

 private:
  std::mutex mutex_;
  std::map<std::string, uint64_t> hashes_;
};

// The cache key of a run: the two files' contents and everything that changes its numbers.
std::string CacheKey(const Experiment& e, const RunSpec& run, ReferenceHashes& hashes) {
  std::string options = fmt::format("cheval-table 1\nmode {}\nstatistic {}\nmax_diff {}\nalign {} {}\nrpg {} {} {} {}\n",
                                    e.mode == TableMode::kRpg ? "rpg" : "cheval", e.statistic, e.max_diff_s, run.align,
                                    run.align_frames, run.rpg.align_type, run.rpg.align_num_frames,
                                    run.rpg.start_time_s, run.rpg.end_time_s);
  for (const std::string& m : e.metrics) options += m + "\n";
  const uint64_t a = Fnv1a(fmt::format("{:016x}", hashes.Get(run.reference)), Fnv1a(options));
  const uint64_t b = Fnv1a(FileBytes(run.estimate), a);
  return fmt::format("{:016x}{:016x}", a, b);
}

double Statistic(const eval::ErrorStatistics& s, const std::string& statistic) {
  if (statistic == "mean") return s.mean;
  if (statistic == "median") return s.median;
  return s.rmse;
}

eval::EvaluationOptions BaseOptions(const Experiment& e, const RunSpec& run) {
  eval::EvaluationOptions o;
  o.association = eval::AssociationOptions::FromSeconds(e.max_diff_s, 0.0);
  const auto method = eval::AlignmentMethodFromString(run.align);
  if (!method) throw UsageError(fmt::format("unknown alignment '{}' for {}", run.align, run.estimate));
  o.alignment.method = *method;
  o.alignment.n_align = run.align_frames > 0 ? run.align_frames : 0;
  return o;
}

// One metric of a run in cheval mode; a reference's velocity is fitted on `fit_threads`
// (CurveOptions::threads).
double ChevalMetric(const Experiment& e, const RunSpec& run, SharedReference& ref, const traj::Trajectory& est,
                    const std::string& metric, int fit_threads) {
  eval::EvaluationOptions o = BaseOptions(e, run);
  static const std::regex rpe(R"(rpe_(trans|rot)_(.+)m)");
  std::smatch m;
  const traj::Trajectory* reference = &ref.trajectory;
  if (metric == "ape_trans" || metric == "ape_rot") {
    o.metric = eval::MetricKind::kApe;
    o.relation = metric == "ape_trans" ? eval::PoseRelation::kTranslation : eval::PoseRelation::kAngleDeg;
  } else if (std::regex_match(metric, m, rpe)) {
    o.metric = eval::MetricKind::kRpe;
    o.relation = m[1] == "trans" ? eval::PoseRelation::kTranslation : eval::PoseRelation::kAngleDeg;
    o.rpe.delta = std::stod(m[2].str());
    o.rpe.delta_unit = eval::DeltaUnit::kMeters;
  } else if (metric == "ase") {
    o.metric = eval::MetricKind::kAse;
    o.pose_only = !est.View().has_velocity();
    if (!o.pose_only && !ref.trajectory.View().has_velocity()) {
      // The C-ASE reference velocity: fitted once per sequence, at all its stamps, shared.
      std::call_once(ref.velocity_once, [&] {
        try {
          eval::VelocityOptions v = o.velocity;
          v.method = eval::VelocityMethod::kChebyshev;
          v.curve.threads = fit_threads;
          const eval::VelocityEstimate fit = eval::EstimateVelocity(ref.trajectory.View(), v);
          ref.with_velocity = ref.trajectory;
          ref.with_velocity->SetVelocities(fit.velocities);
        } catch (const Error& error) {
          ref.velocity_error = error.what();
        }
      });
      if (!ref.with_velocity) throw ComputeError(ref.velocity_error);
      reference = &*ref.with_velocity;
      o.reference_velocity = eval::ReferenceVelocitySource::kGiven;
    }
  } else {  // kitti_drift_trans / kitti_drift_rot
    o.metric = eval::MetricKind::kRpe;
    o.kitti_drift = true;
    const eval::EvaluationResult r = eval::Evaluate(reference->View(), est.View(), o);
    if (!r.drift || r.drift->segments == 0) {
      throw ComputeError("no KITTI segment: the reference path is shorter than 100 m");
    }
    return metric == "kitti_drift_trans" ? r.drift->translation_percent : r.drift->rotation_deg_per_m;
  }
  return Statistic(eval::Evaluate(reference->View(), est.View(), o).stats, e.statistic);
}

RunResult EvaluateRun(const Experiment& e, const RunSpec& run, ReferenceCache& refs, int fit_threads) {
  RunResult result;
  const size_t n = e.metrics.size();
  result.values.assign(n, std::nullopt);
  result.errors.assign(n, "");
  std::shared_ptr<SharedReference> ref;
  try {
    ref = refs.Get(run.reference);
    if (e.mode == TableMode::kRpg) {
      const RpgPoses est = ReadRpgPoses(run.estimate);
      std::vector<double> pcts;
      static const std::regex rel(R"(rpe_(trans|rot)_(\d+)pct)");
      for (const std::string& metric : e.metrics) {
        std::smatch m;
        if (std::regex_match(metric, m, rel)) pcts.push_back(std::stoi(m[2].str()) / 100.0);
      }
      const RpgResult r = RpgEvaluate(ref->rpg, est, run.rpg, pcts);
      size_t rel_index = 0;
      for (size_t k = 0; k < n; ++k) {
        const std::string& metric = e.metrics[k];
        std::smatch m;
        if (metric == "ape_trans") {
          result.values[k] = r.rmse_trans_m;
        } else if (metric == "ape_rot") {
          result.values[k] = r.rmse_rot_deg;
        } else if (std::regex_match(metric, m, rel)) {
          const RpgRelativeErrors& re = r.relative[rel_index++];
          const std::vector<double>& v = m[1] == "trans" ? re.trans_m : re.rot_deg;
          if (v.empty()) {
            result.errors[k] = fmt::format("fewer than 2 sub-trajectories of {} m", re.distance_m);
          } else {
            double sum = 0;
            for (double x : v) sum += x;
            result.values[k] = sum / static_cast<double>(v.size());
          }
        }
      }
    } else {
      const traj::Trajectory est = traj::ReadTrajectory(run.estimate);
      for (size_t k = 0; k < n; ++k) {
        try {
          result.values[k] = ChevalMetric(e, run, *ref, est, e.metrics[k], fit_threads);
        } catch (const InputError&) {
          throw;
        } catch (const Error& error) {
          result.errors[k] = error.what();
        }
      }
    }
  } catch (const Error& error) {
    result.failure = error.what();
    result.values.assign(n, std::nullopt);
  }
  return result;
}

}  // namespace

std::vector<RunResult> EvaluateRuns(const Experiment& e, const EvaluateRunsOptions& options) {
  CheckMetrics(e);
  if (options.threads < 1) throw UsageError("EvaluateRunsOptions::threads must be >= 1");
  const size_t total = e.runs.size();
  std::vector<RunResult> results(total);
  ReferenceCache refs(e.mode);
  ReferenceHashes hashes;
  if (!options.cache_folder.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(options.cache_folder, ec);
    if (ec) throw OutputError(fmt::format("{}: error: cannot write: {}", options.cache_folder, ec.message()));
  }
  // Work order: round robin over the references, so that concurrent workers start on different
  // sequences instead of waiting for the same reference read and velocity fit.
  std::vector<size_t> order(total);
  {
    std::map<std::string, size_t> seen;  // reference -> runs scheduled so far
    std::vector<std::pair<size_t, size_t>> rank(total);
    std::map<std::string, size_t> first;
    for (size_t i = 0; i < total; ++i) {
      const std::string& ref = e.runs[i].reference;
      first.emplace(ref, first.size());
      rank[i] = {seen[ref]++, first[ref]};
    }
    std::iota(order.begin(), order.end(), size_t{0});
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return rank[a] < rank[b]; });
  }
  std::atomic<size_t> next{0};
  std::mutex progress_mutex;
  size_t done = 0;
  std::exception_ptr first_error;
  auto work = [&] {
    for (size_t slot = next++; slot < total; slot = next++) {
      const size_t i = order[slot];
      const RunSpec& run = e.runs[i];
      RunResult& r = results[i];
      try {
        if (!run.missing.empty()) {
          r.values.assign(e.metrics.size(), std::nullopt);
          r.errors.assign(e.metrics.size(), "");
          r.failure = run.missing;
        } else {
          std::string cache_file;
          bool cached = false;
          if (!options.cache_folder.empty()) {
            try {
              cache_file = (std::filesystem::path(options.cache_folder) / (CacheKey(e, run, hashes) + ".json")).string();
            } catch (const InputError&) {
              cache_file.clear();  // unreadable input: EvaluateRun reports it
            }
            if (!cache_file.empty() && std::filesystem::exists(cache_file)) {
              try {
                const nlohmann::json j = nlohmann::json::parse(std::ifstream(cache_file));
                if (j.at("values").size() == e.metrics.size()) {
                  for (const auto& v : j.at("values")) r.values.push_back(v.is_null() ? std::nullopt : std::optional<double>(v.get<double>()));
                  r.errors = j.at("errors").get<std::vector<std::string>>();
                  r.failure = j.at("failure").get<std::string>();
                  r.from_cache = cached = true;
                }
              } catch (const std::exception&) {
                r = RunResult{};  // a damaged cache file: evaluate again
              }
            }
          }
          if (!cached) {
            // Runs on several threads fit on one each; a lone run fits on every core.
            r = EvaluateRun(e, run, refs, options.threads > 1 ? 1 : 0);
            if (!cache_file.empty()) {
              nlohmann::json j;
              j["values"] = nlohmann::json::array();
              for (const auto& v : r.values) j["values"].push_back(v ? nlohmann::json(*v) : nlohmann::json());
              j["errors"] = r.errors;
              j["failure"] = r.failure;
              WriteOutput(cache_file, j.dump() + "\n");
            }
          }
        }
      } catch (...) {
        std::lock_guard<std::mutex> lock(progress_mutex);
        if (!first_error) first_error = std::current_exception();
      }
      std::lock_guard<std::mutex> lock(progress_mutex);
      ++done;
      ReportProgress(options.progress, "runs", static_cast<int64_t>(done), static_cast<int64_t>(total));
    }
  };
  std::vector<std::thread> threads;
  const int n_threads = static_cast<int>(std::min<size_t>(static_cast<size_t>(options.threads), std::max<size_t>(total, 1)));
  for (int k = 1; k < n_threads; ++k) threads.emplace_back(work);
  work();
  for (std::thread& t : threads) t.join();
  if (first_error) std::rethrow_exception(first_error);
  return results;
}

}  // namespace cheval::table
