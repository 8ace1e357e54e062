#include "cheval/sim/motion.h"

#include <cmath>
#include <numbers>
#include <random>

#include <fmt/format.h>

#include "cheval/common/error.h"

namespace cheval::sim {
namespace {

// Lissajous drone: p(t) = (A sin(a w t + phase), B sin(b w t), C + D sin(c w t)). Yaw follows the
// horizontal heading; roll and pitch are small sinusoids. Everything is differentiated by hand.
struct Drone {
  double A = 6.0, B = 4.0, C = 1.5, D = 0.5;
  double a = 1.0, b = 2.0, c = 3.0, w = 2.0 * std::numbers::pi / 20.0;  // one figure per 20 s, <= ~4 m/s
  double phase = 0.3;
  double tilt = 0.15, tilt_rate = 1.3;  // roll/pitch amplitude (rad) and angular frequency (rad/s)

  Eigen::Vector3d Position(double t) const {
    return {A * std::sin(a * w * t + phase), B * std::sin(b * w * t), C + D * std::sin(c * w * t)};
  }
  Eigen::Vector3d Velocity(double t) const {
    return {A * a * w * std::cos(a * w * t + phase), B * b * w * std::cos(b * w * t), D * c * w * std::cos(c * w * t)};
  }
  Eigen::Vector3d Acceleration(double t) const {
    return {-A * a * a * w * w * std::sin(a * w * t + phase), -B * b * b * w * w * std::sin(b * w * t),
            -D * c * c * w * w * std::sin(c * w * t)};
  }
  // Roll, pitch, yaw and their rates.
  void Attitude(double t, Eigen::Vector3d* rpy, Eigen::Vector3d* rpy_rate) const {
    const Eigen::Vector3d v = Velocity(t), acc = Acceleration(t);
    const double speed2 = v.x() * v.x() + v.y() * v.y();
    const double yaw = std::atan2(v.y(), v.x());
    const double yaw_rate = speed2 > 0 ? (v.x() * acc.y() - v.y() * acc.x()) / speed2 : 0.0;
    *rpy = {tilt * std::sin(tilt_rate * t), tilt * std::cos(0.7 * tilt_rate * t), yaw};
    *rpy_rate = {tilt * tilt_rate * std::cos(tilt_rate * t), -tilt * 0.7 * tilt_rate * std::sin(0.7 * tilt_rate * t),
                 yaw_rate};
  }
};

}  // namespace

std::string_view ToString(MotionKind kind) {
  switch (kind) {
    case MotionKind::kDrone: return "drone";
  }
  return "?";
}

std::optional<MotionKind> MotionKindFromString(std::string_view name) {
  if (name == "drone") return MotionKind::kDrone;
  return std::nullopt;
}

traj::Trajectory GenerateMotion(const MotionOptions& options) {
  if (!(options.duration_s > 0) || !std::isfinite(options.duration_s)) {
    throw UsageError(fmt::format("--duration must be a positive number of seconds, got {}", options.duration_s));
  }
  if (!(options.rate_hz > 0) || !std::isfinite(options.rate_hz)) {
    throw UsageError(fmt::format("--rate must be a positive number of Hz, got {}", options.rate_hz));
  }
  const auto samples = static_cast<Eigen::Index>(std::floor(options.duration_s * options.rate_hz)) + 1;
  if (samples > 100'000'000) throw UsageError("--duration x --rate asks for more than 1e8 samples");
  Drone drone;
  std::mt19937_64 rng(options.seed);
  drone.phase = std::uniform_real_distribution<double>(0.0, 2.0 * std::numbers::pi)(rng);

  traj::Trajectory trajectory(traj::Channels{traj::OrientationKind::kQuaternion, true, true, true});
  trajectory.Reserve(samples);
  const double period_ns = 1e9 / options.rate_hz;
  for (Eigen::Index i = 0; i < samples; ++i) {
    const auto offset_ns = static_cast<int64_t>(std::llround(static_cast<double>(i) * period_ns));
    const double t = static_cast<double>(offset_ns) * 1e-9;  // seconds since the start, exact on the grid
    const Eigen::Vector3d p = drone.Position(t), v = drone.Velocity(t);
    Eigen::Vector3d rpy, rate;
    drone.Attitude(t, &rpy, &rate);
    const Eigen::Matrix3d Rx = Eigen::AngleAxisd(rpy[0], Eigen::Vector3d::UnitX()).toRotationMatrix();
    const Eigen::Matrix3d Ry = Eigen::AngleAxisd(rpy[1], Eigen::Vector3d::UnitY()).toRotationMatrix();
    const Eigen::Matrix3d Rz = Eigen::AngleAxisd(rpy[2], Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const Eigen::Quaterniond q(Rz * Ry * Rx);
    // Body rate of R = Rz(yaw) Ry(pitch) Rx(roll): ω = Rxᵀ Ryᵀ (0,0,yaw') + Rxᵀ (0,pitch',0) + (roll',0,0).
    const Eigen::Vector3d omega = Rx.transpose() * Ry.transpose() * Eigen::Vector3d(0, 0, rate[2]) +
                                  Rx.transpose() * Eigen::Vector3d(0, rate[1], 0) + Eigen::Vector3d(rate[0], 0, 0);
    const double quaternion[4] = {q.x(), q.y(), q.z(), q.w()};
    trajectory.Append(options.start_stamp_ns + offset_ns, p.data(), quaternion, v.data(), omega.data());
  }
  return trajectory;
}

traj::Trajectory AddPositionNoise(const traj::TrajectoryView& truth, double sigma_m, uint64_t seed) {
  if (!(sigma_m >= 0) || !std::isfinite(sigma_m)) {
    throw UsageError(fmt::format("--noise must be a non-negative number of metres, got {}", sigma_m));
  }
  traj::Channels channels = truth.channels();
  channels.velocity = false;
  channels.angular_velocity = false;
  traj::Trajectory measured(channels);
  measured.Reserve(truth.size());
  std::mt19937_64 rng(seed ^ 0x9e3779b97f4a7c15ULL);
  std::normal_distribution<double> noise(0.0, sigma_m);
  const auto p = truth.positions();
  const int stride = traj::OrientationStride(channels.orientation);
  std::vector<double> orientation(stride);
  for (Eigen::Index i = 0; i < truth.size(); ++i) {
    Eigen::Vector3d noisy = p.col(i);
    if (sigma_m > 0) noisy += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    if (channels.orientation == traj::OrientationKind::kQuaternion) {
      const Eigen::Vector4d q = truth.quaternions().col(i);
      std::copy(q.data(), q.data() + 4, orientation.begin());
    } else if (channels.orientation == traj::OrientationKind::kMatrix) {
      const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> R = truth.Rotation(i);
      std::copy(R.data(), R.data() + 9, orientation.begin());
    }
    measured.Append(truth.stamps_ns()[i], noisy.data(), orientation.data());
  }
  return measured;
}

}  // namespace cheval::sim
