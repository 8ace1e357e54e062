#include "cheval/sim/quadrotor.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "cheval/common/error.h"
#include "cheval/common/options.h"
#include "cheval/common/random.h"
#include "cheval/lie/so3.h"

namespace cheval::sim {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kWarmUpS = 3.0;  // flown before t = 0, not recorded

// One axis of a reference: c + rate·t + Σ A sin(ω t + φ).
struct Wave {
  double amplitude, frequency, phase;
};
struct Axis {
  double center = 0, rate = 0;
  std::vector<Wave> waves;
  // Value and derivatives 0..2.
  std::array<double, 3> At(double t) const {
    std::array<double, 3> out{center + rate * t, rate, 0.0};
    for (const Wave& w : waves) {
      const double s = std::sin(w.frequency * t + w.phase), c = std::cos(w.frequency * t + w.phase);
      out[0] += w.amplitude * s;
      out[1] += w.amplitude * w.frequency * c;
      out[2] -= w.amplitude * w.frequency * w.frequency * s;
    }
    return out;
  }
};
struct Reference {
  Axis x, y, z, yaw;
};

Reference MakeReference(QuadrotorScenario scenario) {
  Reference r;
  r.z.center = 1.5;
  switch (scenario) {
    case QuadrotorScenario::kHover:
      break;
    case QuadrotorScenario::kLine:  // -2 m .. +2 m along x and back, every 8 s
      r.x.waves = {{2.0, 2 * kPi / 8, -kPi / 2}};
      break;
    case QuadrotorScenario::kCircle:  // radius 2 m in 6 s, facing along the path
      r.x.waves = {{2.0, 2 * kPi / 6, kPi / 2}};
      r.y.waves = {{2.0, 2 * kPi / 6, 0.0}};
      r.yaw.center = kPi / 2;
      r.yaw.rate = 2 * kPi / 6;
      break;
    case QuadrotorScenario::kFigureEight:
      r.x.waves = {{2.5, 2 * kPi / 8, 0.0}};
      r.y.waves = {{1.5, 4 * kPi / 8, 0.0}};
      break;
    case QuadrotorScenario::kLissajous:
      r.x.waves = {{3.0, 2 * kPi / 7, 0.0}};
      r.y.waves = {{2.0, 2 * kPi / 5, 0.5}};
      r.z.waves = {{0.5, 2 * kPi / 4, 0.0}};
      r.yaw.waves = {{0.5, 0.7, 0.0}};
      break;
    case QuadrotorScenario::kAggressive:  // up to ~12 m/s² and 1.3 rad/s of yaw
      r.x.waves = {{3.0, 1.6, 0.0}};
      r.y.waves = {{2.0, 2.4, 0.0}};
      r.z.center = 2.0;
      r.z.waves = {{0.6, 2.0, 0.0}};
      r.yaw.waves = {{1.0, 1.3, 0.0}};
      break;
  }
  return r;
}

// The simulator's streams of the project's generator (common/random.h). Their engines are seeded
// from (seed, stream) by this file's own mix and Normal() takes midpoint uniforms, as the data
// folders of earlier versions were made, so a seed still gives the same flight.
Random SimulatorRandom(uint64_t seed, uint64_t stream) {
  return Random::FromEngineSeed(seed * 0x9E3779B97F4A7C15ULL + stream * 0xD1B54A32D192ED03ULL + 1,
                                Random::BoxMullerInput::kMidpoint);
}

// (k + ½)·2⁻⁵³ from the top 53 bits k of the next output: uniform in (0, 1).
double MidpointUniform(Random& random) { return (static_cast<double>(random() >> 11) + 0.5) * 0x1.0p-53; }

// Three normals drawn in the order x, y, z.
Eigen::Vector3d Normal3(Random& random) {
  const double a = random.Normal(), b = random.Normal(), c = random.Normal();
  return {a, b, c};
}

// Simulation state: p, q (x y z w), v, ω, Ω.
struct State {
  Eigen::Vector3d p, v, w;
  Eigen::Quaterniond q;
  Eigen::Vector4d rotor;
};
struct Derivative {
  Eigen::Vector3d p, v, w;
  Eigen::Vector4d q, rotor;
};

class Simulator {
 public:
  Simulator(const estim::QuadrotorParameters& params, Reference reference)
      : model_{params}, reference_(std::move(reference)) {
    const double a = params.arm_m, k = params.moment_coefficient / params.thrust_coefficient;
    Eigen::Matrix4d mix;  // [T, τx, τy, τz] = mix · f
    mix << 1, 1, 1, 1,  //
        a, a, -a, -a,   //
        -a, a, a, -a,   //
        -k, k, -k, k;
    unmix_ = mix.inverse();
    const double wn = 15.0, zeta = 0.8;  // attitude loop; the motors (τ = 0.02 s) are ~3x faster
    k_R_ = params.inertia_kgm2 * wn * wn;
    k_w_ = params.inertia_kgm2 * 2 * zeta * wn;
  }

