// The rotor model, estimator and identification (rotor_model.h, rotor_estimator.h) on simulated
// flights with known parameters: the model against QuadrotorModel, the estimate's accuracy, the
// identification's recovery of perturbed parameters, the vehicle file round trip.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "../support/residual_only.h"
#include "../support/test_data.h"

#include "cheval/cheb/chebyshev.h"
#include "cheval/common/error.h"
#include "cheval/estim/internal/parametric_collocation_cost.h"
#include "cheval/estim/problem.h"
#include "cheval/estim/models.h"
#include "cheval/estim/rotor_estimator.h"
#include "cheval/estim/vehicle.h"
#include "cheval/sim/quadrotor.h"

namespace cheval {
namespace {

namespace fs = std::filesystem;
const std::string kVehicle = std::string(CHEVAL_SOURCE_DIR) + "/data/vehicles/flightgoggles.json";

// The FlightGoggles vehicle without its quadratic drag (not in the rotor model).
estim::Vehicle SimVehicle() {
  estim::Vehicle v = estim::ReadVehicle(kVehicle);
  v.quadrotor.drag_coefficient = 0;
  return v;
}

// Its published constants for the rotor model (θ = published is then the exact vehicle).
estim::RotorVehicle SimRotorVehicle() {
  const estim::QuadrotorParameters q = SimVehicle().quadrotor;
  estim::RotorVehicle v;
  v.nominal.mass_kg = q.mass_kg;
  v.nominal.arm_m = q.arm_m;
  v.nominal.thrust_coefficient = q.thrust_coefficient;
  v.nominal.moment_coefficient = q.moment_coefficient;
  v.nominal.inertia_kgm2 = q.inertia_kgm2;
  v.nominal.gravity_mps2 = q.gravity_mps2;
  return v;
}

// The simulator's motor i (FlightGoggles numbering, models.h) as Crazyflie motor m(4 − i).
Eigen::Vector4d ToCrazyflie(const Eigen::Vector4d& r) { return {r[3], r[2], r[1], r[0]}; }

// A simulated flight as the reader would give it: truth positions, attitude, body rates, rotor speeds
// and the accelerometer's specific force in the world frame, R (k Σ Ω² / m) e3 (the vehicle has no drag).
estim::RotorFlight SimulatedFlight(sim::QuadrotorScenario scenario, double duration_s) {
  sim::QuadrotorSimOptions options;
  options.scenario = scenario;
  options.duration_s = duration_s;
  const estim::QuadrotorData data = sim::SimulateQuadrotor(SimVehicle(), options);
  estim::RotorFlight flight;
  flight.path = "simulated";
  for (const estim::QuadrotorTruth& truth : data.truth) {
    estim::RotorSample s;
    s.t = truth.t;
    s.p = truth.p;
    s.q = truth.q;
    s.w = truth.w;
    s.rotor = ToCrazyflie(truth.rotor);
    const estim::RotorNominal n = SimRotorVehicle().nominal;
    s.accel = truth.q * Eigen::Vector3d(0, 0, n.thrust_coefficient * truth.rotor.squaredNorm() / n.mass_kg);
    s.flying = true;
    flight.samples.push_back(s);
  }
  flight.flying_spans = {{flight.samples.front().t, flight.samples.back().t}};
  return flight;
}

TEST(RotorModel, MatchesTheQuadrotorModel) {
  const estim::QuadrotorModel full{SimVehicle().quadrotor};
  const estim::RotorVehicle v = SimRotorVehicle();
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  double x[9] = {1, 2, 3, 1.5, -0.7, 0.3, 0.2, -0.1, 0.4}, x_dot[9], y_dot[9], omega[3];
  const Eigen::Vector4d rotors(1100, 1180, 1050, 1230);
  full.Dynamics(x, R, rotors.data(), x_dot, omega);
  const Eigen::Vector4d cf = ToCrazyflie(rotors);
  const double cf_dot[4] = {300, -120, 45, -800};  // no rotor inertia in θ: the rates play no part
  estim::RotorDynamics(v.nominal, x, R, cf.data(), cf_dot, v.theta.data(), y_dot);
  for (int i = 0; i < 9; ++i) EXPECT_NEAR(y_dot[i], x_dot[i], 1e-9 * (1 + std::abs(x_dot[i]))) << i;
}

// The rotors' reaction torque conserves angular momentum: with every external torque and force zero
// (θ's thrust and moment coefficients 0), a body whose rotors spin up and down keeps the world-frame
// angular momentum R (J ω + h), h = −c_r Y e3 (Y = Σ s_i Ω_i) — its sign and gyroscopic part right.
TEST(RotorModel, RotorReactionConservesAngularMomentum) {
  estim::RotorVehicle v = SimRotorVehicle();
  v.nominal.inertia_kgm2 = Eigen::Vector3d(2.4e-5, 2.6e-5, 4.1e-5);
  estim::RotorThetaVector theta = estim::RotorThetaVector::Zero();
  theta.segment<3>(estim::kThetaInertiaX).setOnes();
  theta[estim::kThetaRotorInertia] = -30;  // c_r = −3e-8 kg m²
  const double c_r = -30 * estim::kRotorInertiaUnit;
  const Eigen::Vector3d J = v.nominal.inertia_kgm2;
  const Eigen::Vector4d u0(1700, 1650, 1800, 1600), rate(900, -1500, 2500, -400);  // rad/s, rad/s²
  const auto momentum = [&](const Eigen::Matrix3d& R, const Eigen::Vector3d& w, double t) {
    const Eigen::Vector4d u = u0 + rate * t;
    const double Y = u[0] - u[1] + u[2] - u[3];
    return Eigen::Vector3d(R * (J.cwiseProduct(w) - c_r * Y * Eigen::Vector3d::UnitZ()));
  };
  // ω' of the model at (R, ω, t); p and v do not enter the torques here.
  const auto w_dot = [&](const Eigen::Matrix3d& R, const Eigen::Vector3d& w, double t) {
    const Eigen::Vector4d u = u0 + rate * t;
    double x[9] = {0, 0, 0, 0, 0, 0, w.x(), w.y(), w.z()}, x_dot[9];
    estim::RotorDynamics(v.nominal, x, R, u.data(), rate.data(), theta.data(), x_dot);
    return Eigen::Vector3d(x_dot[6], x_dot[7], x_dot[8]);
  };
  Eigen::Matrix3d R = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, -1).normalized()).toRotationMatrix();
  Eigen::Vector3d w(1.5, -2.0, 0.7);
  const Eigen::Vector3d L0 = momentum(R, w, 0);
  const double h = 1e-5;
  const auto exp = [](const Eigen::Vector3d& phi) {
    return phi.norm() > 0 ? Eigen::AngleAxisd(phi.norm(), phi.normalized()).toRotationMatrix()
                          : Eigen::Matrix3d::Identity();
  };
  for (int k = 0; k < 20000; ++k) {  // 0.2 s by the midpoint rule on (R, ω)
    const double t = k * h;
    const Eigen::Vector3d w_mid = w + 0.5 * h * w_dot(R, w, t);
    const Eigen::Matrix3d R_mid = R * exp(0.5 * h * w);
    w += h * w_dot(R_mid, w_mid, t + 0.5 * h);
    R = R * exp(h * w_mid);
  }
  const Eigen::Vector3d L1 = momentum(R, w, 20000 * h);
  // The rotors' momentum changes by |c_r ΔY| = 3e-8 · 0.2 · 5300 ≈ 3.2e-5; the body takes it all.
  EXPECT_LT((L1 - L0).norm(), 1e-3 * std::abs(c_r * 0.2 * 5300)) << (L1 - L0).transpose();
  EXPECT_GT((J.cwiseProduct(w) - J.cwiseProduct(Eigen::Vector3d(1.5, -2.0, 0.7))).norm(), 0.3 * std::abs(c_r * 0.2 * 5300));
}

