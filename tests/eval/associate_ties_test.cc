// evo decides the nearest stamp and the tolerance on float64 seconds (sync.matching_time_indices:
// np.abs(stamps_2 + offset_2 - stamp_1), np.argmin, <= max_diff), with the seconds as its readers
// make them (file_interface: float(decimal) for TUM, float(ns) / 1e9 for EuRoC). The default
// association reproduces those decisions; these tests check it against a transcription of that loop
// in doubles, on a constructed exact half-way tie and on random lists at epoch magnitude.
#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "cheval/eval/associate.h"

namespace cheval::eval {
namespace {

constexpr int64_t kMs = 1'000'000;
constexpr int64_t kEpoch = 1'403'636'580'000'000'000;  // EuRoC MH_05's first second, in ns

// evo's loop in float64: stamps_1 the shorter list, stamps_2 the longer one plus offset_2.
Association EvoFloatLoop(const std::vector<int64_t>& ref, const std::vector<int64_t>& est, const AssociationOptions& o) {
  const bool est_longer = est.size() > ref.size();
  const std::vector<int64_t>& shorter = est_longer ? ref : est;
  const std::vector<int64_t>& longer = est_longer ? est : ref;
  const EvoStampSeconds short_kind = est_longer ? o.ref_seconds : o.est_seconds;
  const EvoStampSeconds long_kind = est_longer ? o.est_seconds : o.ref_seconds;
  const double offset_2 = est_longer ? o.offset_s() : -o.offset_s();
  std::vector<double> stamps_2;
  for (int64_t ns : longer) stamps_2.push_back(EvoSeconds(ns, long_kind) + offset_2);
  Association a;
  for (size_t k = 0; k < shorter.size(); ++k) {
    const double stamp_1 = EvoSeconds(shorter[k], short_kind);
    size_t index_2 = 0;  // np.argmin: the first minimum
    for (size_t j = 1; j < stamps_2.size(); ++j) {
      if (std::abs(stamps_2[j] - stamp_1) < std::abs(stamps_2[index_2] - stamp_1)) index_2 = j;
    }
    if (std::abs(stamps_2[index_2] - stamp_1) <= o.max_diff_s()) {
      (est_longer ? a.ref : a.est).push_back(static_cast<Eigen::Index>(k));
      (est_longer ? a.est : a.ref).push_back(static_cast<Eigen::Index>(index_2));
    }
  }
  return a;
}

TEST(AssociateTiesTest, EvoSecondsAreWhatEvosReadersMake) {
  // float("1403636580.838555527") and float("1403636580838555527") / 1e9, as Python computes them.
  EXPECT_EQ(EvoSeconds(1'403'636'580'838'555'527, EvoStampSeconds::kDecimal), 1403636580.838555527);
  EXPECT_EQ(EvoSeconds(1'403'636'580'838'555'527, EvoStampSeconds::kNanosecondsOver1e9),
            1403636580838555527.0 / 1e9);
  EXPECT_EQ(EvoSeconds(-1'500'000'000, EvoStampSeconds::kDecimal), -1.5);
  EXPECT_EQ(EvoSeconds(5, EvoStampSeconds::kDecimal), 5e-9);
}

// A reference at t and t + 10 ms and an estimate exactly half-way, at epoch magnitude. Exact
// arithmetic has a tie (the first, ref 0); evo's float seconds are not a tie: the rounding of
// the three stamps to doubles (ulp 2.4e-7 s) makes one side nearer.
TEST(AssociateTiesTest, ExactHalfWayTieGoesWhereEvosFloatsSendIt) {
  int checked_other_side = 0;
  for (int64_t base = kEpoch; base < kEpoch + 200 * kMs; base += 10 * kMs + 37) {
    const std::vector<int64_t> ref = {base, base + 10 * kMs};
    const std::vector<int64_t> est = {base + 5 * kMs};
    for (EvoStampSeconds kind : {EvoStampSeconds::kDecimal, EvoStampSeconds::kNanosecondsOver1e9}) {
      AssociationOptions options;
      options.ref_seconds = kind;
      options.est_seconds = kind;
      const Association evo = EvoFloatLoop(ref, est, options);
      ASSERT_EQ(evo.size(), 1);
      const Association a = AssociateStamps(ref, est, options);
      EXPECT_EQ(a.ref, evo.ref) << base;
      EXPECT_EQ(a.est, evo.est) << base;
      options.evo_float_seconds = false;
      EXPECT_EQ(AssociateStamps(ref, est, options).ref, std::vector<Eigen::Index>{0});  // exact: the first
      if (evo.ref[0] == 1) ++checked_other_side;
    }
  }
  // Some of these ties are decided for the later reference pose by evo: the case the rule is for.
  EXPECT_GT(checked_other_side, 0);
}

// The tolerance too is tested in floats: |dt| exactly max_diff in decimal can be just above or below.
TEST(AssociateTiesTest, ToleranceBoundaryIsEvosFloatComparison) {
  int differs = 0;
  for (int64_t base = kEpoch; base < kEpoch + 100 * kMs; base += 1 * kMs + 13) {
    const std::vector<int64_t> ref = {base};
    const std::vector<int64_t> est = {base + 10 * kMs};
    AssociationOptions options;  // max_diff 0.01 s
    const Association evo = EvoFloatLoop(ref, est, options);
    EXPECT_EQ(AssociateStamps(ref, est, options).size(), evo.size()) << base;
    if (evo.empty()) ++differs;  // the exact rule always keeps |dt| == max_diff
  }
  EXPECT_GT(differs, 0);
}

// Random lists at epoch magnitude on a coarse grid (many exact ties and boundary values), sorted or
// shuffled, duplicates, offsets, both stamp readings and mixed: the pairs of evo's float loop.
TEST(AssociateTiesTest, MatchesEvosFloatLoopOnRandomLists) {
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 600; ++trial) {
    const size_t n = 1 + rng() % 50, m = 1 + rng() % 50;
    std::uniform_int_distribution<int64_t> grid(0, 40);
    const int64_t base = kEpoch + static_cast<int64_t>(rng() % 1'000'000'007);
    std::vector<int64_t> ref(n), est(m);
    for (auto& s : ref) s = base + grid(rng) * 5 * kMs;
    for (auto& s : est) s = base + grid(rng) * 5 * kMs;
    if (trial % 2 == 0) {
      std::sort(ref.begin(), ref.end());
      std::sort(est.begin(), est.end());
    }
    AssociationOptions options;
    options.max_diff_ns = static_cast<int64_t>(rng() % 4) * 5 * kMs;
    options.offset_ns = (static_cast<int64_t>(rng() % 5) - 2) * 5 * kMs;
    options.ref_seconds = rng() % 2 ? EvoStampSeconds::kDecimal : EvoStampSeconds::kNanosecondsOver1e9;
    options.est_seconds = rng() % 2 ? EvoStampSeconds::kDecimal : EvoStampSeconds::kNanosecondsOver1e9;
    const Association fast = AssociateStamps(ref, est, options);
    const Association slow = EvoFloatLoop(ref, est, options);
    ASSERT_EQ(fast.ref, slow.ref) << "trial " << trial;
    ASSERT_EQ(fast.est, slow.est) << "trial " << trial;
  }
}

}  // namespace
}  // namespace cheval::eval
