// Time association: evo's semantics checked against a brute-force implementation written here from
// docs/evaluation.md, "Association" (iterate the shorter list, nearest stamp, first on ties, inclusive max_diff,
// est + offset ≈ ref), on sorted, unsorted and duplicated stamps; plus hand-checked cases.
#include "cheval/eval/associate.h"

#include <algorithm>
#include <random>

#include <gtest/gtest.h>

#include "cheval/common/error.h"
#include "eval_test_util.h"

namespace cheval::eval {
namespace {

constexpr int64_t kMs = 1'000'000;

// evo's sync.matching_time_indices as docs/evaluation.md ("Association") states it, O(n·m).
Association BruteForce(const std::vector<int64_t>& ref, const std::vector<int64_t>& est, int64_t max_diff,
                       int64_t offset) {
  const bool est_longer = est.size() > ref.size();
  const std::vector<int64_t>& shorter = est_longer ? ref : est;
  const std::vector<int64_t>& longer = est_longer ? est : ref;
  Association a;
  for (size_t k = 0; k < shorter.size(); ++k) {
    size_t best = 0;
    int64_t best_diff = -1;
    for (size_t j = 0; j < longer.size(); ++j) {
      // other list shifted: ref - offset, or est + offset
      const int64_t shifted = est_longer ? longer[j] + offset : longer[j] - offset;
      const int64_t diff = std::abs(shifted - shorter[k]);
      if (best_diff < 0 || diff < best_diff) {
        best = j;
        best_diff = diff;
      }
    }
    if (best_diff >= 0 && best_diff <= max_diff) {
      (est_longer ? a.ref : a.est).push_back(static_cast<Eigen::Index>(k));
      (est_longer ? a.est : a.ref).push_back(static_cast<Eigen::Index>(best));
    }
  }
  return a;
}

TEST(AssociateTest, HandCheckedNearestFirstOnTiesInclusive) {
  const std::vector<int64_t> ref = {0, 10 * kMs, 20 * kMs, 30 * kMs};
  const std::vector<int64_t> est = {4 * kMs, 5 * kMs, 16 * kMs, 40 * kMs};
  AssociationOptions options;
  options.max_diff_ns = 5 * kMs;
  const Association a = AssociateStamps(ref, est, options);
  // Equal lengths: iterate the estimate. 4 -> 0 (4 ms); 5 -> tie 0/10 -> 0 (first), 5 ms <= 5 ms kept;
  // 16 -> 20 (4 ms); 40 -> 30 (10 ms > 5 ms) dropped.
  EXPECT_EQ(a.est, (std::vector<Eigen::Index>{0, 1, 2}));
  EXPECT_EQ(a.ref, (std::vector<Eigen::Index>{0, 0, 2}));  // not one-to-one: ref 0 used twice
  options.max_diff_ns = 5 * kMs - 1;                         // 5 ms no longer within
  EXPECT_EQ(AssociateStamps(ref, est, options).est, (std::vector<Eigen::Index>{0, 2}));
}

TEST(AssociateTest, OffsetMeansEstimatePlusOffsetIsReference) {
  const std::vector<int64_t> ref = {1000 * kMs, 1100 * kMs, 1200 * kMs};
  const std::vector<int64_t> est = {0, 100 * kMs, 200 * kMs, 300 * kMs};  // longer: iterate the reference
  AssociationOptions options;
  EXPECT_TRUE(AssociateStamps(ref, est, options).empty());
  options.offset_ns = 1000 * kMs;
  const Association a = AssociateStamps(ref, est, options);
  EXPECT_EQ(a.ref, (std::vector<Eigen::Index>{0, 1, 2}));
  EXPECT_EQ(a.est, (std::vector<Eigen::Index>{0, 1, 2}));
  options.offset_ns = -1000 * kMs;
  EXPECT_TRUE(AssociateStamps(ref, est, options).empty());
}

TEST(AssociateTest, ShorterListIsIteratedInFileOrder) {
  // Reference shorter and unsorted: pairs come in the reference's file order.
  const std::vector<int64_t> ref = {30 * kMs, 10 * kMs};
  const std::vector<int64_t> est = {9 * kMs, 12 * kMs, 29 * kMs, 31 * kMs};
  const Association a = AssociateStamps(ref, est);
  EXPECT_EQ(a.ref, (std::vector<Eigen::Index>{0, 1}));
  EXPECT_EQ(a.est, (std::vector<Eigen::Index>{2, 0}));  // 30 -> 29 (tie with 31: the first), 10 -> 9
}

TEST(AssociateTest, DuplicatedStampsTakeTheFirstInFileOrder) {
  const std::vector<int64_t> ref = {50 * kMs, 20 * kMs, 20 * kMs, 10 * kMs, 20 * kMs};
  const std::vector<int64_t> est = {21 * kMs, 20 * kMs};
  const Association a = AssociateStamps(ref, est);
  EXPECT_EQ(a.ref, (std::vector<Eigen::Index>{1, 1}));  // the first 20 ms in file order, also for a 1 ms miss
}

// The same pairs as the brute force on random lists: sorted or shuffled, with duplicates, with
// every length relation, offsets and tolerances (including ties and boundary values, since stamps
// are drawn on a coarse grid).
TEST(AssociateTest, MatchesBruteForceOnRandomLists) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 400; ++trial) {
    const size_t n = 1 + rng() % 60, m = 1 + rng() % 60;
    std::uniform_int_distribution<int64_t> grid(0, 40);
    std::vector<int64_t> ref(n), est(m);
    for (auto& s : ref) s = grid(rng) * 5 * kMs + 1'400'000'000'000'000'000;
    for (auto& s : est) s = grid(rng) * 5 * kMs + 1'400'000'000'000'000'000;
    if (trial % 2 == 0) {
      std::sort(ref.begin(), ref.end());
      std::sort(est.begin(), est.end());
    }
    AssociationOptions options;
    options.evo_float_seconds = false;  // the exact rule; evo's float decisions: associate_ties_test.cc
    options.max_diff_ns = static_cast<int64_t>(rng() % 4) * 5 * kMs;  // 0, 5, 10, 15 ms: exact hits and ties
    options.offset_ns = (static_cast<int64_t>(rng() % 5) - 2) * 5 * kMs;
    const Association fast = AssociateStamps(ref, est, options);
    const Association slow = BruteForce(ref, est, options.max_diff_ns, options.offset_ns);
    ASSERT_EQ(fast.ref, slow.ref) << "trial " << trial;
    ASSERT_EQ(fast.est, slow.est) << "trial " << trial;
  }
}