// The v' and ω' defects, with θ known and θ a parameter block, cost the same evaluated alone (Ceres
// pricing a step: doubles) and linearised (ceres::Jet), at nodes where every term is far from zero.
TEST(RotorModel, DefectsCostTheSameWithAndWithoutJacobians) {
  estim::RotorVehicle v = SimRotorVehicle();
  v.theta[estim::kThetaDragXY] = 3;
  v.theta[estim::kThetaDragZ] = 2;
  v.theta[estim::kThetaFlapX] = 5;
  v.theta[estim::kThetaRotorInertia] = -7;
  const int degree = 5;
  estim::PseudoSpectralProblem<estim::RotorModel> problem({v.nominal, v.theta}, {0.0, 0.25, 0.5}, degree);
  for (int g = 0; g < problem.num_nodes(); ++g) {
    const double t = problem.NodeTime(g);
    Eigen::VectorXd x(9);
    x << t, 2 * t, -t, 1 + t, -0.5, 0.3 * t, 0.2 + t, -0.1, 0.4 * t;
    const Eigen::Vector4d rotors = Eigen::Vector4d(1100, 1180, 1050, 1230) + 400 * t * Eigen::Vector4d(1, -1, 0.5, 2);
    problem.SetNode(g, x, Eigen::AngleAxisd(0.4 + t, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix(),
                    rotors);
  }
  problem.SetChartReferences();
  const Eigen::MatrixXd D = cheb::DifferentiationMatrix(degree);
  estim::RotorThetaVector theta = v.theta;
  for (int s = 0; s < problem.num_segments(); ++s) {
    for (int j = 0; j <= degree; ++j) {
      for (int part : {1, 2}) {
        problem.AddPrior(std::make_unique<estim::internal::ParametricCollocationCost<false>>(
            v.nominal, problem.SegmentOf(s), D, j, part, 0.3, theta.data()));
        problem.AddPrior(std::make_unique<estim::internal::ParametricCollocationCost<true>>(
            v.nominal, problem.SegmentOf(s), D, j, part, 0.3, theta.data()));
      }
    }
  }
  EXPECT_EQ(cheval::testing::ExpectResidualOnlyEvaluationMatches(problem.ceres_problem()), 2 * 6 * 2 * 2);
}

// The flatness inversion with the true vehicle on exact data is close (the fits' window smooths).
TEST(RotorEstimator, EstimateReachesSimulatedAccuracy) {
  const estim::RotorFlight flight = SimulatedFlight(sim::QuadrotorScenario::kFigureEight, 8.0);
  const estim::RotorEstimate e = estim::EstimateRotors(flight, SimRotorVehicle(), {});
  EXPECT_TRUE(e.converged);
  for (int i = 0; i < 4; ++i) {
    EXPECT_LT(e.error.percent[i], 0.5) << i;     // measured: see docs/estimator_real_data.md
    EXPECT_LT(e.baseline.percent[i], 1.0) << i;  // exact positions: the baseline is good too
  }
  EXPECT_GT(e.scored_samples, 600);
  EXPECT_NEAR(e.duration_s, 8.0, 0.02);
  estim::RotorEstimateOptions one_thread;  // the default uses every core; the result is the same
  one_thread.threads = 1;
  const estim::RotorEstimate single = estim::EstimateRotors(flight, SimRotorVehicle(), one_thread);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(single.error.percent[i], e.error.percent[i], 1e-9) << i;
}

// Identification from a base vehicle with wrong published values recovers the true ones; J_z, which
// only scales the yaw torques' ratios to it, is held at the base's (here the true) value.
// The onboard samples (attitude, body rate, accelerometer) stamped 30 ms after the motion capture and the rotor
// telemetry of the same instant: the estimate finds the offset and keeps the simulated accuracy in
// the motion capture's time; taking the two clocks as one, it does not.
TEST(RotorEstimator, EstimatesTheOnboardClockOffset) {
  estim::RotorFlight flight = SimulatedFlight(sim::QuadrotorScenario::kFigureEight, 8.0);
  const int lag = 3;  // samples at 100 Hz
  for (size_t i = flight.samples.size() - 1; i >= lag; --i) {
    flight.samples[i].q = flight.samples[i - lag].q;
    flight.samples[i].w = flight.samples[i - lag].w;
    flight.samples[i].accel = flight.samples[i - lag].accel;
  }
  const double offset = flight.samples[lag].t - flight.samples[0].t;
  const estim::RotorEstimate e = estim::EstimateRotors(flight, SimRotorVehicle(), {});
  ASSERT_EQ(e.clock_offsets_s.size(), 1u);
  EXPECT_NEAR(e.clock_offsets_s[0], offset, 0.002);
  estim::RotorEstimateOptions one_clock;
  one_clock.estimate_clock_offset = false;
  const estim::RotorEstimate same = estim::EstimateRotors(flight, SimRotorVehicle(), one_clock);
  for (int i = 0; i < 4; ++i) {
    EXPECT_LT(e.error.percent[i], 0.5) << i;
    EXPECT_GT(same.error.percent[i], 2 * e.error.percent[i]) << i;
  }
}

// Motion capture that freezes for 0.3 s of every second (as on the shared flights, in turns) and is
// noisy (2 mm) leaves the collective thrust to the dynamics there; the accelerometer (0.3 m/s² of
// white noise) carries it through.
TEST(RotorEstimator, AccelerometerCarriesThrustThroughMotionCaptureFreezes) {
  estim::RotorFlight flight = SimulatedFlight(sim::QuadrotorScenario::kFigureEight, 8.0);
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (size_t i = 0; i < flight.samples.size(); ++i) {
    estim::RotorSample& s = flight.samples[i];
    s.fresh_position = i % 100 < 70;
    s.p += 0.002 * Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    s.accel += 0.3 * Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
  }
  estim::RotorEstimateOptions without;
  without.use_accelerometer = false;
  const estim::RotorEstimate a = estim::EstimateRotors(flight, SimRotorVehicle(), {});
  const estim::RotorEstimate b = estim::EstimateRotors(flight, SimRotorVehicle(), without);
  for (int i = 0; i < 4; ++i) {  // measured: 0.35 % with, 0.72 % without
    EXPECT_LT(a.error.percent[i], 0.5) << i;
    EXPECT_GT(b.error.percent[i], 1.5 * a.error.percent[i]) << i;
  }
}

TEST(RotorIdentification, RecoversPerturbedParameters) {
  const estim::RotorFlight flight = SimulatedFlight(sim::QuadrotorScenario::kLissajous, 10.0);
  estim::RotorVehicle base = SimRotorVehicle();
  const estim::RotorNominal truth = base.nominal;
  base.nominal.thrust_coefficient *= 1.1;
  base.nominal.moment_coefficient *= 0.6;
  base.nominal.inertia_kgm2 = base.nominal.inertia_kgm2.cwiseProduct(Eigen::Vector3d(0.8, 1.25, 1.0));
  std::vector<estim::RotorIdentification> per_flight;
  estim::RotorEstimateOptions options;
  options.rotor_sigma_radps = 1.0;  // the simulator's rotor speeds are exact (the default 30 is for ESC telemetry)
  const estim::RotorVehicle id = estim::IdentifyRotors({flight}, base, options, &per_flight);
  ASSERT_EQ(per_flight.size(), 1u);
  // The collective thrust coefficient is what the translation sees: within 1 %.
  EXPECT_NEAR(id.theta.head<4>().mean() * base.nominal.thrust_coefficient / truth.thrust_coefficient, 1.0, 0.01);
  // Every parameter within 3 σ of the truth (in θ's units relative to the base vehicle): the
  // individual rotors, inertias and k_M trade against the torque offset when the rotor speeds vary
  // little, and the reported σ says so.
  estim::RotorThetaVector expected = estim::RotorThetaVector::Zero();
  expected.head<4>().setConstant(truth.thrust_coefficient / base.nominal.thrust_coefficient);
  for (int i = 0; i < 3; ++i) expected[estim::kThetaInertiaX + i] = truth.inertia_kgm2[i] / base.nominal.inertia_kgm2[i];
  expected[estim::kThetaMoment] = truth.moment_coefficient / base.nominal.moment_coefficient;
  EXPECT_EQ(id.theta[estim::kThetaInertiaX + 2], 1.0);  // held
  EXPECT_EQ(id.theta_sigma[estim::kThetaInertiaX + 2], 0.0);
  for (int i = 0; i < estim::kRotorThetaSize; ++i) {
    if (i != estim::kThetaInertiaX + 2) {
      EXPECT_GT(id.theta_sigma[i], 0) << i;
    }
    EXPECT_LT(std::abs(id.theta[i] - expected[i]), 3 * id.theta_sigma[i] + 1e-3)
        << i << ": " << id.theta[i] << " +- " << id.theta_sigma[i] << ", truth " << expected[i];
  }
  // ... and the roll and pitch inertia to 10 %.
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(id.theta[estim::kThetaInertiaX + i] / expected[estim::kThetaInertiaX + i], 1.0, 0.1) << i;
  }
}

