// The reader of flights with measured rotor speeds (crazyflie_data.h): conversion, NaN rows,
// flying spans, the scored samples, the messages of bad files, and the three shared flights.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "../support/test_data.h"
#include "cheval/common/error.h"
#include "cheval/estim/crazyflie_data.h"

namespace cheval {
namespace {

namespace fs = std::filesystem;

const char* kHeader =
    "t,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz,x_mocap,y_mocap,z_mocap,m1_erpm,m2_erpm,m3_erpm,m4_erpm,ax,ay,az,"
    "is_flying\n";

// A row in kHeader's layout: time t, mocap x = t, eRPM `erpm` on every motor, `flying`.
std::string Row(double t, double erpm, int flying, const std::string& mocap_x = "") {
  const std::string x = mocap_x.empty() ? std::to_string(t) : mocap_x;
  return std::to_string(t) + ",0,0,0,2,0,0,0,0,0,0,0.1,0.2,0.3," + x + ",0,1," + std::to_string(erpm) + "," +
         std::to_string(erpm) + "," + std::to_string(erpm) + "," + std::to_string(erpm) + ",0,0,9.8," +
         std::to_string(flying) + "\n";
}

class RotorFlightFile : public ::testing::Test {
 protected:
  std::string Write(const std::string& text) {
    const fs::path dir = fs::temp_directory_path() /
                         ("cheval_rotors_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
                          ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir);
    const std::string path = (dir / "flight.csv").string();
    std::ofstream(path) << text;
    return path;
  }
  // The message of the InputError that reading `text` throws ("" when none).
  std::string Error(const std::string& text) {
    const std::string path = Write(text);
    try {
      estim::ReadRotorFlight(path);
    } catch (const InputError& e) {
      return std::string(e.what()).substr(path.size());
    }
    return "";
  }
};

TEST_F(RotorFlightFile, ConvertsAndNormalises) {
  std::string text = kHeader;
  for (int i = 0; i < 5; ++i) text += Row(0.01 * i, 36000, 1);
  const estim::RotorFlight f = estim::ReadRotorFlight(Write(text));
  ASSERT_EQ(f.samples.size(), 5u);
  // 36000 eRPM = 6000 mechanical rpm = 100 rev/s = 200π rad/s.
  EXPECT_NEAR(f.samples[0].rotor[2], 200 * M_PI, 1e-9);
  EXPECT_NEAR(f.samples[0].q.norm(), 1.0, 1e-15);  // stored (2, 0, 0, 0)
  EXPECT_NEAR(f.samples[3].p.x(), 0.03, 1e-12);
  EXPECT_NEAR(f.samples[1].w.z(), 0.3, 1e-15);
  EXPECT_NEAR(f.samples[1].accel.z(), 9.8, 1e-15);
  EXPECT_TRUE(f.dropped_lines.empty());
  ASSERT_EQ(f.flying_spans.size(), 1u);
  EXPECT_DOUBLE_EQ(f.flying_spans[0].second, 0.04);
}

TEST_F(RotorFlightFile, DropsAndReportsMissingValues) {
  std::string text = kHeader;
  for (int i = 0; i < 6; ++i) {
    std::string row = Row(0.01 * i, 36000, 1);
    if (i == 2) row = Row(0.02, 36000, 1, "nan");
    if (i == 4) row = Row(0.04, 36000, 1, " ");  // an empty field
    text += row;
  }
  const estim::RotorFlight f = estim::ReadRotorFlight(Write(text));
  EXPECT_EQ(f.samples.size(), 4u);
  ASSERT_EQ(f.dropped_lines.size(), 2u);
  EXPECT_EQ(f.dropped_lines[0], 4);  // header is line 1
  EXPECT_EQ(f.dropped_lines[1], 6);
  for (const estim::RotorSample& s : f.samples) EXPECT_TRUE(std::isfinite(s.p.x()));
}

TEST_F(RotorFlightFile, FlyingSpansAndScoredSamples) {
  std::string text = kHeader;
  // 0–0.99 s on the ground, 1.00–3.99 s flying, 4.00–4.49 s on the ground, 4.50–5.99 s flying.
  for (int i = 0; i < 600; ++i) {
    const int flying = (i >= 100 && i < 400) || i >= 450 ? 1 : 0;
    text += Row(0.01 * i, 36000, flying);
  }
  const estim::RotorFlight f = estim::ReadRotorFlight(Write(text));
  ASSERT_EQ(f.flying_spans.size(), 2u);
  EXPECT_NEAR(f.flying_spans[0].first, 1.0, 1e-9);
  EXPECT_NEAR(f.flying_spans[0].second, 3.99, 1e-9);
  EXPECT_NEAR(f.flying_spans[1].first, 4.5, 1e-9);
  const std::vector<size_t> scored = estim::ScoredSamples(f, 0.5);
  // [1.5, 3.49] and [5.0, 5.49]: 200 + 50 samples (up to rounding of the printed times).
  EXPECT_NEAR(static_cast<double>(scored.size()), 250.0, 2.0);
  for (size_t i : scored) {
    EXPECT_TRUE(f.samples[i].flying);
    EXPECT_TRUE(f.samples[i].t >= 1.5 - 1e-9);
  }
}

TEST_F(RotorFlightFile, MarksRepeatedMotionCapturePositions) {
  std::string text = kHeader;
  text += Row(0.00, 36000, 1, "0.5") + Row(0.01, 36000, 1, "0.5") + Row(0.02, 36000, 1, "0.6");
  const estim::RotorFlight f = estim::ReadRotorFlight(Write(text));
  EXPECT_TRUE(f.samples[0].fresh_position);
  EXPECT_FALSE(f.samples[1].fresh_position);
  EXPECT_TRUE(f.samples[2].fresh_position);
}

TEST_F(RotorFlightFile, BadFiles) {
  EXPECT_NE(Error("t,x_mocap,y_mocap\n0,1,2\n").find(":1:1: error: the header lacks the column(s) z_mocap, qw"),
            std::string::npos);
  std::string text = std::string(kHeader) + Row(0, 1, 1) + "0.01,1,2\n";
  EXPECT_NE(Error(text).find(":3:1: error: expected 25 fields as in the header, got 3"), std::string::npos);
  text = std::string(kHeader) + Row(0, 1, 1) + Row(0.01, 1, 1, "abc");
  EXPECT_NE(Error(text).find(":3:42: error: column \"x_mocap\": expected a finite number"), std::string::npos)
      << Error(text);
  text = std::string(kHeader) + Row(0.01, 1, 1) + Row(0.01, 1, 1) + Row(0.02, 1, 1);
  EXPECT_NE(Error(text).find(":3:1: error: times must increase"), std::string::npos);
  text = std::string(kHeader) + Row(0, -5, 1) + Row(0.01, 1, 1) + Row(0.02, 1, 1);
  EXPECT_NE(Error(text).find(":2:1: error: column \"m1_erpm\": a rotor speed must be >= 0"), std::string::npos);
  text = std::string(kHeader) + Row(0, 1, 2) + Row(0.01, 1, 1) + Row(0.02, 1, 1);
  EXPECT_NE(Error(text).find("is_flying\": expected 0 or 1, got 2"), std::string::npos);
  text = std::string(kHeader) + Row(0, 1, 1) + Row(0.01, 1, 1, "nan");
  EXPECT_NE(Error(text).find(":0:0: error: expected at least 3 complete rows, got 1 (1 dropped"), std::string::npos);
  EXPECT_NE(Error("").find("empty file"), std::string::npos);
  text = std::string(kHeader) + "0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,1,1,1,1,0,0,0,1\n";
  EXPECT_NE(Error(text).find(":2:1: error: expected a rotation"), std::string::npos);
  const fs::path dir = fs::temp_directory_path();
  EXPECT_THROW(estim::ReadRotorFlight(dir.string()), InputError);
  EXPECT_THROW(estim::ReadRotorFlight((dir / "cheval_no_such_flight.csv").string()), InputError);
}

TEST(RotorFlightShared, ReadsTheThreeFlights) {
  CHEVAL_REQUIRE_SHARED_DATA();
  struct Case {
    const char* name;
    size_t rows;
  };
  for (const Case& c : {Case{"square_20251017_run1", 1900}, Case{"random1_20251017_run1", 6000},
                        Case{"melon_20251017_run5", 6500}}) {
    const estim::RotorFlight f =
        estim::ReadRotorFlight(cheval::testing::SharedDataDir() + "/crazyflie_brushless_idsia/" + c.name + ".csv");
    EXPECT_EQ(f.samples.size() + f.dropped_lines.size(), c.rows) << c.name;
    ASSERT_FALSE(f.flying_spans.empty());
    for (const estim::RotorSample& s : f.samples) {
      ASSERT_GT(s.rotor.minCoeff(), 300.0) << c.name << " t " << s.t;  // SOURCE.md: ≈ 600–2500 rad/s
      ASSERT_LT(s.rotor.maxCoeff(), 3000.0) << c.name << " t " << s.t;
    }
  }
}

}  // namespace
}  // namespace cheval