  // The force the controller asks for (world), and the desired rotation.
  void Desired(const State& s, double t, Eigen::Vector3d* force, Eigen::Matrix3d* R_d) const {
    const estim::QuadrotorParameters& m = model_.parameters;
    const auto x = reference_.x.At(t), y = reference_.y.At(t), z = reference_.z.At(t), yaw = reference_.yaw.At(t);
    const Eigen::Vector3d p_r(x[0], y[0], z[0]), v_r(x[1], y[1], z[1]), a_r(x[2], y[2], z[2]);
    const double kp = 4.0, kd = 3.6;  // position loop: ω_n = 2 rad/s, ζ = 0.9
    *force = m.mass_kg * (a_r + Eigen::Vector3d(0, 0, m.gravity_mps2) - kp * (s.p - p_r) - kd * (s.v - v_r)) +
             m.drag_coefficient * s.v.norm() * s.v;
    const Eigen::Vector3d b3 = force->normalized();
    const Eigen::Vector3d b1c(std::cos(yaw[0]), std::sin(yaw[0]), 0.0);
    const Eigen::Vector3d b2 = b3.cross(b1c).normalized();
    R_d->col(0) = b2.cross(b3);
    R_d->col(1) = b2;
    R_d->col(2) = b3;
  }

  // Rotor speed command (rad/s) of a state; counts saturation.
  Eigen::Vector4d Command(const State& s, double t, bool* saturated) const {
    const estim::QuadrotorParameters& m = model_.parameters;
    Eigen::Vector3d force;
    Eigen::Matrix3d R_d;
    Desired(s, t, &force, &R_d);
    const Eigen::Matrix3d R = s.q.toRotationMatrix();
    const double thrust = force.dot(R.col(2));
    const Eigen::Matrix3d E = R_d.transpose() * R - R.transpose() * R_d;
    const Eigen::Vector3d e_R = 0.5 * Eigen::Vector3d(E(2, 1), E(0, 2), E(1, 0));
    const Eigen::Vector3d Jw = m.inertia_kgm2.cwiseProduct(s.w);
    const Eigen::Vector3d tau = -k_R_.cwiseProduct(e_R) - k_w_.cwiseProduct(s.w) + s.w.cross(Jw);
    Eigen::Vector4d wrench(thrust, tau.x(), tau.y(), tau.z());
    const Eigen::Vector4d f = unmix_ * wrench;
    Eigen::Vector4d command;
    for (int i = 0; i < 4; ++i) {
      double speed = std::sqrt(std::max(f[i], 0.0) / m.thrust_coefficient);
      if (f[i] < 0 || speed > m.max_rotor_speed_radps) *saturated = true;
      command[i] = std::min(speed, m.max_rotor_speed_radps);
    }
    return command;
  }

  Derivative Rate(const State& s, double t, bool* saturated) const {
    Derivative d;
    double x[9], x_dot[9], omega[3];
    for (int i = 0; i < 3; ++i) {
      x[i] = s.p[i];
      x[3 + i] = s.v[i];
      x[6 + i] = s.w[i];
    }
    model_.Dynamics(x, Eigen::Matrix3d(s.q.toRotationMatrix()), s.rotor.data(), x_dot, omega);
    d.p = Eigen::Vector3d(x_dot[0], x_dot[1], x_dot[2]);
    d.v = Eigen::Vector3d(x_dot[3], x_dot[4], x_dot[5]);
    d.w = Eigen::Vector3d(x_dot[6], x_dot[7], x_dot[8]);
    const Eigen::Quaterniond qdot = s.q * Eigen::Quaterniond(0, 0.5 * omega[0], 0.5 * omega[1], 0.5 * omega[2]);
    d.q = qdot.coeffs();
    d.rotor = (Command(s, t, saturated) - s.rotor) / model_.parameters.motor_time_constant_s;
    return d;
  }

  static State Add(const State& s, const Derivative& d, double h) {
    State out = s;
    out.p += h * d.p;
    out.v += h * d.v;
    out.w += h * d.w;
    out.q.coeffs() += h * d.q;
    out.rotor += h * d.rotor;
    return out;
  }

