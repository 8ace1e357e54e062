#pragma once
/// \file
/// The project's random generator: reproducible numbers for simulations and noise, the same for a
/// seed with every compiler and standard library (docs/sim.md, "Random numbers").
///
/// The engine is std::mt19937_64, whose output sequence the C++ standard fixes ([rand.predef]: the
/// 10000th output of a default-constructed engine, seed 5489, is 9981545732273789042). The standard's
/// distributions (std::uniform_real_distribution, std::normal_distribution) are not fixed and differ
/// between libraries, so Uniform() and Normal() are cheval's own transforms of the engine's output.

#include <cstdint>
#include <random>

namespace cheval {

/// A seeded stream of random bits, uniform and standard normal numbers. Every draw is a fixed
/// function of the seed (and stream) and of the draws before it. Not thread-safe: one generator per
/// thread or per use (separate streams make uses independent of each other's number of draws).
/// Also a UniformRandomBitGenerator (operator(), min(), max()), so std distributions accept it and
/// consume the engine's outputs exactly as they would consume std::mt19937_64's.
class Random {
 public:
  /// How Normal() maps two engine outputs to its two uniforms u₁ (radius) and u₂ (angle). With
  /// k = output >> 11 (the top 53 bits):
  enum class BoxMullerInput {
    kHalfOpen,  ///< u₁ = 1 − k₁·2⁻⁵³ ∈ (0, 1], u₂ = k₂·2⁻⁵³ ∈ [0, 1) (the default)
    kMidpoint,  ///< u₁ = (k₁ + ½)·2⁻⁵³, u₂ = (k₂ + ½)·2⁻⁵³, both in (0, 1)
  };

  /// Stream `stream` of `seed`: the engine is std::mt19937_64 seeded with
  /// SplitMix(seed XOR SplitMix(stream + 0x632be59bd9b4e019)), where SplitMix(x) is the output of
  /// the SplitMix64 generator (Steele, Lea, Flood, "Fast splittable pseudorandom number generators",
  /// OOPSLA 2014) from state x: z = x + 0x9e3779b97f4a7c15, z = (z ^ z >> 30)·0xbf58476d1ce4e5b9,
  /// z = (z ^ z >> 27)·0x94d049bb133111eb, z ^ z >> 31 (mod 2⁶⁴). Nearby seeds and streams give
  /// unrelated engine seeds. Normal() uses BoxMullerInput::kHalfOpen.
  Random(uint64_t seed, uint64_t stream);

  /// The engine seeded exactly as std::mt19937_64(engine_seed), for callers whose numbers are fixed
  /// by their own seeding; `input` chooses Normal()'s uniforms.
  static Random FromEngineSeed(uint64_t engine_seed, BoxMullerInput input = BoxMullerInput::kHalfOpen);

  /// SplitMix(x) as defined at Random(seed, stream).
  static uint64_t SplitMix(uint64_t x);

  using result_type = uint64_t;
  static constexpr result_type min() { return std::mt19937_64::min(); }
  static constexpr result_type max() { return std::mt19937_64::max(); }
  /// The engine's next output (all 64 bits).
  result_type operator()() { return engine_(); }

  /// k·2⁻⁵³ with k the top 53 bits of the next output: uniform on the 2⁵³ doubles j·2⁻⁵³ of [0, 1).
  double Uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  /// lo + (hi − lo)·Uniform(): in [lo, hi) up to the rounding of the product.
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  /// −1 when Uniform() < 0.5, else +1 (one output).
  double Sign() { return Uniform() < 0.5 ? -1.0 : 1.0; }

  /// A standard normal number by the Box–Muller transform (Box & Muller, Ann. Math. Stat. 29, 1958):
  /// from two outputs, uniforms u₁, u₂ (see BoxMullerInput), r = √(−2 ln u₁), a = 2π·u₂; returns
  /// r·cos a and keeps r·sin a, which the next call returns without drawing. So the calls 2i and
  /// 2i + 1 use the outputs 2i and 2i + 1 of the engine (when no other draw is interleaved).
  double Normal();

 private:
  struct EngineSeed {
    uint64_t value;
  };
  Random(EngineSeed seed, BoxMullerInput input) : engine_(seed.value), input_(input) {}

  std::mt19937_64 engine_;
  BoxMullerInput input_ = BoxMullerInput::kHalfOpen;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace cheval
