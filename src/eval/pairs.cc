#include "cheval/eval/pairs.h"

#include <fmt/format.h>

#include "cheval/common/error.h"

namespace cheval::eval {

PairedStates::PairedStates(const traj::TrajectoryView& ref, const traj::TrajectoryView& est,
                           const Association& association)
    : ref_(ref), est_(est), association_(&association) {}

void PairedStates::SetReferenceVelocities(Eigen::Matrix3Xd velocities) {
  if (velocities.cols() != size()) {
    throw ComputeError(fmt::format("reference velocities: expected one per pair ({}), got {}", size(),
                                   velocities.cols()));
  }
  ref_velocities_ = std::move(velocities);
}

void PairedStates::SetEstimateVelocityInBodyFrame(bool body_frame) {
  if (body_frame && !est_.has_orientation()) {
    throw ComputeError("body-frame estimate velocity needs the estimate's orientation to rotate it into the world "
                       "frame, and the estimate has none");
  }
  est_velocity_body_ = body_frame;
}

Eigen::Vector3d PairedStates::ReferenceVelocity(Eigen::Index k) const {
  if (ref_velocities_) return ref_velocities_->col(k);
  return ref_.velocities().col(RefIndex(k));
}

Eigen::Vector3d PairedStates::RawEstimateVelocity(Eigen::Index k) const {
  const Eigen::Index i = EstIndex(k);
  const Eigen::Vector3d v = est_.velocities().col(i);
  return est_velocity_body_ ? Eigen::Vector3d(est_.Rotation(i) * v) : v;
}

}  // namespace cheval::eval