// Pieces that agree within their σ combine as the product of their Gaussians; pieces farther apart
// than their σ say widen σ by the Birge ratio; a held entry (zero variance) stays as it is.
TEST(RotorIdentification, CombinationWidensSigmaByTheDispersion) {
  estim::RotorIdentification a, b;
  a.covariance.setZero();
  a.covariance.diagonal().setConstant(0.01);  // σ 0.1 each
  a.covariance(6, 6) = 0;                     // held
  b.covariance = a.covariance;
  a.theta = estim::RotorNominal::PublishedTheta();
  b.theta = a.theta;
  b.theta[0] += 0.1;   // 1 σ of a difference of two: consistent
  b.theta[11] += 2.0;  // 20 σ: not
  a.pieces = b.pieces = 1;
  const estim::RotorIdentification c = estim::CombineIdentifications({a, b});
  EXPECT_EQ(c.pieces, 2);
  EXPECT_NEAR(c.theta[0], a.theta[0] + 0.05, 1e-12);
  EXPECT_NEAR(std::sqrt(c.covariance(0, 0)), 0.1 / std::sqrt(2.0), 1e-12);  // Q = 0.5 < 1: not widened
  EXPECT_NEAR(c.theta[11], a.theta[11] + 1.0, 1e-12);
  // Q = 2 · (1 / 0.1)² = 200, Birge ratio sqrt(200) ≈ 14.1: σ 0.0707 → 1.0, the half-distance.
  EXPECT_NEAR(std::sqrt(c.covariance(11, 11)), 1.0, 1e-9);
  EXPECT_EQ(c.covariance(6, 6), 0.0);
  EXPECT_EQ(c.theta[6], a.theta[6]);
  EXPECT_THROW(estim::CombineIdentifications({}), UsageError);
  // The flights' ratio about another θ (IdentifyRotors: each flight's combination about the
  // combination of every piece): Q = Σ (θ_k − θ)² / σ²_k over k groups, ratio sqrt(Q / (k − 1)).
  estim::RotorThetaVector about = a.theta;
  about[11] += 0.3;
  const estim::RotorThetaVector r = estim::BirgeRatios({a, b}, about);
  EXPECT_NEAR(r[11], std::sqrt((0.3 * 0.3 + 1.7 * 1.7) / 0.01), 1e-9);
  EXPECT_NEAR(r[0], 1.0, 1e-12);  // Q = 0.1² / 0.01 = 1: not widened
  EXPECT_EQ(r[6], 1.0);  // held
  EXPECT_EQ(estim::BirgeRatios({a}, about)[11], 1.0);  // one group says nothing of the spread
}

