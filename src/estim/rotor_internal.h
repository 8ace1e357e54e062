#pragma once
// Helpers shared by the rotor estimator's files (rotor_estimator.h): local polynomial fits of a
// flight's samples and the flight's state at any time.

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "cheval/estim/crazyflie_data.h"
#include "cheval/estim/rotor_model.h"

namespace cheval::estim::rotor_internal {

/// Position, velocity and acceleration at t from a least-squares quadratic fit of the fresh
/// motion-capture positions within [t − window/2, t + window/2] (shifted inside the flight near its
/// ends; widened to at least 3 positions).
struct KinematicFit {
  Eigen::Vector3d p, v, a;
};
KinematicFit FitPosition(const RotorFlight& flight, double t, double window_s);

/// Body rate and its derivative at t from a least-squares line through the body rates within the window.
void FitRate(const RotorFlight& flight, double t, double window_s, Eigen::Vector3d* w, Eigen::Vector3d* w_dot);

/// The measured sample at t: linear interpolation (slerp for the attitude) between neighbours.
RotorSample SampleAt(const RotorFlight& flight, double t);

/// Rotor speeds that give the specific force `body_accel_z` (m/s², along body z) and the angular
/// acceleration w_dot at body velocity `body_v` and rate w, with θ: the mixer inverted for Ω²
/// (negative → 0); the rotor-drag and rotor-moment terms use the previous iterate's Σ Ω (three fixed-point passes).
Eigen::Vector4d InvertMixer(const RotorNominal& nominal, const RotorThetaVector& theta, double body_accel_z,
                            const Eigen::Vector3d& body_v, const Eigen::Vector3d& w, const Eigen::Vector3d& w_dot);

}  // namespace cheval::estim::rotor_internal