  // One classical RK4 step of length h; the quaternion is re-normalised after the step.
  State Step(const State& s, double t, double h, bool* saturated) const {
    const Derivative k1 = Rate(s, t, saturated);
    const Derivative k2 = Rate(Add(s, k1, h / 2), t + h / 2, saturated);
    const Derivative k3 = Rate(Add(s, k2, h / 2), t + h / 2, saturated);
    const Derivative k4 = Rate(Add(s, k3, h), t + h, saturated);
    Derivative sum;
    sum.p = k1.p + 2 * k2.p + 2 * k3.p + k4.p;
    sum.v = k1.v + 2 * k2.v + 2 * k3.v + k4.v;
    sum.w = k1.w + 2 * k2.w + 2 * k3.w + k4.w;
    sum.q = k1.q + 2 * k2.q + 2 * k3.q + k4.q;
    sum.rotor = k1.rotor + 2 * k2.rotor + 2 * k3.rotor + k4.rotor;
    State out = Add(s, sum, h / 6);
    out.q.normalize();
    return out;
  }

  // The reference state at t = 0 with the attitude and rotor speeds that fly it.
  State Initial(double t0) const {
    State s;
    const auto x = reference_.x.At(t0), y = reference_.y.At(t0), z = reference_.z.At(t0);
    s.p = Eigen::Vector3d(x[0], y[0], z[0]);
    s.v = Eigen::Vector3d(x[1], y[1], z[1]);
    s.w.setZero();
    Eigen::Vector3d force;
    Eigen::Matrix3d R_d;
    s.q = Eigen::Quaterniond::Identity();
    s.rotor.setZero();
    Desired(s, t0, &force, &R_d);
    s.q = Eigen::Quaterniond(R_d);
    bool ignored = false;
    s.rotor = Command(s, t0, &ignored);
    return s;
  }

 private:
  estim::QuadrotorModel model_;
  Reference reference_;
  Eigen::Matrix4d unmix_;
  Eigen::Vector3d k_R_, k_w_;
};

estim::QuadrotorTruth ToTruth(const State& s, double t) { return {t, s.p, s.q, s.v, s.w, s.rotor}; }

// Landmarks on the faces of the room [-10, 10]² x [0, 6], uniform in area.
std::vector<Eigen::Vector3d> MakeLandmarks(int count, Random& random) {
  std::vector<Eigen::Vector3d> points;
  const double wall = 20.0 * 6.0, floor = 20.0 * 20.0, total = 4 * wall + 2 * floor;
  for (int i = 0; i < count; ++i) {
    double pick = MidpointUniform(random) * total;
    const double a = MidpointUniform(random) * 20.0 - 10.0, b = MidpointUniform(random);
    if (pick < 4 * wall) {
      const int face = std::min(3, static_cast<int>(pick / wall));
      const double h = b * 6.0;
      const Eigen::Vector3d options[4] = {{10, a, h}, {-10, a, h}, {a, 10, h}, {a, -10, h}};
      points.push_back(options[face]);
    } else {
      pick -= 4 * wall;
      points.emplace_back(a, b * 20.0 - 10.0, pick < floor ? 0.0 : 6.0);
    }
  }
  return points;
}

}  // namespace

std::string_view ToString(QuadrotorScenario scenario) {
  switch (scenario) {
    case QuadrotorScenario::kHover: return "hover";
    case QuadrotorScenario::kLine: return "line";
    case QuadrotorScenario::kCircle: return "circle";
    case QuadrotorScenario::kFigureEight: return "figure8";
    case QuadrotorScenario::kLissajous: return "lissajous";
    case QuadrotorScenario::kAggressive: return "aggressive";
  }
  return "?";
}

std::optional<QuadrotorScenario> QuadrotorScenarioFromString(std::string_view name) {
  for (QuadrotorScenario s : AllQuadrotorScenarios()) {
    if (ToString(s) == name) return s;
  }
  return std::nullopt;
}

std::vector<QuadrotorScenario> AllQuadrotorScenarios() {
  return {QuadrotorScenario::kHover,       QuadrotorScenario::kLine,      QuadrotorScenario::kCircle,
          QuadrotorScenario::kFigureEight, QuadrotorScenario::kLissajous, QuadrotorScenario::kAggressive};
}