TEST(RotorEstimateOptions, RefusesOutOfRangeFields) {
  estim::RotorEstimateOptions o;
  EXPECT_NO_THROW(o.Validate());
  o.identification_piece_s = 0.5;  // pieces shorter than a second would hold a few segments at most
  EXPECT_THROW(o.Validate(), OptionError);
  o = {};
  o.threads = 0;
  EXPECT_THROW(o.Validate(), OptionError);
  o = {};
  o.accelerometer_sigma_mps2 = 0;
  EXPECT_THROW(o.Validate(), OptionError);
  EXPECT_GE(estim::RotorEstimateOptions{}.threads, 1);
}

TEST(RotorVehicleFile, RoundTripAndErrors) {
  const fs::path dir = fs::temp_directory_path() /
                       ("cheval_rotor_vehicle_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
  fs::create_directories(dir);
  estim::RotorVehicle v = SimRotorVehicle();
  v.name = "sim";
  v.theta[3] = 1.07;
  v.theta[estim::kThetaDragXY] = 2.5;
  v.theta_sigma.setConstant(0.01);
  const std::string path = (dir / "v.json").string();
  std::ofstream(path) << estim::RotorVehicleToJson(v);
  const estim::RotorVehicle r = estim::ReadRotorVehicle(path);
  EXPECT_EQ(r.name, "sim");
  EXPECT_DOUBLE_EQ(r.theta[3], 1.07);
  EXPECT_DOUBLE_EQ(r.theta[estim::kThetaDragXY], 2.5);
  EXPECT_DOUBLE_EQ(r.nominal.arm_m, v.nominal.arm_m);
  std::ofstream(path) << "{\"mass_kg\": 1, \"arm_m\": 0.1}";
  EXPECT_THROW(estim::ReadRotorVehicle(path), InputError);
  std::ofstream(path) << "{\"mass_kg\": -1, \"arm_m\": 0.1, \"thrust_coefficient\": 1e-6, \"moment_coefficient\": "
                         "1e-8, \"inertia_kgm2\": [1, 1, 1]}";
  try {
    estim::ReadRotorVehicle(path);
    ADD_FAILURE() << "accepted a negative mass";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("\"mass_kg\" must be a finite number > 0"), std::string::npos) << e.what();
  }
  std::ofstream(path) << "{\"mass\": 1}";
  EXPECT_THROW(estim::ReadRotorVehicle(path), InputError);
  fs::remove_all(dir);
}

