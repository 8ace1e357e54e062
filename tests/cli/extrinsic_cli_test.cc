// `--transform-right` on real data: the VINS-Mono MH_05 output of vio_perf holds the pose of EuRoC's
// cam0, a ~90° rotation of the IMU (body) frame of the ground truth, so its rotation APE is ~89°.
// With EuRoC's published cam0 extrinsic (mav0/cam0/sensor.yaml, T_BS = body <- cam0) applied as
// P_imu = P_cam0 * T_BS^-1, it is a few degrees. Also the evo spelling and a bad file. Skipped
// without the shared data.
#include <fstream>
#include <string>

#include <Eigen/Dense>
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../support/test_data.h"
#include "cli_runner.h"

namespace cheval {
namespace {

class ExtrinsicCliTest : public testing::CliTest {
 protected:
  double RotationRmse(const std::string& extra, const std::string& json) {
    const std::string data = testing::SharedDataDir();
    const testing::RunResult run = Cheval(fmt::format(
        "ape {}/ov_data/euroc_mav/MH_05_difficult.csv {}/vio_perf/commit_b4a7c3f/vins/MH_05.tum --align se3 -r angle_deg "
        "{} --json {}",
        data, data, extra, Path(json)));
    EXPECT_EQ(run.exit_code, 0) << run.err;
    return nlohmann::json::parse(testing::Slurp(Path(json)))["stats"]["rmse"].get<double>();
  }
};

TEST_F(ExtrinsicCliTest, EurocCam0ExtrinsicMakesVinsRotationApeAFewDegrees) {
  CHEVAL_REQUIRE_SHARED_DATA();
  Eigen::Matrix4d t_bs;  // EuRoC mav0/cam0/sensor.yaml
  t_bs << 0.0148655429818, -0.999880929698, 0.00414029679422, -0.0216401454975, 0.999557249008, 0.0149672133247,
      0.025715529948, -0.064676986768, -0.0257744366974, 0.00375618835797, 0.999660727178, 0.00981073058949, 0, 0, 0,
      1;
  const Eigen::Matrix4d t_sb = t_bs.inverse();
  std::ofstream(Path("T_cam0_imu.txt")) << t_sb.format(Eigen::IOFormat(17, 0, " ", "\n"));
  const double without = RotationRmse("", "a.json");
  const double with = RotationRmse("--transform-right " + Path("T_cam0_imu.txt"), "b.json");
  EXPECT_GT(without, 85.0);
  EXPECT_LT(with, 5.0);
  EXPECT_EQ(RotationRmse("--transform_right " + Path("T_cam0_imu.txt"), "c.json"), with);
  EXPECT_EQ(testing::Slurp(Path("b.json")), testing::Slurp(Path("c.json")));
}

TEST_F(ExtrinsicCliTest, BadTransformFileIsInputErrorNamingIt) {
  CHEVAL_REQUIRE_SHARED_DATA();
  std::ofstream(Path("bad.txt")) << "1 0 0 0\n0 1 0 0\n0 0 1 0\n";
  const std::string data = testing::SharedDataDir();
  const testing::RunResult run =
      Cheval(fmt::format("ape {0}/evo/fr2_desk_groundtruth.txt {0}/evo/fr2_desk_ORB.txt --ref-transform-left {1}",
                         data, Path("bad.txt")));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("bad.txt"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("expected a 4x4 matrix of 16"), std::string::npos) << run.err;
}

}  // namespace
}  // namespace cheval
