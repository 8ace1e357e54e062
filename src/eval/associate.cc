#include "cheval/eval/associate.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <fmt/format.h>

#include "cheval/common/error.h"
#include "cheval/common/options.h"
#include "cheval/traj/stamp.h"

namespace cheval::eval {
namespace {

__extension__ typedef __int128 Wide;  // stamp ± offset and their differences cannot overflow in 128 bits

// The stamps of the longer list in increasing order (a contiguous copy, so the binary searches stay
// in cache), their positions in file order (ties kept in file order), and for every sorted position
// the start of its run of equal stamps, whose first pose in file order is the one evo's argmin picks.
struct SortedStamps {
  std::vector<int64_t> stamps;
  std::vector<Eigen::Index> order;  // empty when the list is already sorted (order = identity)
  std::vector<Eigen::Index> run_start;

  explicit SortedStamps(std::span<const int64_t> input) : run_start(input.size()) {
    if (std::is_sorted(input.begin(), input.end())) {
      stamps.assign(input.begin(), input.end());
    } else {
      order.resize(input.size());
      std::iota(order.begin(), order.end(), Eigen::Index{0});
      std::stable_sort(order.begin(), order.end(), [&](Eigen::Index a, Eigen::Index b) { return input[a] < input[b]; });
      stamps.resize(input.size());
      for (size_t k = 0; k < order.size(); ++k) stamps[k] = input[static_cast<size_t>(order[k])];
    }
    for (size_t k = 0; k < stamps.size(); ++k) {
      run_start[k] = k > 0 && stamps[k] == stamps[k - 1] ? run_start[k - 1] : static_cast<Eigen::Index>(k);
    }
  }
  Eigen::Index FileIndex(Eigen::Index sorted) const { return order.empty() ? sorted : order[static_cast<size_t>(sorted)]; }
};

std::string Range(std::span<const int64_t> stamps) {
  const auto [lo, hi] = std::minmax_element(stamps.begin(), stamps.end());
  return fmt::format("{} .. {} s", traj::FormatSeconds(*lo), traj::FormatSeconds(*hi));
}

}  // namespace

int64_t SecondsToNanoseconds(double seconds, const std::string& what) {
  const double ns = std::round(seconds * 1e9);
  if (!std::isfinite(ns) || std::abs(ns) >= 9.2e18) {
    throw UsageError(fmt::format("{}: {} s is not a usable time", what, seconds));
  }
  return static_cast<int64_t>(ns);
}

AssociationOptions AssociationOptions::FromSeconds(double max_diff_s, double offset_s) {
  const OptionCheck check("AssociationOptions");
  auto usable = [](double seconds) { return std::isfinite(seconds) && std::abs(std::round(seconds * 1e9)) < 9.2e18; };
  check(usable(max_diff_s), "max_diff_ns", "must be a usable time, got {} s", max_diff_s);
  check(usable(offset_s), "offset_ns", "must be a usable time, got {} s", offset_s);
  AssociationOptions options;
  options.max_diff_ns = SecondsToNanoseconds(max_diff_s, "AssociationOptions::max_diff_ns");
  options.offset_ns = SecondsToNanoseconds(offset_s, "AssociationOptions::offset_ns");
  return options;
}

void AssociationOptions::Validate() const {
  const OptionCheck check("AssociationOptions");
  check(max_diff_ns >= 0, "max_diff_ns", "must be >= 0, got {} s", traj::FormatSeconds(max_diff_ns));
}

Association AssociateStamps(std::span<const int64_t> ref_stamps_ns, std::span<const int64_t> est_stamps_ns,
                            const AssociationOptions& options) {
  options.Validate();
  // evo iterates over the shorter list (the estimate when the lengths are equal) and searches the
  // other, shifted into the shorter one's time: reference - offset, or estimate + offset.
  const bool est_longer = est_stamps_ns.size() > ref_stamps_ns.size();
  const std::span<const int64_t> shorter = est_longer ? ref_stamps_ns : est_stamps_ns;
  const std::span<const int64_t> longer = est_longer ? est_stamps_ns : ref_stamps_ns;
  const Wide shift = est_longer ? Wide{options.offset_ns} : -Wide{options.offset_ns};

  Association result;
  if (longer.empty()) return result;
  const SortedStamps sorted(longer);
  const Eigen::Index m = static_cast<Eigen::Index>(longer.size());
  // Walk instead of searching when the next query is at most ~64 mean stamp spacings further on.
  const Wide walk_limit = Wide{64} * (Wide{sorted.stamps.back()} - Wide{sorted.stamps.front()} + 1) / m;
  result.ref.reserve(shorter.size());
  result.est.reserve(shorter.size());
  Eigen::Index lo = 0;
  Wide previous_q = 0;
  for (Eigen::Index k = 0; k < static_cast<Eigen::Index>(shorter.size()); ++k) {
    // |longer[j] + shift - s| = |longer[j] - q| with q = s - shift. lo = the first sorted position
    // with stamp >= q: found by walking on from the previous query when the queries increase (O(n + m)
    // for sorted files), by binary search otherwise.
    const Wide q = Wide{shorter[k]} - shift;
    if (k == 0 || q < previous_q || q - previous_q > walk_limit) {
      lo = std::partition_point(sorted.stamps.begin(), sorted.stamps.end(), [&](int64_t s) { return Wide{s} < q; }) -
           sorted.stamps.begin();
    } else {
      while (lo < m && Wide{sorted.stamps[static_cast<size_t>(lo)]} < q) ++lo;
    }
    previous_q = q;
    // The nearest stamp is the smallest one >= q or the largest one < q; within a run of equal
    // stamps the first in file order, and between the two sides the first in file order on a tie.
    Eigen::Index best = -1;
    Wide best_diff = 0;
    if (lo < m) {
      best = sorted.FileIndex(lo);  // first of its run, since ties are sorted in file order
      best_diff = Wide{sorted.stamps[static_cast<size_t>(lo)]} - q;
    }
    if (lo > 0) {
      const Eigen::Index start = sorted.run_start[static_cast<size_t>(lo - 1)];
      const Eigen::Index below = sorted.FileIndex(start);
      const Wide diff = q - Wide{sorted.stamps[static_cast<size_t>(start)]};
      if (best < 0 || diff < best_diff || (diff == best_diff && below < best)) {
        best = below;
        best_diff = diff;
      }
    }
    if (best_diff <= Wide{options.max_diff_ns}) {
      (est_longer ? result.ref : result.est).push_back(k);
      (est_longer ? result.est : result.ref).push_back(best);
    }
  }
  return result;
}

Association Associate(const traj::TrajectoryView& ref, const traj::TrajectoryView& est,
                      const AssociationOptions& options) {
  if (ref.empty() || est.empty()) {
    throw ComputeError(fmt::format("nothing to compare: the {} has no poses", ref.empty() ? "reference" : "estimate"));
  }
  if (!ref.has_stamps() || !est.has_stamps()) {
    if (ref.size() != est.size()) {
      throw ComputeError(fmt::format(
          "the reference has {} poses and the estimate {}: without stamps (KITTI) pose i is compared with pose i, "
          "so the files must have the same length (give each file its stamps with ReadOptions::kitti_times_path to "
          "associate by time)",
          ref.size(), est.size()));
    }
    Association result;
    result.by_index = true;
    result.ref.resize(static_cast<size_t>(ref.size()));
    std::iota(result.ref.begin(), result.ref.end(), Eigen::Index{0});
    result.est = result.ref;
    return result;
  }
  Association result = AssociateStamps(ref.stamps_ns(), est.stamps_ns(), options);
  if (result.empty()) {
    throw ComputeError(fmt::format(
        "no estimate stamp is within AssociationOptions::max_diff_ns {} s of a reference stamp (with "
        "AssociationOptions::offset_ns {} s): reference stamps span {}, estimate stamps span {}. If the clocks "
        "differ, give AssociationOptions::offset_ns (est + offset = ref); if "
        "the ranges differ by a factor of 1000 or 1e9, one file is in other units (ms, ns) than its format says",
        traj::ToSeconds(options.max_diff_ns), traj::ToSeconds(options.offset_ns), Range(ref.stamps_ns()),
        Range(est.stamps_ns())));
  }
  return result;
}

std::vector<int64_t> PairedStamps(std::span<const int64_t> stamps_ns, std::span<const Eigen::Index> indices) {
  std::vector<int64_t> out(indices.size());
  for (size_t k = 0; k < indices.size(); ++k) out[k] = stamps_ns[static_cast<size_t>(indices[k])];
  return out;
}

}  // namespace cheval::eval
