// `cheval ase --velocity-frame body` through the executable: the estimate's velocity columns are
// body-frame and must become R_world_body · v_body. The reference file carries that world velocity,
// worked out by hand (tests/eval/body_velocity_test.cc has the same table), so the velocity part is
// zero with the right rotation and metres per second with its transpose or none.
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_runner.h"

namespace cheval {
namespace {

class VelocityFrameCliTest : public testing::CliTest {
 protected:
  // TUM + velocity: t x y z qx qy qz qw vx vy vz. The orientations (quaternions written out):
  //   Rz(90°) = (0, 0, s, s), Rx(90°) = (s, 0, 0, s), Rz(90°)·Rx(90°) = (1/2, 1/2, 1/2, 1/2), Ry(180°) = (0, 1, 0, 0)
  // with s = √2/2. v_body = (1, 2, 3) becomes, by hand, (-2, 1, 3), (1, -3, 2), (3, 1, 2), (-1, 2, -3).
  void WriteFiles() const {
    const double s = std::sqrt(0.5);
    const double q[4][4] = {{0, 0, s, s}, {s, 0, 0, s}, {0.5, 0.5, 0.5, 0.5}, {0, 1, 0, 0}};
    const double world[4][3] = {{-2, 1, 3}, {1, -3, 2}, {3, 1, 2}, {-1, 2, -3}};
    const double p[4][3] = {{0, 0, 0}, {1, 1, 0}, {2, 4, 1}, {3, 9, 0}};
    std::ofstream ref(Path("ref.tumv")), est(Path("est.tumv"));
    for (int i = 0; i < 4; ++i) {
      const std::string pose = fmt::format("{}.0 {} {} {} {:.17g} {:.17g} {:.17g} {:.17g}", 100 + i, p[i][0], p[i][1],
                                           p[i][2], q[i][0], q[i][1], q[i][2], q[i][3]);
      ref << fmt::format("{} {} {} {}\n", pose, world[i][0], world[i][1], world[i][2]);
      est << pose << " 1 2 3\n";
    }
  }

  // The velocity column of --errors (stamp,error,rotation,position,velocity).
  std::vector<double> VelocityErrors(const std::string& csv) const {
    std::istringstream in(testing::Slurp(Path(csv)));
    std::string line;
    std::getline(in, line);
    EXPECT_EQ(line, "stamp,error,rotation,position,velocity");
    std::vector<double> out;
    while (std::getline(in, line)) out.push_back(std::stod(line.substr(line.rfind(',') + 1)));
    return out;
  }
};

TEST_F(VelocityFrameCliTest, BodyVelocityIsRotatedIntoTheWorld) {
  WriteFiles();
  const testing::RunResult body = Cheval(fmt::format("ase {} {} --velocity-frame body --json {} --errors {}",
                                                     Path("ref.tumv"), Path("est.tumv"), Path("b.json"), Path("b.csv")));
  ASSERT_EQ(body.exit_code, 0) << body.err;
  const nlohmann::json j = nlohmann::json::parse(testing::Slurp(Path("b.json")));
  EXPECT_EQ(j["stats"]["n"], 4);
  // R v to rounding: the quaternions are written to 17 digits, |v| ~ 4 m/s.
  EXPECT_LT(j["parts"]["velocity"]["max"].get<double>(), 1e-14);
  EXPECT_LT(j["stats"]["max"].get<double>(), 1e-14);
  for (double e : VelocityErrors("b.csv")) EXPECT_LT(e, 1e-14);

  // The same columns read as world frame (the default): |v_body − v_world| per pose, by hand
  // √10, √26, √6, √40; RMSE √((10 + 26 + 6 + 40) / 4) = √20.5.
  const testing::RunResult world =
      Cheval(fmt::format("ase {} {} --json {} --errors {}", Path("ref.tumv"), Path("est.tumv"), Path("w.json"),
                         Path("w.csv")));
  ASSERT_EQ(world.exit_code, 0) << world.err;
  const nlohmann::json w = nlohmann::json::parse(testing::Slurp(Path("w.json")));
  EXPECT_NEAR(w["parts"]["velocity"]["rmse"].get<double>(), std::sqrt(20.5), 1e-14);
  const std::vector<double> per_pose = VelocityErrors("w.csv");
  const double expected[] = {std::sqrt(10.0), std::sqrt(26.0), std::sqrt(6.0), std::sqrt(40.0)};
  ASSERT_EQ(per_pose.size(), 4u);
  for (size_t i = 0; i < 4; ++i) EXPECT_NEAR(per_pose[i], expected[i], 1e-14) << i;
}

}  // namespace
}  // namespace cheval
