#pragma once
// Synthetic motion for the velocity fit's tests: sums of sinusoids per axis, sampled evenly, with
// their exact velocity (tests/cheb/under_resolved_test.cc, local_regression_test.cc,
// robust_curve_test.cc, gap_bridges_test.cc, degree_test.cc).

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <Eigen/Core>

namespace cheval::cheb::testing_motion {

struct Tones {
  std::vector<int64_t> stamps;
  Eigen::MatrixXd positions, velocities;  // m x 3
};

struct Tone {
  int axis;
  double hz, amplitude, phase;  // position amplitude (m)
};

// The stamps (s) of a short recording cut up by dropouts: `segments` segments of 5, 6, 7, 5, ...
// samples at 50 Hz, 0.1 s of dropout after each. `breaks`, when given, gets each segment's last
// sample but the recording's (the boundaries no difference is taken across).
inline std::vector<double> SegmentedStamps(int segments, std::vector<Eigen::Index>* breaks = nullptr) {
  std::vector<double> times;
  double at = 0.0;
  for (int segment = 0; segment < segments; ++segment, at += 0.1) {
    for (int i = 0; i < 5 + segment % 3; ++i, at += 0.02) times.push_back(at);
    if (breaks != nullptr && segment + 1 < segments) breaks->push_back(static_cast<Eigen::Index>(times.size()) - 1);
  }
  return times;
}

// Per axis six tones of log-uniform frequency from 0.05 Hz up to f_max (one at it), ~0.3 m/s in
// all: bench/velocity_sweep.py's "tones" motion, drawn from `rng`.
inline std::vector<Tone> SweepTones(double f_max, std::mt19937_64* rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Tone> tones;
  for (int c = 0; c < 3; ++c) {
    for (int k = 0; k < 6; ++k) {
      const double hz = k == 0 ? f_max : std::exp(std::log(0.05) + (std::log(f_max) - std::log(0.05)) * unit(*rng));
      const double rate = 0.3 / std::sqrt(6.0) * (0.5 + unit(*rng));
      tones.push_back({c, hz, rate / (2.0 * M_PI * hz), 2.0 * M_PI * unit(*rng)});
    }
  }
  return tones;
}

// The tones' position and velocity at time t (s).
inline void EvaluateTones(const std::vector<Tone>& tones, double t, Eigen::Vector3d* p, Eigen::Vector3d* v) {
  p->setZero();
  v->setZero();
  for (const Tone& tone : tones) {
    const double w = 2.0 * M_PI * tone.hz;
    (*p)[tone.axis] += tone.amplitude * std::sin(w * t + tone.phase);
    (*v)[tone.axis] += tone.amplitude * w * std::cos(w * t + tone.phase);
  }
}

// The tones sampled at `rate_hz` for 20 s, each sample's coordinates then drawn with noise σ.
inline Tones Synthesize(double rate_hz, const std::vector<Tone>& tones, double noise, std::mt19937_64* rng) {
  std::normal_distribution<double> gauss(0.0, 1.0);
  const auto m = static_cast<Eigen::Index>(20.0 * rate_hz) + 1;
  Tones s;
  s.positions.resize(m, 3);
  s.velocities.resize(m, 3);
  for (Eigen::Index i = 0; i < m; ++i) {
    s.stamps.push_back(std::llround(static_cast<double>(i) / rate_hz * 1e9));
    Eigen::Vector3d p, v;
    EvaluateTones(tones, static_cast<double>(i) / rate_hz, &p, &v);
    s.positions.row(i) = p.transpose();
    s.velocities.row(i) = v.transpose();
    if (noise > 0.0) {
      for (int c = 0; c < 3; ++c) s.positions(i, c) += noise * gauss(*rng);
    }
  }
  return s;
}

// Per axis, 160 tones spread up to 1.5 f_max whose velocity spectrum is flat to f_max and then
// falls as f⁻⁴ (bench/velocity_sweep.py's "broad" motion), 0.3 m/s in all, sampled at `rate_hz`
// for 20 s with noise σ (none by default).
inline Tones Broad(double rate_hz, double f_max, uint64_t seed, double noise = 0.0) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> gauss(1.0, 0.3);
  constexpr int kTones = 160;
  std::vector<Tone> tones;
  for (int j = 0; j < 3 * kTones; ++j) {
    const int k = j % kTones;
    const double hz = (0.02 + (1.5 * f_max - 0.02) * k / (kTones - 1)) * (0.97 + 0.06 * unit(rng));
    const double shape = 1.0 / std::sqrt(1.0 + std::pow(hz / f_max, 8));
    const double amplitude = 0.3 * std::sqrt(2.0 / kTones) * shape * std::abs(gauss(rng)) / (2.0 * M_PI * hz);
    tones.push_back({j / kTones, hz, amplitude, 2.0 * M_PI * unit(rng)});
  }
  return Synthesize(rate_hz, tones, noise, &rng);
}

}  // namespace cheval::cheb::testing_motion
