// Helpers shared by the evaluation tests: building small trajectories by hand, random rotations,
// moving a whole trajectory by a similarity, and a drone flight with exact velocity.

#pragma once

#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "cheval/eval/pairs.h"
#include "cheval/sim/motion.h"
#include "cheval/traj/trajectory.h"

namespace cheval::eval::testing {

// Expects `call` to throw an `Error` whose message contains every one of `parts`.
template <typename Error, typename Call>
void ExpectThrowWith(const Call& call, std::initializer_list<std::string> parts) {
  try {
    call();
    ADD_FAILURE() << "expected an exception";
  } catch (const Error& e) {
    for (const std::string& part : parts) EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

// A unit quaternion of angle `angle` (rad) about `axis`.
inline Eigen::Quaterniond AxisAngle(double angle, const Eigen::Vector3d& axis) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis.normalized()));
}

// A uniformly random rotation.
inline Eigen::Quaterniond RandomRotation(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  Eigen::Quaterniond q(g(rng), g(rng), g(rng), g(rng));
  q.normalize();
  return q;
}

// One pose to append: stamp (ns), position, orientation and optional velocity.
struct PoseSpec {
  int64_t stamp_ns = 0;
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
};

// A trajectory of `poses` with quaternion orientation (kNone when `orientation` is false) and
// velocity when `velocity` is true.
inline traj::Trajectory MakeTrajectory(const std::vector<PoseSpec>& poses, bool velocity = false,
                                       bool orientation = true) {
  traj::Channels channels;
  channels.velocity = velocity;
  channels.orientation = orientation ? traj::OrientationKind::kQuaternion : traj::OrientationKind::kNone;
  traj::Trajectory t(channels);
  for (const PoseSpec& s : poses) {
    const double q[4] = {s.q.x(), s.q.y(), s.q.z(), s.q.w()};
    t.Append(s.stamp_ns, s.p.data(), q, s.v.data());
  }
  return t;
}

// The poses of `trajectory` as PoseSpecs (orientation as unit quaternions, velocity if present).
inline std::vector<PoseSpec> PosesOf(const traj::TrajectoryView& trajectory) {
  std::vector<PoseSpec> out;
  for (Eigen::Index i = 0; i < trajectory.size(); ++i) {
    PoseSpec s;
    s.stamp_ns = trajectory.stamps_ns()[i];
    s.p = trajectory.positions().col(i);
    if (trajectory.has_orientation()) s.q = trajectory.UnitQuaternion(i);
    if (trajectory.has_velocity()) s.v = trajectory.velocities().col(i);
    out.push_back(s);
  }
  return out;
}

// `trajectory` moved by the similarity S: R' = R_S R, p' = c R_S p + t, v' = c R_S v.
inline traj::Trajectory Transformed(const traj::TrajectoryView& trajectory, const Similarity& s) {
  std::vector<PoseSpec> poses = PosesOf(trajectory);
  const Eigen::Quaterniond qs(s.rotation);
  for (PoseSpec& p : poses) {
    p.p = s.ApplyToPoint(p.p);
    p.v = s.ApplyToVector(p.v);
    p.q = qs * p.q;
  }
  return MakeTrajectory(poses, trajectory.has_velocity(), trajectory.has_orientation());
}

// A random similarity with a rotation of any angle, a translation of ~10 m and the given scale.
inline Similarity RandomSimilarity(std::mt19937_64& rng, double scale = 1.0) {
  std::normal_distribution<double> g;
  Similarity s;
  s.rotation = RandomRotation(rng).toRotationMatrix();
  s.translation = Eigen::Vector3d(g(rng), g(rng), g(rng)) * 10.0;
  s.scale = scale;
  return s;
}

// The simulated drone of `seconds` at 100 Hz (exact states at any stamp), and its flight on the
// nominal grid with exact velocity (TUM + velocity).
inline sim::MotionModel DroneModel(double seconds, uint64_t seed = 1) {
  sim::MotionOptions options;
  options.kind = sim::MotionKind::kDrone;
  options.duration_s = seconds;
  options.rate_hz = 100.0;
  options.seed = seed;
  return sim::MotionModel(options);
}
inline traj::Trajectory DroneTruth(double seconds, uint64_t seed = 1) {
  return sim::GenerateMotion(DroneModel(seconds, seed));
}

// `truth` with Gaussian noise: positions (m), orientations (rad, right perturbation) and velocities
// (m/s), deterministic in `seed`.
inline traj::Trajectory Noisy(const traj::TrajectoryView& truth, double position_sigma, double rotation_sigma,
                              double velocity_sigma, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g;
  std::vector<PoseSpec> poses = PosesOf(truth);
  for (PoseSpec& p : poses) {
    p.p += position_sigma * Eigen::Vector3d(g(rng), g(rng), g(rng));
    const Eigen::Vector3d w = rotation_sigma * Eigen::Vector3d(g(rng), g(rng), g(rng));
    if (w.norm() > 0) p.q = p.q * AxisAngle(w.norm(), w);
    p.v += velocity_sigma * Eigen::Vector3d(g(rng), g(rng), g(rng));
  }
  return MakeTrajectory(poses, truth.has_velocity(), truth.has_orientation());
}

}  // namespace cheval::eval::testing
