#pragma once
/// \file
/// The random streams of the simulator: every use draws from its own stream of the seed
/// (cheval::Random(seed, stream)), so e.g. changing the noise does not move the dropouts. The values
/// are part of the outputs: changing one changes every file made with that stream. Internal to src/sim.

#include <cstdint>

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

}  // namespace cheval::sim::internal