// Long sorted lists with clusters and jumps: the search walks forward between near queries and
// binary-searches after far ones; both must give the brute force's pairs.
TEST(AssociateTest, MatchesBruteForceOnLongClusteredLists) {
  std::mt19937_64 rng(8);
  for (int trial = 0; trial < 6; ++trial) {
    std::vector<int64_t> ref, est;
    int64_t t = 0;
    for (int i = 0; i < 3000; ++i) {
      t += (rng() % 50 == 0) ? static_cast<int64_t>(rng() % 5'000) * kMs : static_cast<int64_t>(rng() % 6) * kMs;
      ref.push_back(t);
      if (rng() % 3 == 0) est.push_back(t + (static_cast<int64_t>(rng() % 21) - 10) * kMs);
    }
    std::sort(est.begin(), est.end());
    if (trial % 3 == 2) std::shuffle(est.begin(), est.end(), rng);
    AssociationOptions options;
    options.evo_float_seconds = false;
    options.max_diff_ns = static_cast<int64_t>(trial) * 2 * kMs;
    const Association fast = AssociateStamps(ref, est, options);
    const Association slow = BruteForce(ref, est, options.max_diff_ns, 0);
    ASSERT_EQ(fast.ref, slow.ref) << "trial " << trial;
    ASSERT_EQ(fast.est, slow.est) << "trial " << trial;
    ASSERT_GT(fast.size(), 0);
  }
}

TEST(AssociateTest, WithoutStampsPairsByIndexAndNeedsEqualLengths) {
  using testing::MakeTrajectory;
  using testing::PoseSpec;
  traj::Trajectory a = MakeTrajectory({PoseSpec{}, PoseSpec{}, PoseSpec{}});
  traj::Trajectory b = MakeTrajectory({PoseSpec{}, PoseSpec{}, PoseSpec{}});
  a.SetHasStamps(false);
  b.SetHasStamps(false);
  const Association pairs = Associate(a.View(), b.View());
  EXPECT_TRUE(pairs.by_index);
  EXPECT_EQ(pairs.est, (std::vector<Eigen::Index>{0, 1, 2}));
  traj::Trajectory c = MakeTrajectory({PoseSpec{}, PoseSpec{}});
  c.SetHasStamps(false);
  testing::ExpectThrowWith<ComputeError>([&] { Associate(a.View(), c.View()); },
                                         {"the reference has 3 poses and the estimate 2"});
}

TEST(AssociateTest, NoPairsSaysBothRangesAndSuggestsOffsetOrUnits) {
  using testing::MakeTrajectory;
  using testing::PoseSpec;
  const traj::Trajectory ref = MakeTrajectory({PoseSpec{1'000'000'000}, PoseSpec{2'000'000'000}});
  const traj::Trajectory est = MakeTrajectory({PoseSpec{5'000'000'000}, PoseSpec{6'000'000'000}});
  testing::ExpectThrowWith<ComputeError>([&] { Associate(ref.View(), est.View()); },
                                         {"reference stamps span 1.000000000 .. 2.000000000 s",
                                          "estimate stamps span 5.000000000 .. 6.000000000 s",
                                          "AssociationOptions::offset_ns", "units"});
  AssociationOptions shifted;
  shifted.offset_ns = -4'000'000'000;
  EXPECT_EQ(Associate(ref.View(), est.View(), shifted).size(), 2);
  AssociationOptions negative;
  negative.max_diff_ns = -1;
  EXPECT_THROW(AssociateStamps({}, {}, negative), UsageError);
}

TEST(AssociateTest, SecondsToNanosecondsRoundsAndRejectsNonFinite) {
  EXPECT_EQ(SecondsToNanoseconds(0.01, "AssociationOptions::max_diff_ns"), 10'000'000);
  EXPECT_EQ(SecondsToNanoseconds(-1.5, "AssociationOptions::offset_ns"), -1'500'000'000);
  EXPECT_THROW(SecondsToNanoseconds(std::nan(""), "AssociationOptions::offset_ns"), UsageError);
  EXPECT_THROW(SecondsToNanoseconds(1e12, "AssociationOptions::offset_ns"), UsageError);
}

}  // namespace
}  // namespace cheval::eval
