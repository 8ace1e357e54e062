#pragma once
/// \file
/// Synthetic motion with exact derivatives, for tests, demos and benchmarks. Every trajectory is an
/// analytic function of time, so positions, velocities, orientations and body angular velocities
/// are exact; measurement noise, if asked for, is added to a copy.

#include <cstdint>
#include <optional>
#include <string_view>

#include "cheval/traj/trajectory.h"

namespace cheval::sim {

/// Kinds of synthetic motion. (kDrone is a Lissajous figure flown with yaw along the path and the
/// roll/pitch a multirotor needs to accelerate; more kinds arrive with the velocity module.)
enum class MotionKind { kDrone };

std::string_view ToString(MotionKind kind);
/// Parses a kind name ("drone"); nullopt if unknown.
std::optional<MotionKind> MotionKindFromString(std::string_view name);

/// Options of GenerateMotion. Validated by GenerateMotion (UsageError naming the option).
struct MotionOptions {
  MotionKind kind = MotionKind::kDrone;
  double duration_s = 60.0;            ///< > 0
  double rate_hz = 200.0;              ///< > 0, samples per second
  int64_t start_stamp_ns = 1'403'636'580'000'000'000;  ///< absolute start (EuRoC-like epoch stamps)
  uint64_t seed = 1;                   ///< seeds the noise and the shape's random phases
};

/// Exact motion sampled at `rate_hz` from `start_stamp_ns`: positions (m), unit quaternions,
/// world-frame velocities (m/s) and body angular velocities (rad/s). Throws UsageError.
traj::Trajectory GenerateMotion(const MotionOptions& options);

/// A copy of `truth` without velocities, with N(0, sigma²) noise on every position coordinate
/// (metres), drawn from a generator seeded with `seed`. sigma >= 0.
traj::Trajectory AddPositionNoise(const traj::TrajectoryView& truth, double sigma_m, uint64_t seed);

}  // namespace cheval::sim
