// The quadrotor simulator's options: Validate names the struct and the field (the CLI and Python
// spell the field their way), and SimulateQuadrotor calls it before any work. The simulator's
// physics and data are tested with the estimator (tests/estim/quadrotor_test.cc,
// tests/estim/rigid_body_physics_test.cc).
#include <cmath>
#include <functional>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "cheval/common/error.h"
#include "cheval/estim/vehicle.h"
#include "cheval/sim/quadrotor.h"

namespace cheval {
namespace {

TEST(QuadrotorSimOptions, ValidateNamesTheFirstBadField) {
  EXPECT_NO_THROW(sim::QuadrotorSimOptions().Validate());
  struct Case {
    std::function<void(sim::QuadrotorSimOptions&)> change;
    std::string field, message;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const Case cases[] = {
      {[](auto& o) { o.duration_s = 0; }, "duration_s", "QuadrotorSimOptions::duration_s must be in (0, 3600] s, got 0"},
      {[&](auto& o) { o.duration_s = nan; }, "duration_s", "QuadrotorSimOptions::duration_s must be in (0, 3600] s, got nan"},
      {[](auto& o) { o.duration_s = 3601; }, "duration_s", "QuadrotorSimOptions::duration_s must be in (0, 3600] s, got 3601"},
      {[](auto& o) { o.integration_rate_hz = 99; }, "integration_rate_hz",
       "QuadrotorSimOptions::integration_rate_hz must be in [100, 1e5] Hz, got 99"},
      {[](auto& o) { o.truth_rate_hz = 2000; }, "truth_rate_hz",
       "QuadrotorSimOptions::truth_rate_hz must be in (0, integration_rate_hz = 1000] Hz, got 2000"},
      {[](auto& o) { o.landmarks = 0; }, "landmarks", "QuadrotorSimOptions::landmarks must be > 0, got 0"},
      {[](auto& o) { o.max_features_per_frame = -1; }, "max_features_per_frame",
       "QuadrotorSimOptions::max_features_per_frame must be > 0, got -1"},
      {[](auto& o) { o.vo_position_noise_m = -0.1; }, "vo_position_noise_m",
       "QuadrotorSimOptions::vo_position_noise_m must be a finite number >= 0, got -0.1"},
      {[](auto& o) { o.vo_rotation_drift_rad_per_sqrt_s = INFINITY; }, "vo_rotation_drift_rad_per_sqrt_s",
       "QuadrotorSimOptions::vo_rotation_drift_rad_per_sqrt_s must be a finite number >= 0, got inf"},
  };
  for (const Case& c : cases) {
    sim::QuadrotorSimOptions options;
    c.change(options);
    try {
      options.Validate();
      ADD_FAILURE() << "no error: " << c.message;
    } catch (const OptionError& e) {
      EXPECT_EQ(e.options(), "QuadrotorSimOptions");
      EXPECT_EQ(e.field(), c.field);
      EXPECT_EQ(std::string(e.what()), c.message);
    }
  }
}

TEST(QuadrotorSimOptions, SimulateValidatesFirst) {
  const estim::Vehicle vehicle = estim::ReadVehicle(std::string(CHEVAL_SOURCE_DIR) + "/data/vehicles/flightgoggles.json");
  sim::QuadrotorSimOptions options;
  options.duration_s = -1;
  EXPECT_THROW(sim::SimulateQuadrotor(vehicle, options), OptionError);
}

}  // namespace
}  // namespace cheval
