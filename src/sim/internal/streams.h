#pragma once
/// \file
/// The random streams of the simulator and its sequenced draws: every use draws from its own stream
/// of the seed (cheval::Random(seed, stream)), so e.g. changing the noise does not move the dropouts.
/// The values are part of the outputs: changing one changes every file made with that stream.
/// Internal to src/sim.

#include <Eigen/Core>
#include <cstdint>

#include "cheval/common/random.h"

namespace cheval::sim::internal {

enum Stream : uint64_t {
  kShape = 1,      ///< the kind's random parameters
  kGaps,           ///< Measure: gap positions
  kDropout,        ///< Measure: dropouts
  kJitter,         ///< Measure: stamp offsets
  kNoise,          ///< Measure: position noise
  kAddNoise,       ///< AddPositionNoise
  kRotationNoise,  ///< Measure: orientation noise
  kEstimate,       ///< SimulateEstimate: stream kEstimate + 0x100 · EstimatorSimOptions::stream
};

/// Three standard normals from `random` as (x, y, z), drawn in the order z, y, x. The order is part
/// of the outputs: the draws were once the arguments of one constructor call, whose evaluation order
/// C++ leaves to the compiler, and GCC evaluated them last first. Drawing them in sequence keeps the
/// files and makes the numbers the same with every compiler.
inline Eigen::Vector3d NormalVector(Random& random) {
  const double z = random.Normal();
  const double y = random.Normal();
  const double x = random.Normal();
  return {x, y, z};
}

/// random.Sign() · random.Uniform(lo, hi), drawn in this order (sequenced for the same reason).
inline double SignedUniform(Random& random, double lo, double hi) {
  const double sign = random.Sign();
  return sign * random.Uniform(lo, hi);
}

}  // namespace cheval::sim::internal
