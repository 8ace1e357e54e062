#include "../internal/shape.h"

#include <stdexcept>

#include "../internal/streams.h"
#include "cheval/common/random.h"

namespace cheval::sim::internal {

Mat3<Jet> RotationZYX(const Jet& yaw, const Jet& pitch, const Jet& roll) {
  const auto [sy, cy] = Jet::SinCos(yaw);
  const auto [sp, cp] = Jet::SinCos(pitch);
  const auto [sr, cr] = Jet::SinCos(roll);
  return {{{cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr},
           {sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr},
           {-sp, cp * sr, cp * cr}}};
}

std::unique_ptr<const Shape> MakeShape(MotionKind kind, uint64_t seed) {
  Random random(seed, kShape);
  switch (kind) {
    case MotionKind::kCar:
      return MakeCar(random);
    case MotionKind::kLegged:
      return MakeLegged(random);
    case MotionKind::kDrone:
      return MakeDrone(random);
    case MotionKind::kHandheld:
      return MakeHandheld(random);
  }
  throw std::invalid_argument("MakeShape: not a MotionKind (MotionOptions::Validate rejects it)");
}

}  // namespace cheval::sim::internal
