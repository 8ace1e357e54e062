// The quadrotor: model (torques of the motor layout, hover), vehicle files (good and bad), the
// simulator (physics consistency with the model, camera, determinism) and the estimator end to end.
#include <cstdio>
#include <cmath>
#include <random>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "cheval/common/error.h"
#include "cheval/estim/internal/thrust_acceleration_cost.h"
#include "cheval/estim/models.h"
#include "cheval/estim/problem.h"
#include "cheval/estim/quadrotor_data.h"
#include "cheval/estim/quadrotor_estimator.h"
#include "cheval/estim/quadrotor_scoring.h"
#include "cheval/estim/vehicle.h"
#include "cheval/lie/so3.h"
#include "cheval/sim/quadrotor.h"

namespace cheval {
namespace {

namespace fs = std::filesystem;

const std::string kVehicle = std::string(CHEVAL_SOURCE_DIR) + "/data/vehicles/flightgoggles.json";

TEST(QuadrotorModel, ShippedVehicleHoversAtTheDocumentedSpeed) {
  const estim::Vehicle v = estim::ReadVehicle(kVehicle);
  // docs/estimator.md: sqrt(m g / 4 k_F) ≈ 1133 rad/s for the FlightGoggles vehicle.
  EXPECT_NEAR(v.quadrotor.HoverRotorSpeed(), std::sqrt(1.0 * 9.81 / (4 * 1.91e-6)), 1e-9);
  EXPECT_NEAR(v.quadrotor.HoverRotorSpeed(), 1133.1, 0.1);
  const estim::QuadrotorModel model{v.quadrotor};
  double x[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0}, x_dot[9], omega[3];
  const double h = v.quadrotor.HoverRotorSpeed();
  const double u[4] = {h, h, h, h};
  model.Dynamics(x, Eigen::Matrix3d::Identity().eval(), u, x_dot, omega);
  for (int i = 0; i < 9; ++i) EXPECT_NEAR(x_dot[i], 0.0, 1e-12) << i;
}

// Motor layout of docs/estimator.md: speeding up the two left motors (0, 1; y = +a) rolls right-side
// down (τ_x > 0); the front ones (0, 3; x = +a) pitch nose up (τ_y < 0); the +1-spin motors (1, 3)
// yaw positive.
TEST(QuadrotorModel, TorquesFollowTheMotorLayout) {
  estim::QuadrotorParameters p = estim::ReadVehicle(kVehicle).quadrotor;
  const estim::QuadrotorModel model{p};
  const double h = 1000, d = 10;
  const double left[4] = {h + d, h + d, h, h}, front[4] = {h + d, h, h, h + d}, spin[4] = {h, h + d, h, h + d};
  const double df = p.thrust_coefficient * ((h + d) * (h + d) - h * h);
  EXPECT_NEAR(model.Torque(left).x(), 2 * p.arm_m * df, 1e-12);
  EXPECT_NEAR(model.Torque(front).y(), -2 * p.arm_m * df, 1e-12);
  EXPECT_NEAR(model.Torque(spin).z(), 2 * p.moment_coefficient * ((h + d) * (h + d) - h * h), 1e-12);
  EXPECT_NEAR(model.Torque(left).z(), 0.0, 1e-12);
}

class VehicleFileTest : public ::testing::Test {
 protected:
  std::string Write(const std::string& text) {
    path_ = fs::temp_directory_path() / ("cheval_vehicle_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
                                         ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".json");
    std::ofstream(path_) << text;
    return path_.string();
  }
  void TearDown() override { fs::remove(path_); }
  // The shipped file with one "key": value replaced.
  std::string Shipped(const std::string& from, const std::string& to) {
    std::ifstream in(kVehicle);
    std::string text((std::istreambuf_iterator<char>(in)), {});
    const size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return text.replace(at, from.size(), to);
  }
  void ExpectError(const std::string& text, const std::string& message) {
    try {
      estim::ReadVehicle(Write(text));
      ADD_FAILURE() << "no error for " << message;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  }
  fs::path path_;
};

TEST_F(VehicleFileTest, NonPhysicalOrMissingValuesAreErrors) {
  ExpectError(Shipped("\"mass_kg\": 1.0", "\"mass_kg\": -1.0"), "\"mass_kg\" must be a finite number > 0 and <= 10000, got -1");
  ExpectError(Shipped("[0.0049, 0.0049, 0.0069]", "[0.0049, 0, 0.0069]"), "singular or negative inertia");
  ExpectError(Shipped("[0.0049, 0.0049, 0.0069]", "[0.001, 0.001, 0.01]"), "triangle inequality");
  ExpectError(Shipped("\"mass_kg\": 1.0,", ""), "missing key \"mass_kg\"");
  ExpectError(Shipped("\"fx\": 400", "\"fx\": \"400\""), "\"camera.fx\" must be a number");
  ExpectError(Shipped("\"max_rotor_speed_radps\": 2200", "\"max_rotor_speed_radps\": 1000"), "cannot fly");
  ExpectError("{ not json", "expected JSON (a vehicle file)");
  EXPECT_THROW(estim::ReadVehicle("/nonexistent/vehicle.json"), InputError);
}

// A number beyond a double is an InputError naming the key that holds it (nlohmann's out_of_range
// escaped as an internal error, exit 70, before).
TEST_F(VehicleFileTest, NumberOverflowNamesTheKey) {
  ExpectError(Shipped("\"mass_kg\": 1.0", "\"mass_kg\": 1e400"),
              ":0:0: error: mass_kg: the number '1e400' is too large for a double (at most 1.8e308 in magnitude)");
  ExpectError(Shipped("\"rate_hz\": 30", "\"rate_hz\": -1e400"), "error: camera.rate_hz: the number '-1e400' is too large");
  ExpectError(Shipped("[0.0049, 0.0049, 0.0069]", "[0.0049, 1e999, 0.0069]"), "error: inertia_kgm2[1]: the number '1e999'");
}

// Every value within its documented range (docs/estimator.md, "Vehicle file"), so nothing computed
// from it overflows; the camera rate bounds the simulator's frames.
TEST_F(VehicleFileTest, ValuesOutsideTheirRangeAreErrors) {
  ExpectError(Shipped("\"mass_kg\": 1.0", "\"mass_kg\": 1e300"),
              "\"mass_kg\" must be a finite number > 0 and <= 10000, got 1e+300");
  ExpectError(Shipped("\"rate_hz\": 30", "\"rate_hz\": 1e6"),
              "\"camera.rate_hz\" must be a finite number > 0 and <= 1000, got 1000000");
  ExpectError(Shipped("\"width\": 640", "\"width\": 1e10"), "\"camera.width\" must be an integer in [1, 100000], got 10000000000");
  ExpectError(Shipped("\"height\": 480", "\"height\": 480.5"), "\"camera.height\" must be an integer in [1, 100000], got 480.5");
  ExpectError(Shipped("\"cx\": 320", "\"cx\": 1e300"), "\"camera.cx\" must be a finite number in [-1000000, 1000000], got 1e+300");
  ExpectError(Shipped("\"gravity_mps2\": 9.81", "\"gravity_mps2\": 1e200"), "\"gravity_mps2\" must be a finite number > 0 and <= 100");
  ExpectError(Shipped("\"drag_coefficient\": 0.1", "\"drag_coefficient\": 0.1, \"grav\": 9"),
              "unknown key \"grav\"; expected only name, source,");
  ExpectError(Shipped("\"fx\": 400", "\"fx\": 400, \"rate\": 30"), "unknown key \"camera.rate\"");
}

TEST_F(VehicleFileTest, ADirectoryIsAnInputError) {
  const fs::path dir = fs::temp_directory_path() / ("cheval_vehicle_dir_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  try {
    estim::ReadVehicle(dir.string());
    ADD_FAILURE() << "a directory was read as a vehicle";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), dir.string() + ":0:0: error: is a directory; expected a vehicle JSON file");
  }
  fs::remove_all(dir);
}

// The estimator refuses a segment length whose problem would not fit in memory before allocating
// it (--segment 1e-9 took 15.6 GB and ended in exit 70; the segment count overflowed an int).
TEST(QuadrotorEstimator, RefusesASegmentLengthBeyondTheMemoryLimit) {
  const estim::Vehicle vehicle = estim::ReadVehicle(kVehicle);
  sim::QuadrotorSimOptions sim_options;
  sim_options.duration_s = 1.0;
  const estim::QuadrotorData data = sim::SimulateQuadrotor(vehicle, sim_options);
  for (double segment : {1e-9, 1e-5}) {
    estim::QuadrotorEstimateOptions options;
    options.segment_s = segment;
    try {
      estim::EstimateQuadrotor(vehicle, data.landmarks, data.pixels, data.initial, options, {});
      ADD_FAILURE() << "segment " << segment << " accepted";
    } catch (const OptionError& e) {
      EXPECT_EQ(e.field(), "segment_s");
      EXPECT_NE(e.rule().find("must keep the problem within 3 GB"), std::string::npos) << e.what();
      EXPECT_NE(e.rule().find(" GB (16 KB + 6 KB x degree per node)"), std::string::npos) << e.what();
    }
  }
}

// The simulator's memory is bounded: truth samples and landmarks by Validate (OptionError), the
// camera's frames (duration x camera.rate_hz) by a ComputeError naming the vehicle's key.
TEST(QuadrotorSim, RefusesARunBeyondTheMemoryLimit) {
  estim::Vehicle vehicle = estim::ReadVehicle(kVehicle);
  const auto refused_field = [](const sim::QuadrotorSimOptions& o) {
    try {
      o.Validate();
    } catch (const OptionError& e) {
      return e.field();
    }
    return std::string("(accepted)");
  };
  sim::QuadrotorSimOptions options;
  options.duration_s = 3600;
  options.integration_rate_hz = 1e5;
  options.truth_rate_hz = 1e5;
  EXPECT_EQ(refused_field(options), "truth_rate_hz");  // 3.6e8 truth samples
  options = {};
  options.landmarks = 2'000'000'000;
  EXPECT_EQ(refused_field(options), "landmarks");
  options = {};
  options.duration_s = 3600;
  vehicle.camera.rate_hz = 1000;
  EXPECT_GT(sim::QuadrotorSimBytes(vehicle, options), sim::kMaxQuadrotorSimBytes);
  try {
    sim::SimulateQuadrotor(vehicle, options);
    ADD_FAILURE() << "3.6e6 frames accepted";
  } catch (const ComputeError& e) {
    EXPECT_NE(std::string(e.what()).find("camera.rate_hz 1000 Hz is 3.6e+06 frames"), std::string::npos) << e.what();
  }
}

// The simulator integrates the estimator's own model: the truth samples satisfy v = dp/dt to the
// accuracy of a central difference at 100 Hz (O(h²·p''') ≈ 1e-3 m/s for these flights).
TEST(QuadrotorSim, TruthIsConsistentAndDeterministic) {
  const estim::Vehicle v = estim::ReadVehicle(kVehicle);
  sim::QuadrotorSimOptions options;
  options.scenario = sim::QuadrotorScenario::kFigureEight;
  options.duration_s = 3.0;
  const estim::QuadrotorData a = sim::SimulateQuadrotor(v, options), b = sim::SimulateQuadrotor(v, options);
  ASSERT_EQ(a.truth.size(), 301u);
  EXPECT_EQ(a.initial.size(), 91u);  // 30 Hz over 3 s, both ends
  ASSERT_EQ(a.pixels.size(), b.pixels.size());
  for (size_t i = 0; i < a.pixels.size(); ++i) EXPECT_EQ(a.pixels[i].uv, b.pixels[i].uv);
  for (size_t i = 1; i + 1 < a.truth.size(); ++i) {
    const Eigen::Vector3d fd = (a.truth[i + 1].p - a.truth[i - 1].p) / 0.02;
    EXPECT_LT((fd - a.truth[i].v).norm(), 2e-3) << i;
  }
  // Every frame sees at most max_features_per_frame landmarks, inside the image.
  for (const auto& m : a.pixels) {
    EXPECT_GE(m.uv.x(), -5.0);
    EXPECT_LE(m.uv.x(), v.camera.width + 5.0);
  }
  options.seed = 2;
  EXPECT_NE(sim::SimulateQuadrotor(v, options).pixels.front().uv, a.pixels.front().uv);
}

TEST(QuadrotorSim, DataFolderRoundTripAndMissingFiles) {
  const estim::Vehicle v = estim::ReadVehicle(kVehicle);
  sim::QuadrotorSimOptions options;
  options.duration_s = 1.0;
  const estim::QuadrotorData data = sim::SimulateQuadrotor(v, options);
  const fs::path dir = fs::temp_directory_path() / "cheval_quadrotor_roundtrip";
  fs::remove_all(dir);
  estim::WriteQuadrotorData(data, dir.string());
  const estim::QuadrotorData back = estim::ReadQuadrotorData(dir.string());
  ASSERT_EQ(back.pixels.size(), data.pixels.size());
  EXPECT_EQ(back.pixels.back().uv, data.pixels.back().uv);  // %.17g round-trips doubles exactly
  EXPECT_EQ(back.truth.back().rotor, data.truth.back().rotor);
  EXPECT_EQ(back.landmarks.size(), data.landmarks.size());
  fs::remove(dir / "measurements.csv");
  try {
    estim::ReadQuadrotorData(dir.string());
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("measurements.csv:0:0: error: cannot open"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

// A simulated 4 s flight (seed 1) and the truth's times, where the estimate is reported.
struct Flight {
  estim::QuadrotorData data;
  std::vector<double> times;
};
Flight FourSecondFlight(const estim::Vehicle& v, sim::QuadrotorScenario scenario) {
  sim::QuadrotorSimOptions options;
  options.scenario = scenario;
  options.duration_s = 4.0;
  Flight flight{sim::SimulateQuadrotor(v, options), {}};
  for (const auto& t : flight.data.truth) flight.times.push_back(t.t);
  return flight;
}

// End to end on a short hover and a short figure-eight (seed 1) with the defaults. Measured: worst
// motor 0.066 % / 0.135 %, position RMSE 1.9 / 2.6 mm, rotation RMSE 0.029° / 0.030°. The flights
// are deterministic (seeded simulator, one thread), so the bounds sit at ~1.5x those figures: room
// for rounding across compilers and Ceres versions, not for a regression of the estimator.
TEST(QuadrotorEstimator, RecoversRotorSpeedsFromTheCamera) {
  const estim::Vehicle v = estim::ReadVehicle(kVehicle);
  for (sim::QuadrotorScenario scenario : {sim::QuadrotorScenario::kHover, sim::QuadrotorScenario::kFigureEight}) {
    const bool hover = scenario == sim::QuadrotorScenario::kHover;
    const Flight flight = FourSecondFlight(v, scenario);
    const estim::QuadrotorData& data = flight.data;
    const std::vector<double>& times = flight.times;
    const estim::QuadrotorEstimate e =
        estim::EstimateQuadrotor(data.vehicle, data.landmarks, data.pixels, data.initial, {}, times);
    EXPECT_TRUE(e.converged) << e.solver_report;
    EXPECT_EQ(e.states, e.segments * e.degree + 1);
    const estim::QuadrotorErrors errors = estim::CompareWithTruth(e, data.truth);
    EXPECT_EQ(errors.samples, 401);
    EXPECT_LT(errors.rotor_error_percent.maxCoeff(), hover ? 0.1 : 0.2) << sim::ToString(scenario);
    EXPECT_LT(errors.position_rmse_m, hover ? 0.003 : 0.004);
    EXPECT_LT(errors.rotation_rmse_deg, 0.045);
    // The front end's initial poses were worse than the estimate.
    double initial_p2 = 0;
    for (size_t i = 0; i < data.initial.size(); ++i) {
      initial_p2 += (data.initial[i].p - data.truth[std::min(data.truth.size() - 1, static_cast<size_t>(std::lround(data.initial[i].t * 100)))].p).squaredNorm();
    }
    EXPECT_GT(std::sqrt(initial_p2 / data.initial.size()), 3 * errors.position_rmse_m);
  }
}

// The flatness-based initialisation recovers a known flight from its exact poses: noise-free 10 Hz
// poses of the simulated figure-eight (the truth at every third frame). A quadratic fit over ±h =
// ±0.3 s biases v by p⁽³⁾ Στ⁴/(6 Στ²) = 0.0117 p⁽³⁾ on the 7 poses τ = 0, ±0.1, ±0.2, ±0.3 s
// (p⁽³⁾ ≤ 5.8 m/s³ here: ≤ 0.068 m/s) and a by ~0.07 h² p⁽⁴⁾
// (≤ 0.06 m/s², ~0.3 % of the rotor speed); the torques are taken as ω × Jω. So inside the flight
// the rotor speeds come back within 0.6 %, v within 0.08 m/s and p within 3 mm (the cubic term
// the fit cannot follow, ~h³ p⁽³⁾/20 ≈ 8 mm at most, mostly cancels at the window's centre, less
// when t lies off it between poses); in the 0.3 s at each end the
// window is one-sided (extrapolated fit): 1.5 %, 0.25 m/s and 1 cm. The hover start the estimator
// used before is off by over 4 times as much.
TEST(QuadrotorEstimator, FlatnessInitialStateRecoversAKnownFlight) {
  const estim::Vehicle v = estim::ReadVehicle(kVehicle);
  sim::QuadrotorSimOptions options;
  options.scenario = sim::QuadrotorScenario::kFigureEight;
  options.duration_s = 4.0;
  const estim::QuadrotorData data = sim::SimulateQuadrotor(v, options);
  std::vector<estim::PoseSample> poses;
  for (const estim::PoseSample& frame : data.initial) {
    const size_t i = static_cast<size_t>(std::lround(frame.t * 100));
    if (std::abs(data.truth[i].t - frame.t) < 1e-9) poses.push_back({frame.t, data.truth[i].p, data.truth[i].q});
  }
  ASSERT_EQ(poses.size(), 41u);
  double worst_rotor = 0, worst_hover = 0;
  for (const estim::QuadrotorTruth& truth : data.truth) {
    const estim::QuadrotorStateEstimate x0 = estim::FlatnessInitialState(v.quadrotor, poses, truth.t, 0.6);
    const bool inside = truth.t >= 0.3 && truth.t <= 3.7;
    for (int i = 0; i < 4; ++i) {
      const double error = std::abs(x0.rotor[i] - truth.rotor[i]) / truth.rotor[i];
      EXPECT_LT(error, inside ? 0.006 : 0.015) << truth.t;
      worst_rotor = std::max(worst_rotor, error);
      worst_hover = std::max(worst_hover, std::abs(v.quadrotor.HoverRotorSpeed() - truth.rotor[i]) / truth.rotor[i]);
    }
    EXPECT_LT((x0.v - truth.v).norm(), inside ? 0.08 : 0.25) << truth.t;
    EXPECT_LT((x0.p - truth.p).norm(), inside ? 3e-3 : 1e-2) << truth.t;
    // The rotation is the poses' own at a pose time (slerp between them otherwise).
    if (std::abs(truth.t * 10 - std::round(truth.t * 10)) < 1e-9) {
      EXPECT_LT(lie::SO3d(Eigen::Matrix3d(x0.R.transpose() * truth.q.toRotationMatrix())).Log().norm(), 1e-9);
    }
  }
  EXPECT_GT(worst_hover, 4 * worst_rotor);
  EXPECT_THROW(estim::FlatnessInitialState(v.quadrotor, {poses[0], poses[1]}, 0.0, 0.6), ComputeError);
}

// AdaptiveRotorPriorSigma is the maximum-likelihood random-walk intensity: pooled closed form on
// three segments, and on a seeded random walk of known σ = 40 (u' white noise, increments
// N(0, σ² Δt), 10 steps per segment, 4 controls, 300 segments). An inner segment pools 120 squared
// increments: σ̂/σ = sqrt(χ²₁₂₀/120), relative spread 1/√240 = 6.5 %, so 25 % bounds every
// segment (3.9 spreads); the mean over 300 segments spreads 0.37 %: 2 % is 5 of those.
TEST(QuadrotorEstimator, AdaptiveRotorPriorSigmaIsTheRandomWalkMaximumLikelihood) {
  const std::vector<double> three = estim::AdaptiveRotorPriorSigma({4.0, 16.0, 100.0}, 10, 4);
  ASSERT_EQ(three.size(), 3u);
  EXPECT_NEAR(three[0], std::sqrt(20.0 / (2 * 40)), 1e-12);
  EXPECT_NEAR(three[1], std::sqrt(120.0 / (3 * 40)), 1e-12);
  EXPECT_NEAR(three[2], std::sqrt(116.0 / (2 * 40)), 1e-12);
  EXPECT_NEAR(estim::AdaptiveRotorPriorSigma({9.0}, 1, 1)[0], 3.0, 1e-12);
  EXPECT_THROW(estim::AdaptiveRotorPriorSigma({1.0, -1.0}, 10, 4), UsageError);
  EXPECT_THROW(estim::AdaptiveRotorPriorSigma({1.0}, 0, 4), UsageError);

  const double sigma = 40, dt = 0.1;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal(0.0, sigma * std::sqrt(dt));
  std::vector<double> energy(300, 0.0);
  for (double& e : energy) {
    for (int k = 0; k < 10 * 4; ++k) {
      const double step = normal(rng);
      e += step * step / dt;  // Σ (Δu)²/Δt: ∫ |u'|² of the piecewise-linear path
    }
  }
  const std::vector<double> estimate = estim::AdaptiveRotorPriorSigma(energy, 10, 4);
  double mean = 0;
  for (double e : estimate) {
    EXPECT_NEAR(e, sigma, 0.25 * sigma);
    mean += e / estimate.size();
  }
  EXPECT_NEAR(mean, sigma, 0.02 * sigma);
}

// End to end: the collective's thrust-acceleration prior (thrust_prior, the default) against the
// random-walk prior on the collective (thrust_prior = false) on a 4 s hover and a 4 s aggressive
// flight (seed 1). Measured, worst motor: hover 0.066 % against 0.122 %, aggressive 0.512 % against
// 0.945 %, so the thrust prior's error is 0.54x the random walk's on both; 3 and 4 iterations (the
// random walk 3 on both). Deterministic runs: bounds ~1.5x the figures (0.1 %, 0.75 %), the ratio
// at 0.6 and the iterations at the measured counts + 1.
TEST(QuadrotorEstimator, ThrustPriorBeatsTheRandomWalkCollective) {
  const estim::Vehicle v = estim::ReadVehicle(kVehicle);
  for (sim::QuadrotorScenario scenario : {sim::QuadrotorScenario::kHover, sim::QuadrotorScenario::kAggressive}) {
    const Flight flight = FourSecondFlight(v, scenario);
    const estim::QuadrotorData& data = flight.data;
    const std::vector<double>& times = flight.times;
    estim::QuadrotorEstimateOptions random_walk;
    random_walk.thrust_prior = false;
    const estim::QuadrotorEstimate a = estim::EstimateQuadrotor(data.vehicle, data.landmarks, data.pixels, data.initial, {}, times);
    const estim::QuadrotorEstimate r =
        estim::EstimateQuadrotor(data.vehicle, data.landmarks, data.pixels, data.initial, random_walk, times);
    EXPECT_TRUE(a.converged) << a.solver_report;
    EXPECT_TRUE(r.converged) << r.solver_report;
    const double thrust_error = estim::CompareWithTruth(a, data.truth).rotor_error_percent.maxCoeff();
    const double random_walk_error = estim::CompareWithTruth(r, data.truth).rotor_error_percent.maxCoeff();
    const bool hover = scenario == sim::QuadrotorScenario::kHover;
    EXPECT_LT(thrust_error, hover ? 0.1 : 0.75);
    EXPECT_LT(thrust_error, 0.6 * random_walk_error);
    EXPECT_LE(a.iterations, hover ? 4 : 5);
    EXPECT_LE(r.iterations, 4);
  }
}

// Every option is validated before any work, and the error names the struct and the field (the
// faces translate the field into their flag or keyword).
TEST(QuadrotorEstimator, BadOptionsNameTheField) {
  const estim::Vehicle v = estim::ReadVehicle(kVehicle);
  sim::QuadrotorSimOptions options;
  options.duration_s = 1.0;
  const estim::QuadrotorData data = sim::SimulateQuadrotor(v, options);
  const auto message = [&](const estim::QuadrotorEstimateOptions& bad) -> std::string {
    try {
      estim::EstimateQuadrotor(v, data.landmarks, data.pixels, data.initial, bad, {});
    } catch (const OptionError& e) {
      EXPECT_EQ(e.options(), "QuadrotorEstimateOptions");
      return e.what();
    }
    return "no error";
  };
  estim::QuadrotorEstimateOptions bad;
  bad.degree = 1;
  EXPECT_EQ(message(bad), "QuadrotorEstimateOptions::degree must be in [2, 64], got 1");
  bad = {};
  bad.pilot_iterations = 0;
  EXPECT_EQ(message(bad), "QuadrotorEstimateOptions::pilot_iterations must be >= 1, got 0");
  bad = {};
  bad.rotor_prior_sigma_floor = 0;
  EXPECT_EQ(message(bad), "QuadrotorEstimateOptions::rotor_prior_sigma_floor must be > 0, got 0");
  bad = {};
  bad.sigma_rotor_rate = 0;
  EXPECT_EQ(message(bad), "QuadrotorEstimateOptions::sigma_rotor_rate must be > 0, got 0");
  bad = {};
  bad.segment_s = std::numeric_limits<double>::infinity();
  EXPECT_EQ(message(bad), "QuadrotorEstimateOptions::segment_s must be a positive number of seconds, got inf");
  EXPECT_NO_THROW(estim::QuadrotorEstimateOptions{}.Validate());
}

// The thrust-acceleration rows against a direct evaluation and central differences in the blocks'
// ambient coordinates (rotor speeds, quaternion x, y, z, w): f_k = (k_F/m) |Ω_k|² R_k e3.
TEST(QuadrotorEstimator, ThrustAccelerationCostJacobiansMatchDifferences) {
  const estim::Vehicle v = estim::ReadVehicle(kVehicle);
  using Problem = estim::PseudoSpectralProblem<estim::QuadrotorModel>;
  Problem problem(estim::QuadrotorModel{v.quadrotor}, {0.0, 0.7}, 4);
  std::mt19937 rng(3);
  std::normal_distribution<double> n01;
  for (int g = 0; g < problem.num_nodes(); ++g) {
    const Eigen::Quaterniond q = Eigen::Quaterniond(Eigen::Vector4d(n01(rng), n01(rng), n01(rng), n01(rng))).normalized();
    problem.SetNode(g, Eigen::VectorXd::Zero(9), q.toRotationMatrix(),
                    Eigen::Vector4d(1300 + 100 * n01(rng), 1300 + 100 * n01(rng), 1300 + 100 * n01(rng), 1300 + 100 * n01(rng)));
  }
  const double k_over_m = v.quadrotor.thrust_coefficient / v.quadrotor.mass_kg;
  std::array<Eigen::MatrixXd, 3> C{Eigen::MatrixXd::Random(2, 5), Eigen::MatrixXd::Random(2, 5), Eigen::MatrixXd::Random(2, 5)};
  const Eigen::MatrixXd offsets = Eigen::MatrixXd::Random(2, 3);
  const estim::internal::Segment segment = problem.SegmentOf(0);
  estim::internal::ThrustAccelerationCost cost(segment.control, segment.quaternion, C, offsets, k_over_m);
  cost.set_weight(0.3);
  std::vector<double*> blocks = cost.blocks();
  const auto residuals = [&]() {
    Eigen::VectorXd r(6);
    EXPECT_TRUE(cost.Evaluate(blocks.data(), r.data(), nullptr));
    return r;
  };
  Eigen::VectorXd want = Eigen::VectorXd::Zero(6);
  for (int row = 0; row < 2; ++row) {
    for (int a = 0; a < 3; ++a) {
      double sum = offsets(row, a);
      for (int k = 0; k < 5; ++k) {
        const int g = problem.NodeOf(0, k);  // C's column k is point k of the segment
        const Eigen::Map<const Eigen::Vector4d> u(problem.Control(g));
        const Eigen::Matrix3d R = Eigen::Quaterniond(Eigen::Map<const Eigen::Vector4d>(problem.Quaternion(g))).toRotationMatrix();
        sum += C[a](row, k) * k_over_m * u.squaredNorm() * R(a, 2);
      }
      want[3 * row + a] = 0.3 * sum;
    }
  }
  EXPECT_LT((residuals() - want).norm(), 1e-9 * want.norm());
  std::vector<Eigen::Matrix<double, 6, 4, Eigen::RowMajor>> J(10);
  std::vector<double*> jacobians;
  for (auto& j : J) jacobians.push_back(j.data());
  Eigen::VectorXd r(6);
  ASSERT_TRUE(cost.Evaluate(blocks.data(), r.data(), jacobians.data()));
  for (int b = 0; b < 10; ++b) {
    for (int i = 0; i < 4; ++i) {
      const double h = b % 2 == 0 ? 1e-3 : 1e-6, x = blocks[b][i];
      blocks[b][i] = x + h;
      const Eigen::VectorXd plus = residuals();
      blocks[b][i] = x - h;
      const Eigen::VectorXd minus = residuals();
      blocks[b][i] = x;
      const Eigen::VectorXd numeric = (plus - minus) / (2 * h);
      EXPECT_LT((J[b].col(i) - numeric).norm(), 1e-6 * (1 + numeric.norm())) << b << " " << i;
    }
  }
}

TEST(QuadrotorEstimator, BadInputIsAnError) {
  const estim::Vehicle v = estim::ReadVehicle(kVehicle);
  sim::QuadrotorSimOptions options;
  options.duration_s = 1.0;
  estim::QuadrotorData data = sim::SimulateQuadrotor(v, options);
  // Initial poses that do not cover the measurements.
  std::vector<estim::PoseSample> short_initial(data.initial.begin(), data.initial.begin() + 10);
  EXPECT_THROW(estim::EstimateQuadrotor(v, data.landmarks, data.pixels, short_initial, {}, {}), ComputeError);
  // A landmark id outside the map.
  auto pixels = data.pixels;
  pixels[3].landmark = 100000;
  EXPECT_THROW(estim::EstimateQuadrotor(v, data.landmarks, pixels, data.initial, {}, {}), ComputeError);
  estim::QuadrotorEstimateOptions bad;
  bad.degree = 1;
  EXPECT_THROW(estim::EstimateQuadrotor(v, data.landmarks, data.pixels, data.initial, bad, {}), UsageError);
  EXPECT_FALSE(sim::QuadrotorScenarioFromString("loop").has_value());
}

}  // namespace
}  // namespace cheval
