#include "cheval/eval/associate.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
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

// evo's decision in float64 seconds (sync.matching_time_indices): for a stamp s1 of the shorter list,
// the index of the smallest |(s2 + offset_2) - s1| over the longer list, the first in file order on
// equal values (np.argmin), kept when that value is <= max_diff. The exact nanosecond search finds
// the nearest stamp; evo's argmin is among the stamps within float rounding of it (margin_ns), which
// are compared here with evo's arithmetic.
struct EvoChoice {
  std::vector<double> shorter_s, longer_s;  // evo's seconds, in file order
  double offset_2 = 0.0, max_diff = 0.0;
  Wide margin_ns = 0;

  EvoChoice(std::span<const int64_t> shorter, std::span<const int64_t> longer, const SortedStamps& sorted,
            bool est_longer, const AssociationOptions& options)
      : offset_2((est_longer ? 1.0 : -1.0) * options.offset_s()), max_diff(options.max_diff_s()) {
    const EvoStampSeconds short_kind = est_longer ? options.ref_seconds : options.est_seconds;
    const EvoStampSeconds long_kind = est_longer ? options.est_seconds : options.ref_seconds;
    shorter_s.reserve(shorter.size());
    longer_s.reserve(longer.size());
    double largest = std::abs(offset_2);
    for (int64_t ns : shorter) shorter_s.push_back(EvoSeconds(ns, short_kind));
    for (int64_t ns : longer) longer_s.push_back(EvoSeconds(ns, long_kind));
    for (double v : shorter_s) largest = std::max(largest, std::abs(v));
    largest = std::max({largest, std::abs(EvoSeconds(sorted.stamps.front(), long_kind)),
                        std::abs(EvoSeconds(sorted.stamps.back(), long_kind))});
    // Each of the <= 6 roundings (two per conversion, the offset, the difference) is at most half an
    // ulp of the largest magnitude; 16 ulps in nanoseconds bound them with room.
    margin_ns = static_cast<Wide>(std::ceil(16.0 * largest * std::numeric_limits<double>::epsilon() * 1e9)) + 16;
  }

  Eigen::Index Choose(const SortedStamps& sorted, Eigen::Index lo, Wide q, Wide nearest_diff, Eigen::Index k) const {
    const Wide reach = nearest_diff + margin_ns;
    const double s1 = shorter_s[static_cast<size_t>(k)];
    Eigen::Index best = -1;
    double best_value = std::numeric_limits<double>::infinity();
    // Equal stamps have equal seconds: the first of a run in file order (the run's start) stands for it.
    auto consider = [&](Eigen::Index position) {
      const Eigen::Index file = sorted.FileIndex(position);
      const double value = std::abs((longer_s[static_cast<size_t>(file)] + offset_2) - s1);
      if (value < best_value || (value == best_value && file < best)) best = file, best_value = value;
    };
    const Eigen::Index m = static_cast<Eigen::Index>(sorted.stamps.size());
    for (Eigen::Index j = lo - 1; j >= 0 && q - Wide{sorted.stamps[static_cast<size_t>(j)]} <= reach;) {
      j = sorted.run_start[static_cast<size_t>(j)];
      consider(j);
      --j;
    }
    for (Eigen::Index j = lo; j < m && Wide{sorted.stamps[static_cast<size_t>(j)]} - q <= reach;) {
      consider(j);  // lo and every position reached below start a run
      const int64_t stamp = sorted.stamps[static_cast<size_t>(j)];
      j = std::upper_bound(sorted.stamps.begin() + j, sorted.stamps.end(), stamp) - sorted.stamps.begin();
    }
    return best_value <= max_diff ? best : -1;
  }
};

std::string Range(std::span<const int64_t> stamps) {
  const auto [lo, hi] = std::minmax_element(stamps.begin(), stamps.end());
  return fmt::format("{} .. {} s", traj::FormatSeconds(*lo), traj::FormatSeconds(*hi));
}

}  // namespace

double EvoSeconds(int64_t ns, EvoStampSeconds kind) {
  if (kind == EvoStampSeconds::kNanosecondsOver1e9) return static_cast<double>(ns) / 1e9;
  // The decimal "[-]S.NNNNNNNNN", parsed to the nearest double as Python's float() does.
  const uint64_t magnitude = ns < 0 ? 0 - static_cast<uint64_t>(ns) : static_cast<uint64_t>(ns);
  char text[40];
  const int length = std::snprintf(text, sizeof text, "%s%llu.%09llu", ns < 0 ? "-" : "",
                                   static_cast<unsigned long long>(magnitude / 1000000000ULL),
                                   static_cast<unsigned long long>(magnitude % 1000000000ULL));
  double value = 0.0;
  std::from_chars(text, text + length, value);
  return value;
}

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
  std::optional<EvoChoice> evo;
  if (options.evo_float_seconds) evo.emplace(shorter, longer, sorted, est_longer, options);
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
    if (options.evo_float_seconds) {
      if (best_diff > Wide{options.max_diff_ns} + 2 * evo->margin_ns) continue;
      best = evo->Choose(sorted, lo, q, best_diff, k);
      if (best < 0) continue;
    } else if (best_diff > Wide{options.max_diff_ns}) {
      continue;
    }
    (est_longer ? result.ref : result.est).push_back(k);
    (est_longer ? result.est : result.ref).push_back(best);
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
