// rpg_trajectory_evaluation's conventions (cheval/table/rpg.h) on cases whose answer is known by
// construction: the greedy strict association, the alignments, the absolute errors, the
// sub-trajectory lengths and the identity poses before initialisation.
#include <cmath>
#include <numbers>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "cheval/common/error.h"
#include "cheval/table/rpg.h"

namespace cheval::table {
namespace {

TEST(RpgAssociate, GreedyNearestOneToOneStrict) {
  // est 0 and 1 both nearest gt 0; the closer (est 1, 0.001 s) wins it, est 0 takes gt 1 (0.015 s).
  const std::vector<double> est = {10.000, 10.011, 10.100}, gt = {10.010, 10.015, 10.121};
  const auto m = RpgAssociate(est, gt);
  ASSERT_EQ(m.size(), 2u);
  EXPECT_EQ(m[0], (std::pair<Eigen::Index, Eigen::Index>{0, 1}));
  EXPECT_EQ(m[1], (std::pair<Eigen::Index, Eigen::Index>{1, 0}));
  // est 2 is 0.021 s from gt 2: no match; |dt| < 0.02 is strict.
  EXPECT_TRUE(RpgAssociate({1.0}, {1.5}).empty());
  EXPECT_TRUE(RpgAssociate({0.5}, {0.5}, 0.0).empty());
  EXPECT_EQ(RpgAssociate({1.0}, {1.0 + 0.0199}).size(), 1u);
}

// A ground truth on a curve and an estimate that is it moved by a known transform.
struct Pair {
  RpgPoses gt, est;
};

Pair Moved(double scale, double yaw, double tilt, Eigen::Vector3d t = Eigen::Vector3d(1, -2, 0.5)) {
  Pair p;
  const int n = 400;
  p.gt.p.resize(3, n);
  p.gt.q.resize(4, n);
  const Eigen::Matrix3d r = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
  p.est = p.gt;
  p.est.p.resize(3, n);
  p.est.q.resize(4, n);
  for (int i = 0; i < n; ++i) {
    const double s = 0.05 * i;
    p.gt.t.push_back(100 + 0.05 * i);
    p.gt.p.col(i) = Eigen::Vector3d(3 * std::cos(s), 2 * std::sin(1.3 * s), 0.3 * std::sin(0.7 * s));
    const Eigen::Quaterniond q(Eigen::AngleAxisd(s, Eigen::Vector3d(0.2, 0.3, 1).normalized()));
    p.gt.q.col(i) << q.x(), q.y(), q.z(), q.w();
    // est = (s R)^-1 (gt - t): gt = s R est + t.
    p.est.t.push_back(100 + 0.05 * i + 0.001);
    p.est.p.col(i) = r.transpose() * (p.gt.p.col(i) - t) / scale;
    const Eigen::Quaterniond qe(r.transpose() * q.toRotationMatrix());
    p.est.q.col(i) << qe.x(), qe.y(), qe.z(), qe.w();
  }
  return p;
}

TEST(RpgEvaluate, AlignmentsRecoverTheirTransform) {
  {
    const Pair p = Moved(1.0, 0.7, 0.0);
    RpgEvalConfig c;
    c.align_type = "posyaw";
    const RpgResult r = RpgEvaluate(p.gt, p.est, c);
    EXPECT_EQ(r.matched, 400);
    EXPECT_LT(r.rmse_trans_m, 1e-12);
    EXPECT_LT(r.rmse_rot_deg, 1e-5);
    c.align_num_frames = 1;  // from the first poses' orientations
    EXPECT_LT(RpgEvaluate(p.gt, p.est, c).rmse_trans_m, 1e-12);
  }
  {
    const Pair p = Moved(1.0, 0.7, 0.4);  // a tilt: posyaw cannot undo it, se3 can
    RpgEvalConfig c;
    c.align_type = "posyaw";
    EXPECT_GT(RpgEvaluate(p.gt, p.est, c).rmse_trans_m, 0.05);
    c.align_type = "se3";
    EXPECT_LT(RpgEvaluate(p.gt, p.est, c).rmse_trans_m, 1e-12);
    c.align_num_frames = 1;
    EXPECT_LT(RpgEvaluate(p.gt, p.est, c).rmse_trans_m, 1e-12);
  }
  {
    const Pair p = Moved(2.5, -1.0, 0.3);
    RpgEvalConfig c;
    c.align_type = "sim3";
    const RpgResult r = RpgEvaluate(p.gt, p.est, c);
    EXPECT_NEAR(r.alignment.s, 2.5, 1e-12);
    EXPECT_LT(r.rmse_trans_m, 1e-11);
    // The relative errors use the raw estimate with the scale: exact too.
    for (const RpgRelativeErrors& rel : r.relative) {
      ASSERT_GE(rel.trans_m.size(), 2u);
      for (double e : rel.trans_m) EXPECT_LT(e, 1e-10);
    }
    c.align_num_frames = 1;
    EXPECT_THROW(RpgEvaluate(p.gt, p.est, c), ComputeError);
    c.align_num_frames = 401;
    EXPECT_THROW(RpgEvaluate(p.gt, p.est, c), ComputeError);
  }
}

TEST(RpgEvaluate, AbsoluteErrorsAndLengths) {
  Pair p = Moved(1.0, 0.0, 0.0, Eigen::Vector3d::Zero());
  // A known offset of 0.1 m on every estimate and a 2 degree rotation about z on one.
  for (Eigen::Index i = 0; i < p.est.p.cols(); ++i) p.est.p(0, i) += 0.1;
  const Eigen::Vector4d q0 = p.est.q.col(10);
  const Eigen::Quaterniond rotated =
      Eigen::AngleAxisd(2.0 * std::numbers::pi / 180, Eigen::Vector3d::UnitZ()) * Eigen::Quaterniond(q0[3], q0[0], q0[1], q0[2]);
  p.est.q.col(10) << rotated.x(), rotated.y(), rotated.z(), rotated.w();
  RpgEvalConfig c;
  c.align_type = "none";
  const RpgResult r = RpgEvaluate(p.gt, p.est, c);
  EXPECT_NEAR(r.rmse_trans_m, 0.1, 1e-12);
  EXPECT_NEAR(r.abs_rot_deg[10], 2.0, 1e-9);
  EXPECT_NEAR(r.rmse_rot_deg, std::sqrt(4.0 / 400), 1e-9);
  // Sub-trajectory lengths: percentages of the ground-truth length truncated to centimetres.
  double length = 0;
  for (Eigen::Index i = 1; i < p.gt.p.cols(); ++i) length += (p.gt.p.col(i) - p.gt.p.col(i - 1)).norm();
  EXPECT_NEAR(r.gt_length_m, length, 1e-9);
  ASSERT_EQ(r.relative.size(), 5u);
  EXPECT_EQ(r.relative[2].distance_m, std::trunc(0.3 * length * 100) / 100);
}

TEST(RpgEvaluate, IdentityPosesBeforeInitialisationAreCounted) {
  Pair p = Moved(1.0, 0.0, 0.0, Eigen::Vector3d::Zero());
  for (Eigen::Index i = 0; i < 20; ++i) {
    p.est.p.col(i).setZero();
    p.est.q.col(i) << 0, 0, 0, 1;
  }
  RpgEvalConfig c;
  c.align_type = "none";
  const RpgResult r = RpgEvaluate(p.gt, p.est, c);
  EXPECT_EQ(r.matched, 400);
  double sum = 0;
  for (Eigen::Index i = 0; i < 20; ++i) sum += p.gt.p.col(i).squaredNorm();
  EXPECT_NEAR(r.rmse_trans_m, std::sqrt(sum / 400), 1e-12);
}

TEST(RpgQuaternionMatrix, NormalisesAndNearZeroIsIdentity) {
  EXPECT_TRUE(RpgQuaternionMatrix(Eigen::Vector4d(0, 0, 0, 2)).isApprox(Eigen::Matrix3d::Identity()));
  EXPECT_TRUE(RpgQuaternionMatrix(Eigen::Vector4d(0, 0, 0, 1e-9)).isApprox(Eigen::Matrix3d::Identity()));
  const Eigen::Matrix3d rz = RpgQuaternionMatrix(Eigen::Vector4d(0, 0, std::sin(0.25), std::cos(0.25)));
  EXPECT_NEAR(rz(1, 0), std::sin(0.5), 1e-15);
}

}  // namespace
}  // namespace cheval::table