// The shared flights: parameters identified on random1 alone, the estimate of melon (a flight the
// identification never saw) is at most 0.6 of the flatness baseline on every motor, and the in-sample
// estimate of random1 at most half of it (measured: melon 2.55–2.74 % against 5.6–5.9 %, random1
// 1.38–1.44 % against 3.25–3.44 %; docs/estimator_real_data.md).
TEST(RotorEstimatorShared, IdentifiedOnOneFlightEstimatesAnother) {
  CHEVAL_REQUIRE_SHARED_DATA();
  const std::string dir = cheval::testing::SharedDataDir() + "/crazyflie_brushless_idsia/";
  const estim::RotorVehicle base = estim::ReadRotorVehicle(std::string(CHEVAL_SOURCE_DIR) +
                                                           "/data/vehicles/crazyflie21_brushless.json");
  const estim::RotorFlight random1 = estim::ReadRotorFlight(dir + "random1_20251017_run1.csv");
  const estim::RotorFlight melon = estim::ReadRotorFlight(dir + "melon_20251017_run5.csv");
  const estim::RotorVehicle id = estim::IdentifyRotors({random1}, base, {}, nullptr);
  const estim::RotorEstimate in_sample = estim::EstimateRotors(random1, id, {});
  const estim::RotorEstimate held_out = estim::EstimateRotors(melon, id, {});
  for (int i = 0; i < 4; ++i) {
    EXPECT_LT(in_sample.error.percent[i], 0.5 * in_sample.baseline.percent[i]) << i;
    EXPECT_LT(held_out.error.percent[i], 0.6 * held_out.baseline.percent[i]) << i;
    EXPECT_GT(held_out.baseline.percent[i], 4.0) << i;  // the baseline as documented (5.6–5.9 %)
  }
}