std::optional<Eigen::Vector2d> Project(const estim::PinholeCamera& camera, const Eigen::Vector3d& p,
                                       const Eigen::Matrix3d& R, const Eigen::Vector3d& x) {
  const Eigen::Vector3d c = estim::PinholeCamera::BodyFromCamera().transpose() * (R.transpose() * (x - p));
  if (c.z() < 0.1) return std::nullopt;
  const Eigen::Vector2d uv(camera.fx * c.x() / c.z() + camera.cx, camera.fy * c.y() / c.z() + camera.cy);
  if (uv.x() < 0 || uv.y() < 0 || uv.x() > camera.width || uv.y() > camera.height) return std::nullopt;
  return uv;
}

void QuadrotorSimOptions::Validate() const {
  const OptionCheck check("QuadrotorSimOptions");
  check(std::isfinite(duration_s) && duration_s > 0 && duration_s <= 3600, "duration_s", "must be in (0, 3600] s, got {}",
        duration_s);
  check(integration_rate_hz >= 100 && integration_rate_hz <= 1e5, "integration_rate_hz",
        "must be in [100, 1e5] Hz, got {}", integration_rate_hz);
  check(truth_rate_hz > 0 && truth_rate_hz <= integration_rate_hz, "truth_rate_hz",
        "must be in (0, integration_rate_hz = {}] Hz, got {}", integration_rate_hz, truth_rate_hz);
  check(landmarks > 0, "landmarks", "must be > 0, got {}", landmarks);
  check(max_features_per_frame > 0, "max_features_per_frame", "must be > 0, got {}", max_features_per_frame);
  const auto non_negative = [&](double value, std::string_view field) {
    check(std::isfinite(value) && value >= 0, field, "must be a finite number >= 0, got {}", value);
  };
  non_negative(vo_position_noise_m, "vo_position_noise_m");
  non_negative(vo_rotation_noise_rad, "vo_rotation_noise_rad");
  non_negative(vo_position_drift_m_per_sqrt_s, "vo_position_drift_m_per_sqrt_s");
  non_negative(vo_rotation_drift_rad_per_sqrt_s, "vo_rotation_drift_rad_per_sqrt_s");
  const double truth_bytes = (std::floor(duration_s * truth_rate_hz) + 1) * kTruthSampleBytes;
  check(truth_bytes <= kMaxQuadrotorSimBytes, "truth_rate_hz",
        "must keep the truth within {:.0f} GB; {} Hz over {} s is {:.4g} samples, about {:.3g} GB",
        kMaxQuadrotorSimBytes / 1e9, truth_rate_hz, duration_s, std::floor(duration_s * truth_rate_hz) + 1,
        truth_bytes / 1e9);
  const double landmark_bytes = static_cast<double>(landmarks) * kLandmarkBytes;
  check(landmark_bytes <= kMaxQuadrotorSimBytes, "landmarks",
        "must keep the landmarks within {:.0f} GB; {} is about {:.3g} GB", kMaxQuadrotorSimBytes / 1e9, landmarks,
        landmark_bytes / 1e9);
}

double QuadrotorSimBytes(const estim::Vehicle& vehicle, const QuadrotorSimOptions& options) {
  const double frames = std::floor(options.duration_s * vehicle.camera.rate_hz) + 1;
  const double features = std::min(options.max_features_per_frame, options.landmarks);
  return (std::floor(options.duration_s * options.truth_rate_hz) + 1) * kTruthSampleBytes +
         static_cast<double>(options.landmarks) * kLandmarkBytes + frames * (kFrameBytes + features * kPixelBytes);
}

