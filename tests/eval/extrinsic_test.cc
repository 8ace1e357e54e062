// Extrinsic files in evo's load_transform formats (JSON, 4x4 text, 4x4 .npy), their validation, and
// the left / right application to a trajectory, against hand-derived poses.
#include "cheval/eval/extrinsic.h"

#include <cmath>
#include <cstring>
#include <string>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "cheval/common/error.h"
#include "eval_test_util.h"

namespace cheval::eval {
namespace {

// 90 degrees about z, translation (1, 2, 3).
const char* kMatrix = "0 -1 0 1\n1 0 0 2\n0 0 1 3\n0 0 0 1\n";

std::string Npy(const double (&m)[16], bool fortran, bool big_endian) {
  std::string header = std::string("{'descr': '") + (big_endian ? ">" : "<") + "f8', 'fortran_order': " +
                       (fortran ? "True" : "False") + ", 'shape': (4, 4), }";
  while ((10 + header.size() + 1) % 64 != 0) header += ' ';
  header += '\n';
  std::string out = "\x93NUMPY";
  out += '\x01';
  out += '\x00';
  out += static_cast<char>(header.size() & 0xff);
  out += static_cast<char>(header.size() >> 8);
  out += header;
  for (int k = 0; k < 16; ++k) {
    const double v = fortran ? m[(k % 4) * 4 + k / 4] : m[k];
    char bytes[8];
    std::memcpy(bytes, &v, 8);
    if (big_endian) std::reverse(bytes, bytes + 8);
    out.append(bytes, 8);
  }
  return out;
}

void ExpectQuarterTurn(const Extrinsic& e) {
  EXPECT_TRUE(e.rotation.isApprox(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix(), 1e-12));
  EXPECT_TRUE(e.translation.isApprox(Eigen::Vector3d(1, 2, 3)));
  EXPECT_EQ(e.scale, 1.0);
}

TEST(ExtrinsicTest, ReadsEvosThreeFormatsAlike) {
  ExpectQuarterTurn(ParseExtrinsic(kMatrix, "matrix", "t.txt"));
  ExpectQuarterTurn(ParseExtrinsic("0,-1,0,1, 1,0,0,2, 0,0,1,3, 0,0,0,1", "matrix", "t.csv"));
  const double s = std::sqrt(0.5);
  ExpectQuarterTurn(ParseExtrinsic(
      "{\"x\": 1, \"y\": 2, \"z\": 3, \"qx\": 0, \"qy\": 0, \"qz\": " + std::to_string(s) + ", \"qw\": " + std::to_string(s) + "}",
      "json", "t.json"));
  const double m[16] = {0, -1, 0, 1, 1, 0, 0, 2, 0, 0, 1, 3, 0, 0, 0, 1};
  for (bool fortran : {false, true}) {
    for (bool big : {false, true}) ExpectQuarterTurn(ParseExtrinsic(Npy(m, fortran, big), "npy", "t.npy"));
  }
  // A scale: in JSON, or as s*R in the matrix.
  EXPECT_DOUBLE_EQ(ParseExtrinsic("{\"x\":0,\"y\":0,\"z\":0,\"qx\":0,\"qy\":0,\"qz\":0,\"qw\":1,\"scale\":2.5}", "json", "t.json").scale, 2.5);
  EXPECT_NEAR(ParseExtrinsic("2 0 0 0\n0 2 0 0\n0 0 2 0\n0 0 0 1", "matrix", "t.txt").scale, 2.0, 1e-15);
}

TEST(ExtrinsicTest, BadFilesSayWhatIsWrong) {
  const std::pair<std::string, std::string> matrices[] = {
      {"1 0 0 0\n0 1 0 0\n0 0 1 0\n", "12 numbers, expected a 4x4 matrix of 16"},
      {"1 0 0 0\n0 1 0 0\n0 0 1 x\n0 0 0 1", "\"x\" is not a number"},
      {"1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 1 1", "the last row is 0 0 1 1"},
      {"1 0 0 0\n0 1 0 0\n0 0 -1 0\n0 0 0 1", "determinant -1"},
      {"1 0.1 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1", "not orthonormal"},
      {"1 0 0 nan\n0 1 0 0\n0 0 1 0\n0 0 0 1", "row 1 column 4 is nan, expected a finite number"},
  };
  for (const auto& [text, expected] : matrices) {
    testing::ExpectThrowWith<InputError>([&] { ParseExtrinsic(text, "matrix", "bad.txt"); }, {"bad.txt:", expected});
  }
  testing::ExpectThrowWith<InputError>([] { ParseExtrinsic("{\"x\":0,\"y\":0,\"z\":0,\"qx\":0,\"qy\":0,\"qz\":0}", "json", "b.json"); },
                                       {"b.json", "missing key \"qw\""});
  testing::ExpectThrowWith<InputError>([] { ParseExtrinsic("{\"x\":0,\"y\":0,\"z\":0,\"qx\":0,\"qy\":0,\"qz\":0,\"qw\":2}", "json", "b.json"); },
                                       {"norm 2", "unit quaternion"});
  testing::ExpectThrowWith<InputError>([] { ParseExtrinsic("{\"x\":\"1\",\"y\":0,\"z\":0,\"qx\":0,\"qy\":0,\"qz\":0,\"qw\":1}", "json", "b.json"); },
                                       {"x: expected a number"});
  testing::ExpectThrowWith<InputError>([] { ParseExtrinsic("[1, 2]", "json", "b.json"); }, {"expected a JSON object"});
  testing::ExpectThrowWith<InputError>([] { ParseExtrinsic("not numpy at all", "npy", "b.npy"); }, {"b.npy", "magic"});
  const double m[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  std::string truncated = Npy(m, false, false);
  truncated.resize(truncated.size() - 8);
  testing::ExpectThrowWith<InputError>([&] { ParseExtrinsic(truncated, "npy", "b.npy"); }, {"120 bytes of data, expected 128"});
  testing::ExpectThrowWith<InputError>([] { ReadExtrinsic("/nonexistent/t.json"); }, {"/nonexistent/t.json"});
}

TEST(ExtrinsicTest, LeftChangesTheWorldRightTheBody) {
  using testing::PoseSpec;
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()));
  traj::Trajectory t = testing::MakeTrajectory({PoseSpec{0, {1, 0, 0}, q}, PoseSpec{1'000'000'000, {0, 1, 0}, q}});
  Extrinsic e = ParseExtrinsic(kMatrix, "matrix", "t.txt");  // Rz(90°), (1, 2, 3)
  const traj::Trajectory left = TransformTrajectory(t.View(), &e, nullptr);
  const traj::Trajectory right = TransformTrajectory(t.View(), nullptr, &e);
  for (Eigen::Index i = 0; i < 2; ++i) {
    const Eigen::Vector3d p = t.positions().col(i);
    const Eigen::Matrix3d r = t.Rotation(i);
    EXPECT_TRUE(left.positions().col(i).isApprox(e.rotation * p + e.translation, 1e-12));
    EXPECT_TRUE(left.Rotation(i).isApprox(e.rotation * r, 1e-12));
    EXPECT_TRUE(right.positions().col(i).isApprox(p + r * e.translation, 1e-12));
    EXPECT_TRUE(right.Rotation(i).isApprox(r * e.rotation, 1e-12));
  }
  EXPECT_EQ(left.stamps_ns()[1], 1'000'000'000);
  // Right needs rigid, and orientation for a lever arm.
  Extrinsic scaled = e;
  scaled.scale = 2;
  EXPECT_THROW(TransformTrajectory(t.View(), nullptr, &scaled), UsageError);
  traj::Trajectory positions = testing::MakeTrajectory({PoseSpec{0, {1, 0, 0}}}, false, false);
  EXPECT_THROW(TransformTrajectory(positions.View(), nullptr, &e), UsageError);
  EXPECT_NO_THROW(TransformTrajectory(positions.View(), &scaled, nullptr));
}

}  // namespace
}  // namespace cheval::eval