// The target on the hardest shared flight: square (fast turns through motion-capture freezes),
// its vehicle identified on the other two flights only, is at most half the flatness baseline on every
// motor (measured: 3.66 3.39 2.82 2.97 % against 7.94 8.37 8.20 7.60 %, 34–46 %; without the
// accelerometer 4.31 3.99 3.61 3.83 %, motor 1 at 54 %).
TEST(RotorEstimatorShared, SquareLeftOutIsAtMostHalfTheBaseline) {
  CHEVAL_REQUIRE_SHARED_DATA();
  const std::string dir = cheval::testing::SharedDataDir() + "/crazyflie_brushless_idsia/";
  const estim::RotorVehicle base = estim::ReadRotorVehicle(std::string(CHEVAL_SOURCE_DIR) +
                                                           "/data/vehicles/crazyflie21_brushless.json");
  const estim::RotorVehicle id = estim::IdentifyRotors(
      {estim::ReadRotorFlight(dir + "random1_20251017_run1.csv"), estim::ReadRotorFlight(dir + "melon_20251017_run5.csv")},
      base, {}, nullptr);
  const estim::RotorEstimate square = estim::EstimateRotors(estim::ReadRotorFlight(dir + "square_20251017_run1.csv"), id, {});
  for (int i = 0; i < 4; ++i) EXPECT_LT(square.error.percent[i], 0.5 * square.baseline.percent[i]) << i;
}

}  // namespace
}  // namespace cheval
