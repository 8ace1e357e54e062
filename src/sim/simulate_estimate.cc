// A simulated state estimator's output: the truth with drifting errors, as an odometry makes them
// (docs/sim.md, "Simulated estimates").
#include <cmath>
#include <vector>

#include "cheval/common/options.h"
#include "cheval/common/random.h"
#include "cheval/sim/motion.h"
#include "internal/streams.h"

namespace cheval::sim {

void EstimatorSimOptions::Validate() const {
  const OptionCheck check("EstimatorSimOptions");
  check(rate_hz > 0 && std::isfinite(rate_hz), "rate_hz", "must be a positive number of Hz, got {}", rate_hz);
  auto non_negative = [&check](double value, const char* field) {
    check(value >= 0 && std::isfinite(value), field, "must be a non-negative finite number, got {}", value);
  };
  non_negative(velocity_random_walk, "velocity_random_walk");
  non_negative(rotation_random_walk_rad, "rotation_random_walk_rad");
  non_negative(position_noise_m, "position_noise_m");
  non_negative(velocity_noise_mps, "velocity_noise_mps");
  check(delay_s >= 0 && std::isfinite(delay_s), "delay_s", "must be a non-negative number of seconds, got {}", delay_s);
}

traj::Trajectory SimulateEstimate(const MotionModel& model, const EstimatorSimOptions& options) {
  options.Validate();
  const MotionOptions& motion = model.options();
  const double duration = *motion.duration_s;
  const OptionCheck check("EstimatorSimOptions");
  check(options.delay_s < duration, "delay_s", "must be below the duration ({} s), got {}", duration, options.delay_s);
  const double span = duration - options.delay_s;
  const int64_t count = static_cast<int64_t>(std::floor(span * options.rate_hz)) + 1;
  check(count >= 2 && count <= 100'000'000, "rate_hz", "must give 2 to 1e8 poses over {} s (it gives {}), got {}", span,
        count, options.rate_hz);
  std::vector<int64_t> stamps(static_cast<size_t>(count));
  const int64_t first = motion.start_stamp_ns + std::llround(options.delay_s * 1e9);
  for (int64_t i = 0; i < count; ++i) {
    stamps[static_cast<size_t>(i)] = first + std::llround(static_cast<double>(i) * 1e9 / options.rate_hz);
  }
  const traj::Trajectory truth = SampleMotion(model, stamps);
  // One stream per estimate, after the streams of the measured copy.
  Random random(motion.seed, internal::kEstimate + 0x100 * options.stream);
  auto normal3 = [&random] { return internal::NormalVector(random); };

  traj::Trajectory estimate(traj::Channels{traj::OrientationKind::kQuaternion, true, false, true});
  estimate.Reserve(truth.size());
  const auto quaternions = truth.View().quaternions();
  const auto velocities = truth.View().velocities();
  Eigen::Vector3d velocity_error = Eigen::Vector3d::Zero(), position_drift = Eigen::Vector3d::Zero(),
                  rotation_error = Eigen::Vector3d::Zero();
  for (Eigen::Index i = 0; i < truth.size(); ++i) {
    if (i > 0) {
      const double dt = static_cast<double>(stamps[static_cast<size_t>(i)] - stamps[static_cast<size_t>(i - 1)]) * 1e-9;
      position_drift += velocity_error * dt;  // the drift is the integral of the velocity error
      velocity_error += options.velocity_random_walk * std::sqrt(dt) * normal3();
      rotation_error += options.rotation_random_walk_rad * std::sqrt(dt) * normal3();
    }
    const Eigen::Vector3d p = truth.positions().col(i) + position_drift + options.position_noise_m * normal3();
    const Eigen::Vector3d v = velocities.col(i) + velocity_error + options.velocity_noise_mps * normal3();
    const Eigen::Vector4d q_truth = quaternions.col(i);
    const double angle = rotation_error.norm();
    const Eigen::Quaterniond q =
        Eigen::Quaterniond(q_truth[3], q_truth[0], q_truth[1], q_truth[2]) *
        Eigen::Quaterniond(Eigen::AngleAxisd(angle, angle > 0 ? Eigen::Vector3d(rotation_error / angle)
                                                              : Eigen::Vector3d::UnitX()));
    const double xyzw[4] = {q.x(), q.y(), q.z(), q.w()};
    estimate.Append(stamps[static_cast<size_t>(i)], p.data(), xyzw, v.data());
  }
  return estimate;
}

}  // namespace cheval::sim
