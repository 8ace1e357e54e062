// The flatness baseline and the scoring of rotor speeds (rotor_estimator.h), and the local fits
// they and the estimator's initial values share (rotor_internal.h).
#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

#include "cheval/common/error.h"
#include "cheval/estim/rotor_estimator.h"
#include "rotor_internal.h"

namespace cheval::estim {
namespace rotor_internal {
namespace {

// Indices [lo, hi) of the samples within [t − half, t + half], the window shifted inside the flight.
std::pair<size_t, size_t> Window(const RotorFlight& flight, double t, double window_s) {
  const std::vector<RotorSample>& s = flight.samples;
  const double half = 0.5 * window_s, first = s.front().t, last = s.back().t;
  const double center = last - first <= window_s ? 0.5 * (first + last) : std::clamp(t, first + half, last - half);
  const auto by_time = [](const RotorSample& a, double v) { return a.t < v; };
  const size_t lo = std::lower_bound(s.begin(), s.end(), center - half - 1e-9, by_time) - s.begin();
  const size_t hi = std::lower_bound(s.begin(), s.end(), center + half + 1e-9, by_time) - s.begin();
  return {lo, hi};
}

}  // namespace

KinematicFit FitPosition(const RotorFlight& flight, double t, double window_s) {
  auto [lo, hi] = Window(flight, t, window_s);
  const std::vector<RotorSample>& s = flight.samples;
  std::vector<size_t> used;
  while (true) {
    used.clear();
    for (size_t i = lo; i < hi; ++i) {
      if (s[i].fresh_position) used.push_back(i);
    }
    if (used.size() >= 3 || (lo == 0 && hi == s.size())) break;
    if (lo > 0) --lo;
    if (hi < s.size()) ++hi;
  }
  if (used.size() < 3) throw ComputeError("fewer than 3 distinct motion-capture positions in the flight");
  Eigen::MatrixXd A(used.size(), 3), P(used.size(), 3);
  for (size_t r = 0; r < used.size(); ++r) {
    const double tau = s[used[r]].t - t;
    A.row(r) << 1.0, tau, tau * tau;
    P.row(r) = s[used[r]].p.transpose();
  }
  const Eigen::MatrixXd c = A.colPivHouseholderQr().solve(P);
  return {c.row(0).transpose(), c.row(1).transpose(), 2.0 * c.row(2).transpose()};
}

void FitRate(const RotorFlight& flight, double t, double window_s, Eigen::Vector3d* w, Eigen::Vector3d* w_dot) {
  auto [lo, hi] = Window(flight, t, window_s);
  const std::vector<RotorSample>& s = flight.samples;
  while (hi - lo < 2) {
    if (lo > 0) --lo;
    if (hi < s.size()) ++hi;
  }
  Eigen::MatrixXd A(hi - lo, 2), W(hi - lo, 3);
  for (size_t i = lo; i < hi; ++i) {
    A.row(i - lo) << 1.0, s[i].t - t;
    W.row(i - lo) = s[i].w.transpose();
  }
  const Eigen::MatrixXd c = A.colPivHouseholderQr().solve(W);
  *w = c.row(0).transpose();
  *w_dot = c.row(1).transpose();
}

RotorSample SampleAt(const RotorFlight& flight, double t) {
  const std::vector<RotorSample>& s = flight.samples;
  auto it = std::lower_bound(s.begin(), s.end(), t, [](const RotorSample& a, double v) { return a.t < v; });
  if (it == s.begin()) return s.front();
  if (it == s.end()) return s.back();
  const RotorSample& b = *it;
  const RotorSample& a = *(it - 1);
  const double f = (t - a.t) / (b.t - a.t);
  RotorSample out = a;
  out.t = t;
  out.p = a.p + f * (b.p - a.p);
  out.q = a.q.slerp(f, b.q);
  out.w = a.w + f * (b.w - a.w);
  out.accel = a.accel + f * (b.accel - a.accel);
  out.rotor = a.rotor + f * (b.rotor - a.rotor);
  return out;
}

Eigen::Vector4d InvertMixer(const RotorNominal& n, const RotorThetaVector& theta, double body_accel_z,
                            const Eigen::Vector3d& body_v, const Eigen::Vector3d& w, const Eigen::Vector3d& w_dot) {
  const double l = n.arm_m;
  Eigen::Vector4d k;
  for (int i = 0; i < 4; ++i) k[i] = n.thrust_coefficient * theta[kThetaThrust0 + i];
  const double km = n.moment_coefficient * theta[kThetaMoment];
  Eigen::Matrix4d A;  // [T, τx, τy, τz] = A Ω²  (rotor_model.h)
  A.row(0) = k.transpose();
  A.row(1) << -l * k[0], -l * k[1], l * k[2], l * k[3];
  A.row(2) << -l * k[0], l * k[1], l * k[2], -l * k[3];
  A.row(3) << km, -km, km, -km;
  const Eigen::Vector3d J = n.inertia_kgm2.cwiseProduct(theta.segment<3>(kThetaInertiaX));
  const Eigen::Vector3d tau0 =
      J.cwiseProduct(w_dot) + w.cross(J.cwiseProduct(w)) - kRotorTorqueUnit * theta.segment<3>(kThetaTorqueX);
  const Eigen::FullPivLU<Eigen::Matrix4d> lu(A);
  Eigen::Vector4d omega = Eigen::Vector4d::Zero();
  for (int pass = 0; pass < 3; ++pass) {
    const double flap = omega.sum() * kRotorFlapUnit;
    const Eigen::Vector3d tau =
        tau0 - flap * Eigen::Vector3d(theta[kThetaFlapX] * body_v.y(), -theta[kThetaFlapX + 1] * body_v.x(), 0);
    const double drag_z = omega.sum() * kRotorDragUnit * theta[kThetaDragZ] * body_v.z();
    const double thrust = n.mass_kg * (body_accel_z + drag_z);
    const Eigen::Vector4d squared = lu.solve(Eigen::Vector4d(thrust, tau.x(), tau.y(), tau.z()));
    for (int i = 0; i < 4; ++i) omega[i] = std::sqrt(std::max(squared[i], 0.0));
  }
  return omega;
}

}  // namespace rotor_internal

std::vector<Eigen::Vector4d> FlatnessRotorSpeeds(const RotorFlight& flight, const RotorNominal& nominal,
                                                 const RotorThetaVector& theta, double window_s) {
  std::vector<Eigen::Vector4d> out;
  out.reserve(flight.samples.size());
  const Eigen::Vector3d g(0, 0, -nominal.gravity_mps2);
  for (const RotorSample& s : flight.samples) {
    const rotor_internal::KinematicFit fit = rotor_internal::FitPosition(flight, s.t, window_s);
    Eigen::Vector3d w, w_dot;
    rotor_internal::FitRate(flight, s.t, window_s, &w, &w_dot);
    const Eigen::Matrix3d R = s.q.toRotationMatrix();
    const double body_accel_z = (R.transpose() * (fit.a - g)).z();
    out.push_back(rotor_internal::InvertMixer(nominal, theta, body_accel_z, R.transpose() * fit.v, s.w, w_dot));
  }
  return out;
}

RotorError ScoreRotors(const RotorFlight& flight, const std::vector<Eigen::Vector4d>& estimate,
                       const std::vector<size_t>& indices) {
  if (estimate.size() != flight.samples.size()) throw UsageError("one estimate per sample of the flight is needed");
  RotorError e;
  if (indices.empty()) throw ComputeError("no samples to score (no flying span longer than the margins)");
  for (size_t i : indices) {
    const Eigen::Vector4d d = (estimate[i] - flight.samples[i].rotor).cwiseAbs();
    e.rpm += d * kRpmPerRadps;
    e.percent += 100.0 * d.cwiseQuotient(flight.samples[i].rotor.cwiseMax(1e-9));
  }
  e.rpm /= static_cast<double>(indices.size());
  e.percent /= static_cast<double>(indices.size());
  return e;
}

}  // namespace cheval::estim