estim::QuadrotorData SimulateQuadrotor(const estim::Vehicle& vehicle, const QuadrotorSimOptions& options) {
  options.Validate();
  estim::ValidateVehicle(vehicle, "<vehicle>");
  if (const double bytes = QuadrotorSimBytes(vehicle, options); !(bytes <= kMaxQuadrotorSimBytes)) {
    throw ComputeError(fmt::format(
        "the simulation would need about {:.3g} GB, above the limit of {:.0f} GB: {} s at the vehicle's camera.rate_hz "
        "{} Hz is {:.4g} frames of up to {} features each; shorten the duration or lower camera.rate_hz",
        bytes / 1e9, kMaxQuadrotorSimBytes / 1e9, options.duration_s, vehicle.camera.rate_hz,
        std::floor(options.duration_s * vehicle.camera.rate_hz) + 1,
        std::min(options.max_features_per_frame, options.landmarks)));
  }
  estim::QuadrotorData data;
  data.vehicle = vehicle;
  Random landmark_random = SimulatorRandom(options.seed, 1), pixel_random = SimulatorRandom(options.seed, 2),
         vo_random = SimulatorRandom(options.seed, 3), pick_random = SimulatorRandom(options.seed, 4);
  data.landmarks = MakeLandmarks(options.landmarks, landmark_random);

  const Simulator sim(vehicle.quadrotor, MakeReference(options.scenario));
  const estim::PinholeCamera& camera = vehicle.camera;
  const double h = 1.0 / options.integration_rate_hz;
  const int64_t steps = std::llround(options.duration_s * options.integration_rate_hz);
  const int64_t truth_every = std::max<int64_t>(1, std::llround(options.integration_rate_hz / options.truth_rate_hz));
  const double frame_dt = 1.0 / camera.rate_hz;
  int64_t next_frame = 0;
  Eigen::Vector3d drift_p = Eigen::Vector3d::Zero(), drift_r = Eigen::Vector3d::Zero();
  // Warm-up: the vehicle starts on the reference at t = -kWarmUpS and flies until t = 0 before
  // anything is recorded, so the controller's start-up transient is not part of the data.
  State s = sim.Initial(-kWarmUpS);
  for (int64_t i = std::llround(-kWarmUpS * options.integration_rate_hz); i < 0; ++i) {
    bool saturated = false;
    s = sim.Step(s, static_cast<double>(i) * h, h, &saturated);
  }
  auto frame = [&](const State& at, double t) {
    const Eigen::Matrix3d R = at.q.toRotationMatrix();
    std::vector<int> visible;
    std::vector<Eigen::Vector2d> uvs;
    for (int i = 0; i < static_cast<int>(data.landmarks.size()); ++i) {
      if (auto uv = Project(camera, at.p, R, data.landmarks[i])) {
        visible.push_back(i);
        uvs.push_back(*uv);
      }
    }
    // A front end tracks a random subset of at most max_features_per_frame (partial Fisher–Yates).
    const int keep = std::min<int>(options.max_features_per_frame, static_cast<int>(visible.size()));
    for (int i = 0; i < keep; ++i) {
      const int j = i + static_cast<int>(pick_random() % static_cast<uint64_t>(visible.size() - i));
      std::swap(visible[i], visible[j]);
      std::swap(uvs[i], uvs[j]);
    }
    std::vector<estim::PixelObservation> seen;
    for (int i = 0; i < keep; ++i) {
      // y before x: the order GCC evaluated the two arguments of the earlier two-argument form in.
      const double noise_y = pixel_random.Normal(), noise_x = pixel_random.Normal();
      const Eigen::Vector2d noise(noise_x, noise_y);
      seen.push_back({t, visible[i], uvs[i] + camera.pixel_noise_px * noise});
    }
    std::sort(seen.begin(), seen.end(), [](const auto& a, const auto& b) { return a.landmark < b.landmark; });
    data.pixels.insert(data.pixels.end(), seen.begin(), seen.end());
    if (next_frame > 0) {
      drift_p += options.vo_position_drift_m_per_sqrt_s * std::sqrt(frame_dt) * Normal3(vo_random);
      drift_r += options.vo_rotation_drift_rad_per_sqrt_s * std::sqrt(frame_dt) * Normal3(vo_random);
    }
    const Eigen::Vector3d np = options.vo_position_noise_m * Normal3(vo_random);
    const Eigen::Vector3d nr = options.vo_rotation_noise_rad * Normal3(vo_random);
    const Eigen::Quaterniond q_vo = lie::SO3d(at.q).Plus(drift_r + nr).quaternion();
    data.initial.push_back({t, at.p + drift_p + np, q_vo});
  };
  for (int64_t i = 0; i <= steps; ++i) {
    const double t = static_cast<double>(i) * h;
    if (i % truth_every == 0) data.truth.push_back(ToTruth(s, t));
    // Frames in [t, t + h): a partial RK4 step from this grid point.
    while (static_cast<double>(next_frame) * frame_dt < t + h - 1e-12 &&
           static_cast<double>(next_frame) * frame_dt <= options.duration_s + 1e-12) {
      const double tf = static_cast<double>(next_frame) * frame_dt;
      bool ignored = false;
      frame(tf - t > 1e-12 ? sim.Step(s, t, tf - t, &ignored) : s, tf);
      ++next_frame;
    }
    if (i == steps) break;
    bool saturated = false;
    s = sim.Step(s, t, h, &saturated);
    if (saturated) ++data.saturated_steps;
  }
  if (data.saturated_steps > steps / 100) {
    throw ComputeError(fmt::format("the vehicle cannot fly scenario '{}': rotor commands saturated in {} of {} steps",
                                   ToString(options.scenario), data.saturated_steps, steps));
  }
  return data;
}

}  // namespace cheval::sim
