// `cheval estimate rotors` through the executable: a short hover written by the test in the Crazyflie
// CSV layout is estimated and its --report page and --json written; bad input gets its documented
// exit code (docs/cli.md) with the file and line named, and nothing is written.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_runner.h"

namespace cheval {
namespace {

namespace fs = std::filesystem;
using cheval::testing::CliTest;
using cheval::testing::RunResult;
using cheval::testing::Slurp;

const std::string kVehicle = std::string(CHEVAL_SOURCE_DIR) + "/data/vehicles/crazyflie21_brushless.json";
const char* const kHeader =
    "t,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz,x_mocap,y_mocap,z_mocap,m1_erpm,m2_erpm,m3_erpm,m4_erpm,ax,ay,az,is_flying";

// `line` without its comma-separated field number `field` (none when field < 0).
std::string WithoutField(const std::string& line, int field) {
  if (field < 0) return line;
  size_t begin = 0;
  for (int k = 0; k < field; ++k) begin = line.find(',', begin) + 1;
  const size_t end = line.find(',', begin);
  return end == std::string::npos ? line.substr(0, begin - 1) : line.substr(0, begin) + line.substr(end + 1);
}

class RotorsCliTest : public CliTest {
 protected:
  // A 3 s hover at 100 Hz (identity attitude, 1 m up swaying 1 cm in x, 99000 eRPM on every motor),
  // without the column number `drop` of kHeader when given.
  std::string WriteHover(const std::string& name, int drop = -1) const {
    std::ofstream out(Path(name));
    out << WithoutField(kHeader, drop) << "\n";
    for (int i = 0; i < 300; ++i) {
      const double t = 0.01 * i;
      out << WithoutField(fmt::format("{:.2f},0,0,1,1,0,0,0,0,0,0,0,0,0,{:.6f},0,1,99000,99000,99000,99000,0,0,9.81,1",
                                      t, 0.01 * std::sin(t)),
                          drop)
          << "\n";
    }
    return Path(name);
  }

  // --json, -o and, in a build with the report page, --report, all in this test's folder.
  std::string Outputs() const {
    return fmt::format("--json {} -o {}{}", Path("out.json"), Path("out.csv"),
                       CHEVAL_REPORT_AVAILABLE ? " --report " + Path("page.html") : "");
  }
  void ExpectNoOutputs() const {
    for (const char* name : {"out.json", "out.csv", "page.html"}) EXPECT_FALSE(fs::exists(Path(name))) << name;
  }
};

TEST_F(RotorsCliTest, WritesTheReportPageAndJson) {
  const std::string flight = WriteHover("hover.csv");
  const RunResult r =
      Cheval(fmt::format("estimate rotors --data {} --vehicle {} --json {} --report {}", flight, kVehicle,
                         Path("out.json"), Path("page.html")));
  if (!CHEVAL_REPORT_AVAILABLE) {
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_NE(r.err.find("CHEVAL_BUILD_REPORT"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(Path("out.json"))) << "refused before any work";
    return;
  }
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json json = nlohmann::json::parse(Slurp(Path("out.json")));
  EXPECT_EQ(json["rotor_error_percent"].size(), 4u);
  const std::string page = Slurp(Path("page.html"));
  EXPECT_NE(page.find(R"("page":"rotors")"), std::string::npos);
  EXPECT_NE(page.find("<title>cheval estimate rotors: hover.csv with crazyflie21_brushless.json</title>"),
            std::string::npos);
  EXPECT_EQ(page.find(dir_.string()), std::string::npos) << "no folder of this machine in the page";
}

TEST_F(RotorsCliTest, MissingColumnIsExit2NamingFileAndLine) {
  const std::string flight = WriteHover("no_wz.csv", 13);  // without wz
  const RunResult r =
      Cheval(fmt::format("estimate rotors --data {} --vehicle {} {}", flight, kVehicle, Outputs()));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find(flight + ":1:1: error: the header lacks the column(s) wz"), std::string::npos) << r.err;
  ExpectNoOutputs();
}

// An option out of its range is exit 1, named by its flag (not the library's field).
TEST_F(RotorsCliTest, OptionOutOfRangeIsExit1NamingTheFlag) {
  const std::string flight = WriteHover("hover.csv");
  RunResult r = Cheval(fmt::format("estimate rotors --data {} --vehicle {} --degree 1 {}", flight, kVehicle, Outputs()));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("--degree must be in [2, 20], got 1"), std::string::npos) << r.err;
  ExpectNoOutputs();
  r = Cheval(fmt::format("estimate rotors --data {} --vehicle {} --accelerometer-sigma 0 {}", flight, kVehicle, Outputs()));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("--accelerometer-sigma must be > 0, got 0"), std::string::npos) << r.err;
  ExpectNoOutputs();
  r = Cheval(fmt::format("identify rotors --data {} --vehicle {} --piece 0.5 -o {}", flight, kVehicle, Path("v.json")));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("--piece must be at least 1 s, got 0.5"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(Path("v.json")));
}

TEST_F(RotorsCliTest, MissingVehicleFileIsExit2) {
  const std::string flight = WriteHover("hover.csv");
  const RunResult r = Cheval(
      fmt::format("estimate rotors --data {} --vehicle {} {}", flight, Path("no_such_vehicle.json"), Outputs()));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find(Path("no_such_vehicle.json")), std::string::npos) << r.err;
  ExpectNoOutputs();
}

TEST_F(RotorsCliTest, OutputOverAnInputIsRefusedBeforeAnyWork) {
  const std::string flight = WriteHover("hover.csv");
  const std::string before = Slurp(flight);
  RunResult r = Cheval(fmt::format("estimate rotors --data {} --vehicle {} --report {}", flight, kVehicle, flight));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  const std::string expected = CHEVAL_REPORT_AVAILABLE ? "--report " + flight + " names the same file as the input"
                                                       : "CHEVAL_BUILD_REPORT";  // no page in this build
  EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
  EXPECT_EQ(Slurp(flight), before) << "the flight is untouched";
  r = Cheval(fmt::format("estimate rotors --data {} --vehicle {} -o {}", flight, kVehicle, flight));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("-o " + flight + " names the same file as the input"), std::string::npos) << r.err;
  EXPECT_EQ(Slurp(flight), before) << "the flight is untouched";
  r = Cheval(fmt::format("estimate rotors --data {} --vehicle {} --json {} -o {}", flight, kVehicle, Path("same.out"),
                         Path("same.out")));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_FALSE(fs::exists(Path("same.out")));
}

TEST_F(RotorsCliTest, UnwritableReportIsExit4AndWritesNothing) {
  const std::string flight = WriteHover("hover.csv");
  const RunResult r = Cheval(fmt::format("estimate rotors --data {} --vehicle {} --json {} --report {}", flight,
                                         kVehicle, Path("out.json"), Path("no_such_folder/page.html")));
  if (CHEVAL_REPORT_AVAILABLE) {
    EXPECT_EQ(r.exit_code, 4) << r.err;
    EXPECT_NE(r.err.find("no_such_folder/page.html: error: cannot write"), std::string::npos) << r.err;
  } else {
    EXPECT_EQ(r.exit_code, 1) << r.err;  // a build without the page refuses --report before any work
  }
  EXPECT_FALSE(fs::exists(Path("out.json"))) << "the outputs are written together or not at all";
}

}  // namespace
}  // namespace cheval
