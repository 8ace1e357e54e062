// eval::Evaluate end to end on hand-built trajectories, against the definitions of docs/evaluation.md:
// APE of a rigidly moved copy (the offset before alignment, zero after), RPE invariant under a
// global motion, the ASE's parts, the options' validation naming the field, the JSON and the
// per-pair CSV.
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cheval/common/error.h"
#include "cheval/eval/evaluate.h"
#include "eval_test_util.h"
#include "expect_option_error.h"

namespace cheval::eval {
namespace {

using cheval::testing::ExpectOptionError;
using testing::AxisAngle;
using testing::MakeTrajectory;
using testing::PoseSpec;

constexpr int64_t kPeriodNs = 10'000'000;  // 100 Hz

// A helix with changing orientation and its exact velocity, n poses at 100 Hz.
std::vector<PoseSpec> Helix(int n) {
  std::vector<PoseSpec> poses;
  for (int i = 0; i < n; ++i) {
    const double t = 0.01 * i;
    PoseSpec s;
    s.stamp_ns = 1'000'000'000 + i * kPeriodNs;
    s.p = {std::cos(t), std::sin(t), 0.2 * t};
    s.v = {-std::sin(t), std::cos(t), 0.2};
    s.q = AxisAngle(t, Eigen::Vector3d::UnitZ()) * AxisAngle(0.3 * t, Eigen::Vector3d::UnitX());
    poses.push_back(s);
  }
  return poses;
}

// Every pose moved by the rigid motion (R, t): p' = R p + t, q' = R q, v' = R v.
std::vector<PoseSpec> Moved(std::vector<PoseSpec> poses, const Eigen::Quaterniond& R, const Eigen::Vector3d& t) {
  for (PoseSpec& s : poses) {
    s.p = R * s.p + t;
    s.q = R * s.q;
    s.v = R * s.v;
  }
  return poses;
}

TEST(EvaluateTest, ApeOfATranslatedCopyIsTheOffsetUnalignedAndZeroAligned) {
  const traj::Trajectory ref = MakeTrajectory(Helix(300));
  const traj::Trajectory est = MakeTrajectory(Moved(Helix(300), Eigen::Quaterniond::Identity(), {0.3, -0.4, 0}));
  EvaluationOptions options;
  const EvaluationResult raw = Evaluate(ref.View(), est.View(), options);
  ASSERT_EQ(raw.errors.size(), 300u);
  // APE trans_part = |p_est − p_ref| = |(0.3, −0.4, 0)| = 0.5 for every pair.
  for (double e : raw.errors) EXPECT_NEAR(e, 0.5, 1e-12);
  EXPECT_NEAR(raw.stats.rmse, 0.5, 1e-12);
  EXPECT_EQ(raw.stats.n, 300);
  EXPECT_EQ(raw.unit, "m");
  EXPECT_EQ(raw.title, "APE w.r.t. translation part (m)\n(not aligned)");

  options.alignment.method = AlignmentMethod::kSE3;
  const EvaluationResult aligned = Evaluate(ref.View(), est.View(), options);
  // Umeyama recovers the exact rigid motion: every error is zero up to rounding (|p| ~ 1).
  EXPECT_LT(aligned.stats.max, 1e-12);
  EXPECT_NEAR(aligned.alignment.transform.translation.x(), -0.3, 1e-12);
  EXPECT_NEAR(aligned.alignment.transform.translation.y(), 0.4, 1e-12);
  EXPECT_EQ(aligned.alignment.pairs_used, 300);
}

TEST(EvaluateTest, RpeIsInvariantUnderAGlobalRigidMotion) {
  const traj::Trajectory ref = MakeTrajectory(Helix(200));
  const traj::Trajectory est =
      MakeTrajectory(Moved(Helix(200), AxisAngle(1.0, Eigen::Vector3d(1, 2, 3)), {5, -2, 1}));
  EvaluationOptions options;
  options.metric = MetricKind::kRpe;
  options.rpe.delta = 10;
  // E = (Q_i⁻¹ Q_j)⁻¹ (P_i⁻¹ P_j) with P = T Q gives E = I: zero translation error and angle.
  for (PoseRelation relation : {PoseRelation::kTranslation, PoseRelation::kAngleDeg}) {
    options.relation = relation;
    const EvaluationResult r = Evaluate(ref.View(), est.View(), options);
    EXPECT_EQ(r.rpe_pairs.size(), 19u);  // ids 0, 10, ..., 190: 19 consecutive pairs
    EXPECT_LT(r.stats.max, 1e-9) << ToString(relation);
    ASSERT_EQ(r.stamps_end_ns.size(), r.stamps_ns.size());
    EXPECT_EQ(r.stamps_end_ns[0] - r.stamps_ns[0], 10 * kPeriodNs);
  }
  // The APE of the same pair is not zero: the motion is not aligned away.
  options.metric = MetricKind::kApe;
  options.relation = PoseRelation::kTranslation;
  EXPECT_GT(Evaluate(ref.View(), est.View(), options).stats.min, 1.0);
}

TEST(EvaluateTest, AseOfAVelocityOffsetIsItsNorm) {
  const traj::Trajectory ref = MakeTrajectory(Helix(100), true);
  std::vector<PoseSpec> offset = Helix(100);
  for (PoseSpec& s : offset) s.v += Eigen::Vector3d(0, 0.6, 0.8);
  const traj::Trajectory est = MakeTrajectory(offset, true);
  EvaluationOptions options;
  options.metric = MetricKind::kAse;
  const EvaluationResult r = Evaluate(ref.View(), est.View(), options);
  ASSERT_TRUE(r.ase.has_value());
  EXPECT_TRUE(r.ase->has_rotation);
  EXPECT_TRUE(r.ase->has_velocity);
  EXPECT_EQ(r.velocity_source, "given");
  EXPECT_EQ(r.relation, "state");
  // Same R and p: ASE_i = |R_qᵀ (v_p − v_q)| = |(0, 0.6, 0.8)| = 1 (a rotation keeps the norm).
  for (size_t k = 0; k < r.errors.size(); ++k) {
    EXPECT_NEAR(r.errors[k], 1.0, 1e-12);
    EXPECT_NEAR(r.ase->velocity[k], 1.0, 1e-12);
    EXPECT_NEAR(r.ase->position[k], 0.0, 1e-12);
    EXPECT_NEAR(r.ase->rotation[k], 0.0, 1e-12);
  }
  // Pose-only: rotation and position only, so zero.
  options.pose_only = true;
  const EvaluationResult pose = Evaluate(ref.View(), est.View(), options);
  EXPECT_FALSE(pose.ase->has_velocity);
  EXPECT_EQ(pose.relation, "rotation+position");
  EXPECT_LT(pose.stats.max, 1e-12);
}

// A reference whose orientations are all the identity (a position-only source written with identity
// quaternions) is position-only for the ASE, with one warning; identity_reference_is_position_only =
// false keeps the rotation part, which is then the estimate's own rotation angle.
TEST(EvaluateTest, AseTakesAnIdentityOrientationReferenceAsPositionOnly) {
  std::vector<PoseSpec> identity = Helix(100);
  for (PoseSpec& s : identity) s.q = Eigen::Quaterniond::Identity();
  const traj::Trajectory ref = MakeTrajectory(identity, true);
  const traj::Trajectory est = MakeTrajectory(Helix(100), true);  // rotating, same positions and velocities
  EvaluationOptions options;
  options.metric = MetricKind::kAse;
  const EvaluationResult r = Evaluate(ref.View(), est.View(), options);
  EXPECT_FALSE(r.ase->has_rotation);
  EXPECT_EQ(r.relation, "position+velocity");
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("identity_reference_is_position_only"), std::string::npos);
  EXPECT_LT(r.stats.max, 1e-12);  // positions and velocities agree
  options.identity_reference_is_position_only = false;
  const EvaluationResult kept = Evaluate(ref.View(), est.View(), options);
  EXPECT_TRUE(kept.ase->has_rotation);
  EXPECT_TRUE(kept.warnings.empty());
  EXPECT_GT(kept.stats.max, 0.1);  // the helix turns: the identity "orientation" is wrong by that much
  // A reference with real orientations gets no warning.
  options.identity_reference_is_position_only = true;
  EXPECT_TRUE(Evaluate(est.View(), est.View(), options).warnings.empty());
}

TEST(EvaluateTest, ValidateNamesTheFirstBadField) {
  EvaluationOptions options;
  EXPECT_NO_THROW(options.Validate());
  options.association.max_diff_ns = -1;
  ExpectOptionError([&] { options.Validate(); }, "AssociationOptions", "max_diff_ns");
  options = {};
  options.alignment.n_align = 5;  // without a method
  ExpectOptionError([&] { options.Validate(); }, "AlignmentOptions", "n_align");
  options.alignment.n_align = -1;
  options.alignment.method = AlignmentMethod::kSE3;
  ExpectOptionError([&] { options.Validate(); }, "AlignmentOptions", "n_align");
  options = {};
  options.pose_only = true;
  options.estimate_velocity_body_frame = true;
  ExpectOptionError([&] { options.Validate(); }, "EvaluationOptions", "pose_only");
  options = {};
  options.continuous_reference = true;
  options.reference_velocity = ReferenceVelocitySource::kGiven;
  ExpectOptionError([&] { options.Validate(); }, "EvaluationOptions", "continuous_reference");
  // The RPE's δ is checked for RPE only.
  options = {};
  options.rpe.delta = 1.5;  // not a whole number of frames
  EXPECT_NO_THROW(options.Validate());
  options.metric = MetricKind::kRpe;
  ExpectOptionError([&] { options.Validate(); }, "RpeOptions", "delta");
  options.rpe.delta_unit = DeltaUnit::kDegrees;
  EXPECT_NO_THROW(options.Validate());
  options.rpe.delta = 181;
  ExpectOptionError([&] { options.Validate(); }, "RpeOptions", "delta");
  // Evaluate validates before any work.
  const traj::Trajectory ref = MakeTrajectory(Helix(10));
  ExpectOptionError([&] { Evaluate(ref.View(), ref.View(), options); }, "RpeOptions", "delta");
}

TEST(EvaluateTest, AssociationFromSecondsRoundsToNanosecondsAndReadsBack) {
  const AssociationOptions a = AssociationOptions::FromSeconds(0.02, -1.5);
  EXPECT_EQ(a.max_diff_ns, 20'000'000);
  EXPECT_EQ(a.offset_ns, -1'500'000'000);
  // ns / 1e9 is the double nearest to the decimal: the seconds given, exactly.
  EXPECT_EQ(a.max_diff_s(), 0.02);
  EXPECT_EQ(a.offset_s(), -1.5);
  EXPECT_EQ(AssociationOptions{}.max_diff_s(), 0.01);
  ExpectOptionError([] { (void)AssociationOptions::FromSeconds(std::nan(""), 0); }, "AssociationOptions",
                    "max_diff_ns");
  ExpectOptionError([] { (void)AssociationOptions::FromSeconds(0.01, 1e12); }, "AssociationOptions", "offset_ns");
}

TEST(EvaluateTest, JsonAndErrorsCsvRepeatTheResult) {
  const traj::Trajectory ref = MakeTrajectory(Helix(50));
  const traj::Trajectory est = MakeTrajectory(Moved(Helix(50), Eigen::Quaterniond::Identity(), {0, 0, 0.25}));
  EvaluationReport report;
  report.reference_path = "ref.txt";
  report.reference_poses = ref.size();
  report.estimate_path = "est.txt";
  report.estimate_poses = est.size();
  report.options.association = AssociationOptions::FromSeconds(0.02, 0.0);
  report.result = Evaluate(ref.View(), est.View(), report.options);
  const nlohmann::json j = nlohmann::json::parse(EvaluationJson(std::span<const EvaluationReport>(&report, 1)));
  EXPECT_EQ(j["command"], "ape");
  EXPECT_EQ(j["association"]["max_diff"].get<double>(), 0.02);
  EXPECT_EQ(j["association"]["pairs"], 50);
  EXPECT_EQ(j["association"]["method"], "nearest");
  EXPECT_EQ(j["alignment"]["method"], "none");
  EXPECT_NEAR(j["stats"]["rmse"].get<double>(), 0.25, 1e-12);
  EXPECT_EQ(j["stats"]["n"], 50);

  const std::string csv = EvaluationErrorsCsv(std::span<const EvaluationReport>(&report, 1));
  EXPECT_EQ(csv.substr(0, csv.find('\n')), "stamp,error");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 51);
  EXPECT_EQ(csv.substr(csv.find('\n') + 1, 18), "1.000000000,0.25\n1");
  // Two reports: the estimate names each row.
  const std::vector<EvaluationReport> two = {report, report};
  const std::string both = EvaluationErrorsCsv(two);
  EXPECT_EQ(both.substr(0, both.find('\n')), "estimate,stamp,error");
  EXPECT_EQ(std::count(both.begin(), both.end(), '\n'), 101);
  EXPECT_EQ(both.substr(both.find('\n') + 1, 8), "est.txt,");
}

// Issue 13: a file name with a comma or a quote broke the CSV's columns. RFC 4180: such a field is
// quoted, inner quotes doubled; a plain name stays as it is.
TEST(EvaluateTest, ErrorsCsvQuotesEstimateNamesAsRfc4180) {
  const traj::Trajectory ref = MakeTrajectory(Helix(5));
  const traj::Trajectory est = MakeTrajectory(Moved(Helix(5), Eigen::Quaterniond::Identity(), {0, 0, 0.25}));
  EvaluationReport report;
  report.options.association = AssociationOptions::FromSeconds(0.02, 0.0);
  report.result = Evaluate(ref.View(), est.View(), report.options);
  std::vector<EvaluationReport> reports = {report, report, report};
  reports[0].estimate_path = "run 1,2.txt";
  reports[1].estimate_path = "say \"hi\".txt";
  reports[2].estimate_path = "plain.txt";
  const std::string csv = EvaluationErrorsCsv(reports);
  std::vector<std::string> lines;
  for (size_t begin = 0, end; (end = csv.find('\n', begin)) != std::string::npos; begin = end + 1) {
    lines.push_back(csv.substr(begin, end - begin));
  }
  ASSERT_EQ(lines.size(), 16u);
  EXPECT_EQ(lines[1], "\"run 1,2.txt\",1.000000000,0.25");
  EXPECT_EQ(lines[6], "\"say \"\"hi\"\".txt\",1.000000000,0.25");
  EXPECT_EQ(lines[11], "plain.txt,1.000000000,0.25");
}

// Issue 13: coordinates of 1e300 gave inf errors, "std -nan", JSON nulls and exit 0. Every non-finite
// result is a ComputeError saying what and why.
TEST(EvaluateTest, ANonFiniteResultIsAComputeErrorNamingThePairAndTheReason) {
  auto scaled = [](double factor) {
    std::vector<PoseSpec> poses = Helix(50);
    for (PoseSpec& s : poses) s.p *= factor;
    return MakeTrajectory(poses, true);
  };
  const traj::Trajectory est = MakeTrajectory(Helix(50), true);
  auto message = [&](const traj::Trajectory& ref, MetricKind metric, AlignmentMethod align) -> std::string {
    EvaluationOptions options;
    options.metric = metric;
    options.alignment.method = align;
    options.association = AssociationOptions::FromSeconds(0.02, 0.0);
    try {
      const EvaluationResult r = Evaluate(ref.View(), est.View(), options);
      return "no error, rmse " + std::to_string(r.stats.rmse) + " std " + std::to_string(r.stats.std);
    } catch (const ComputeError& e) {
      return e.what();
    }
  };
  // An error overflows (|p| ~ 1e300 squared).
  const traj::Trajectory huge = scaled(1e300);
  for (const MetricKind metric : {MetricKind::kApe, MetricKind::kRpe, MetricKind::kAse}) {
    const std::string m = message(huge, metric, AlignmentMethod::kNone);
    SCOPED_TRACE(m);
    const std::string label = metric == MetricKind::kApe ? "APE" : metric == MetricKind::kRpe ? "RPE" : "ASE";
    EXPECT_EQ(m.rfind("the " + label + " of pair ", 0), 0u);
    EXPECT_NE(m.find("(estimate stamp 1.0"), std::string::npos);
    EXPECT_NE(m.find("not a finite number: the coordinates are too large"), std::string::npos);
  }
  // Each error is finite (~3e153) but their sum of squares is not.
  const std::string sse = message(scaled(3e153), MetricKind::kApe, AlignmentMethod::kNone);
  EXPECT_EQ(sse.rfind("the APE rmse is inf, not a finite number", 0), 0u) << sse;
  // An alignment solved on such coordinates.
  const std::string aligned = message(huge, MetricKind::kApe, AlignmentMethod::kSim3);
  EXPECT_TRUE(aligned.rfind("the sim3 alignment is ", 0) == 0 || aligned.rfind("the APE of pair", 0) == 0) << aligned;
  EXPECT_NE(aligned.find("not a finite number"), std::string::npos) << aligned;
  // Large but computable coordinates still evaluate.
  EXPECT_EQ(message(scaled(1e100), MetricKind::kApe, AlignmentMethod::kNone).rfind("no error", 0), 0u);
}

TEST(EvaluateTest, NamesOfTheEnumsRoundTrip) {
  for (ReferenceVelocitySource s : {ReferenceVelocitySource::kAuto, ReferenceVelocitySource::kGiven,
                                    ReferenceVelocitySource::kChebyshev, ReferenceVelocitySource::kCentral}) {
    EXPECT_EQ(ReferenceVelocitySourceFromString(ToString(s)), s);
  }
  // evo's letters of the RPE's δ unit, as both faces take them.
  EXPECT_EQ(DeltaUnitFromString("f"), DeltaUnit::kFrames);
  EXPECT_EQ(DeltaUnitFromString("m"), DeltaUnit::kMeters);
  EXPECT_EQ(DeltaUnitFromString("d"), DeltaUnit::kDegrees);
  EXPECT_EQ(DeltaUnitFromString("r"), DeltaUnit::kRadians);
  EXPECT_EQ(DeltaUnitFromString("meters"), DeltaUnit::kMeters);
  EXPECT_EQ(DeltaUnitFromString("x"), std::nullopt);
  EXPECT_EQ(DeltaUnitFromString("m2"), std::nullopt);
}

}  // namespace
}  // namespace cheval::eval
