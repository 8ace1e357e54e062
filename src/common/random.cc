#include "cheval/common/random.h"

#include <cmath>
#include <numbers>

namespace cheval {

Random::Random(uint64_t seed, uint64_t stream)
    : Random(EngineSeed{SplitMix(seed ^ SplitMix(stream + 0x632be59bd9b4e019ULL))}, BoxMullerInput::kHalfOpen) {}

Random Random::FromEngineSeed(uint64_t engine_seed, BoxMullerInput input) { return Random(EngineSeed{engine_seed}, input); }

uint64_t Random::SplitMix(uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

double Random::Normal() {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  double u1, u2;
  if (input_ == BoxMullerInput::kHalfOpen) {
    u1 = 1.0 - Uniform();
    u2 = Uniform();
  } else {
    u1 = (static_cast<double>(engine_() >> 11) + 0.5) * 0x1.0p-53;
    u2 = (static_cast<double>(engine_() >> 11) + 0.5) * 0x1.0p-53;
  }
  const double r = std::sqrt(-2.0 * std::log(u1));
  const double angle = 2.0 * std::numbers::pi * u2;
  spare_ = r * std::sin(angle);
  has_spare_ = true;
  return r * std::cos(angle);
}

}  // namespace cheval
