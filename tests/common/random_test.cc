// The random generator's contract (include/cheval/common/random.h). Expected values come from the
// definitions, not from the code: the C++ standard's 10000th output of std::mt19937_64 for seed 5489,
// the published SplitMix64 outputs for state 1234567, and Box–Muller of a std::mt19937_64's outputs.
#include "cheval/common/random.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <vector>

namespace cheval {
namespace {

constexpr uint64_t kGolden = 0x9e3779b97f4a7c15ULL;
constexpr uint64_t kStreamOffset = 0x632be59bd9b4e019ULL;  // Random(seed, stream), random.h
// [rand.predef]: the 10000th consecutive invocation of a default-constructed std::mt19937_64
// (seed 5489) produces 9981545732273789042.
constexpr uint64_t kDefaultSeed = 5489;
constexpr uint64_t kTenThousandth = 9981545732273789042ULL;

// SplitMix64's output from state x, written from its definition (Steele, Lea, Flood, OOPSLA 2014).
uint64_t SplitMix(uint64_t x) {
  uint64_t z = x + kGolden;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// Inverse of an odd number modulo 2⁶⁴ (Newton: each step doubles the correct low bits).
uint64_t InverseOdd(uint64_t a) {
  uint64_t x = a;  // correct to 3 bits, since a·a ≡ 1 (mod 8)
  for (int i = 0; i < 5; ++i) x *= 2 - a * x;
  return x;
}

// x from y = x ^ (x >> s).
uint64_t UndoXorShift(uint64_t y, int s) {
  uint64_t x = y;
  for (int i = 0; i < 64 / s + 1; ++i) x = y ^ (x >> s);
  return x;
}

// The state x with SplitMix(x) = value: every step of the mix is a bijection of 64-bit words.
uint64_t SplitMixInverse(uint64_t value) {
  uint64_t z = UndoXorShift(value, 31);
  z = UndoXorShift(z * InverseOdd(0x94d049bb133111ebULL), 27);
  z = UndoXorShift(z * InverseOdd(0xbf58476d1ce4e5b9ULL), 30);
  return z - kGolden;
}

TEST(SplitMix, MatchesTheReferenceOutputsForState1234567) {
  // The first five outputs of the reference splitmix64.c seeded with 1234567 (Rosetta Code,
  // "Pseudo-random numbers/Splitmix64"); output k comes from state 1234567 + k·golden.
  const uint64_t expected[] = {6457827717110365317ULL, 3203168211198807973ULL, 9817491932198370423ULL,
                               4593380528125082431ULL, 16408922859458223821ULL};
  for (uint64_t k = 0; k < 5; ++k) {
    EXPECT_EQ(SplitMix(1234567 + k * kGolden), expected[k]) << k;  // the test's own definition
    EXPECT_EQ(Random::SplitMix(1234567 + k * kGolden), expected[k]) << k;
    EXPECT_EQ(SplitMixInverse(expected[k]), 1234567 + k * kGolden) << k;
  }
}

TEST(Random, EngineSeedIsStdMt19937_64) {
  Random random = Random::FromEngineSeed(kDefaultSeed);
  for (int i = 1; i < 10000; ++i) random();
  EXPECT_EQ(random(), kTenThousandth);
}

// Random(seed, stream) seeds the engine with SplitMix(seed ^ SplitMix(stream + offset)): choosing
// seed so that this is 5489 must give the standard's 10000th value, for any stream.
TEST(Random, StreamSeedingIsSplitMixOfSeedAndStream) {
  for (const uint64_t stream : {0ULL, 1ULL, 8ULL, 0x1234ULL}) {
    const uint64_t seed = SplitMixInverse(kDefaultSeed) ^ SplitMix(stream + kStreamOffset);
    Random random(seed, stream);
    for (int i = 1; i < 10000; ++i) random();
    EXPECT_EQ(random(), kTenThousandth) << stream;
  }
}

TEST(Random, SameSeedAndStreamSameSequenceOtherwiseAnother) {
  Random a(3, 4), b(3, 4), other_stream(3, 5), other_seed(4, 4);
  int equal_stream = 0, equal_seed = 0;
  for (int i = 0; i < 1000; ++i) {
    const uint64_t x = a();
    ASSERT_EQ(x, b()) << i;
    equal_stream += x == other_stream();
    equal_seed += x == other_seed();
  }
  EXPECT_EQ(equal_stream, 0);
  EXPECT_EQ(equal_seed, 0);
}

TEST(Random, UniformIsTheTop53BitsTimesTwoToTheMinus53) {
  Random random = Random::FromEngineSeed(kDefaultSeed);
  for (int i = 1; i < 10000; ++i) random();
  EXPECT_EQ(random.Uniform(), static_cast<double>(kTenThousandth >> 11) * 0x1.0p-53);
  // The same map on a std::mt19937_64 of another seed; Uniform(lo, hi) and Sign() on top of it.
  Random a = Random::FromEngineSeed(77);
  std::mt19937_64 engine(77);
  for (int i = 0; i < 1000; ++i) {
    ASSERT_EQ(a.Uniform(), static_cast<double>(engine() >> 11) * 0x1.0p-53) << i;
    const double u = static_cast<double>(engine() >> 11) * 0x1.0p-53;
    ASSERT_EQ(a.Uniform(-2.0, 3.0), -2.0 + 5.0 * u) << i;
    ASSERT_EQ(a.Sign(), static_cast<double>(engine() >> 11) * 0x1.0p-53 < 0.5 ? -1.0 : 1.0) << i;
  }
}

TEST(Random, UniformIsInTheHalfOpenUnitInterval) {
  Random random(11, 0);
  double lo = 1.0, hi = 0.0, sum = 0.0;
  const int n = 1'000'000;
  for (int i = 0; i < n; ++i) {
    const double u = random.Uniform();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    lo = std::min(lo, u);
    hi = std::max(hi, u);
    sum += u;
  }
  // n uniforms: the extremes are within ~1/n of the ends (P(min > 20/n) = e^-20); the mean's standard
  // error is 1/√(12 n) ≈ 2.9e-4, bounded at 5 of them.
  EXPECT_LT(lo, 20.0 / n);
  EXPECT_GT(hi, 1.0 - 20.0 / n);
  EXPECT_NEAR(sum / n, 0.5, 5.0 / std::sqrt(12.0 * n));
}

// Box–Muller of two uniforms, as random.h defines it.
std::pair<double, double> BoxMuller(double u1, double u2) {
  const double r = std::sqrt(-2.0 * std::log(u1)), a = 2.0 * std::numbers::pi * u2;
  return {r * std::cos(a), r * std::sin(a)};
}

TEST(Random, NormalIsBoxMullerOfTwoOutputs) {
  for (const auto input : {Random::BoxMullerInput::kHalfOpen, Random::BoxMullerInput::kMidpoint}) {
    Random random = Random::FromEngineSeed(kDefaultSeed, input);
    std::mt19937_64 engine(kDefaultSeed);
    for (int i = 0; i < 1000; ++i) {
      const double k1 = static_cast<double>(engine() >> 11), k2 = static_cast<double>(engine() >> 11);
      const auto [c, s] = input == Random::BoxMullerInput::kHalfOpen
                              ? BoxMuller(1.0 - k1 * 0x1.0p-53, k2 * 0x1.0p-53)
                              : BoxMuller((k1 + 0.5) * 0x1.0p-53, (k2 + 0.5) * 0x1.0p-53);
      ASSERT_EQ(random.Normal(), c) << i;  // r cos a first,
      ASSERT_EQ(random.Normal(), s) << i;  // then the kept r sin a, without a draw
    }
    EXPECT_EQ(random(), engine());  // two outputs per pair of normals, no more
  }
}

// Sample moments of standard normals against 0, 1, 0, 3, each within 5 of its standard errors:
// √(Var(xᵏ)/n) with Var(x) = 1, Var(x²) = 2, Var(x³) = E x⁶ = 15, Var(x⁴) = E x⁸ − 9 = 96.
void ExpectStandardNormalMoments(Random& random) {
  const int n = 1'000'000;
  double m1 = 0, m2 = 0, m3 = 0, m4 = 0;
  for (int i = 0; i < n; ++i) {
    const double x = random.Normal();
    m1 += x;
    m2 += x * x;
    m3 += x * x * x;
    m4 += x * x * x * x;
  }
  const double se = 5.0 / std::sqrt(static_cast<double>(n));
  EXPECT_NEAR(m1 / n, 0.0, se * 1.0);
  EXPECT_NEAR(m2 / n, 1.0, se * std::sqrt(2.0));
  EXPECT_NEAR(m3 / n, 0.0, se * std::sqrt(15.0));
  EXPECT_NEAR(m4 / n, 3.0, se * std::sqrt(96.0));
}

TEST(Random, NormalHasStandardMoments) {
  Random stream(1, 0);
  ExpectStandardNormalMoments(stream);
  Random midpoint = Random::FromEngineSeed(42, Random::BoxMullerInput::kMidpoint);
  ExpectStandardNormalMoments(midpoint);
}

// A std distribution draws from Random exactly as from the engine it wraps (so a user of
// std::mt19937_64 + a std distribution can take Random::FromEngineSeed without other numbers; the
// distribution's own numbers still depend on the standard library).
TEST(Random, IsAUniformRandomBitGeneratorWithTheEnginesOutputs) {
  static_assert(std::uniform_random_bit_generator<Random>);
  Random random = Random::FromEngineSeed(9);
  std::mt19937_64 engine(9);
  std::normal_distribution<double> a(0.0, 1.0), b(0.0, 1.0);
  for (int i = 0; i < 1000; ++i) ASSERT_EQ(a(random), b(engine)) << i;
}

}  // namespace
}  // namespace cheval
