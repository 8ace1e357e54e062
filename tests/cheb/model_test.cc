// The pseudo-spectral model of a trajectory (cheb/model.h) and compression to a tolerance
// (cheb/compress.h): values at the Chebyshev points, bit-identical JSON round trips, the
// reconstruction error on noise-free and noisy synthetic motion, the tolerance met when it can be
// and an error when not, sampling stamps and gaps, and every malformed model file with its message.
#include "cheval/cheb/model.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "cheval/cheb/compress.h"
#include "cheval/common/error.h"
#include "cheval/sim/motion.h"

namespace cheval::cheb {
namespace {

struct Samples {
  std::vector<int64_t> stamps;
  Eigen::MatrixXd positions;  // m x 3
};

Samples FromTrajectory(const traj::Trajectory& trajectory) {
  return {{trajectory.stamps_ns().begin(), trajectory.stamps_ns().end()}, trajectory.positions().transpose()};
}

sim::MotionModel Motion(sim::MotionKind kind, double duration_s) {
  sim::MotionOptions options;
  options.kind = kind;
  options.seed = 1;
  options.duration_s = duration_s;
  return sim::MotionModel(options);
}

// The simulator's drone (figure-eight, up to 8 m/s, 200 Hz) with position noise σ and optional gaps.
Samples Drone(double duration_s, double noise_m, int gaps = 0) {
  sim::MeasurementOptions measurement;
  measurement.noise_m = noise_m;
  measurement.gap_count = gaps;
  measurement.gap_s = gaps > 0 ? 0.5 : 0.0;
  return FromTrajectory(sim::Measure(Motion(sim::MotionKind::kDrone, duration_s), measurement));
}

// Every stamp of the samples and many stamps between them (not sample stamps).
std::vector<int64_t> DenseStamps(const TrajectoryModel& model) {
  std::vector<int64_t> stamps;
  for (const ModelSegment& segment : model.segments) {
    for (int64_t s = segment.first_ns; s <= segment.last_ns; s += 1'234'567) stamps.push_back(s);
    stamps.push_back(segment.last_ns);
  }
  return stamps;
}

TEST(TrajectoryModel, ValuesAreTheWindowPolynomialAtItsChebyshevPointsDescendingInTime) {
  const Samples s = Drone(60.0, 0.0005);
  const Curve curve = FitCurve(s.stamps, s.positions);
  const TrajectoryModel model = ModelFromCurve(curve);
  ASSERT_EQ(model.dimension, 3);
  ASSERT_EQ(model.segments.size(), curve.segments().size());
  ASSERT_GE(curve.segments()[0].windows.size(), 3u);  // a middle window, with overlap on both sides
  const CurveWindow& fitted = curve.segments()[0].windows[1];
  const ModelWindow& stored = model.segments[0].windows[1];
  EXPECT_EQ(stored.core_begin, fitted.core_begin);
  EXPECT_EQ(stored.fit_end, fitted.fit_end);
  for (size_t c = 0; c < 3; ++c) {
    const int n = fitted.degrees[c];
    ASSERT_EQ(stored.degree(c), n);
    for (int j = 0; j <= n; ++j) {
      // t_j = FromUnit(cos(jπ/N)): j = 0 is the end of the fit interval. The DCT and Clenshaw agree
      // to rounding: a few ulps of the largest value (positions of tens of metres -> 1e-13 m).
      const double t = fitted.series.interval.FromUnit(std::cos(std::numbers::pi * j / n));
      EXPECT_NEAR(stored.values[c][j], fitted.series.Value(t)[static_cast<Eigen::Index>(c)], 1e-12) << c << " " << j;
    }
  }
  // Segment stamps are the first and last sample's, exactly.
  EXPECT_EQ(model.segments[0].first_ns, s.stamps.front());
  EXPECT_EQ(model.segments[0].last_ns, s.stamps.back());
  // The model's curve is the fitted curve up to the DCT round trip (~1e-15 relative).
  Eigen::MatrixXd a, b;
  curve.EvaluateMany(s.stamps, 0, &a);
  CurveFromModel(model).EvaluateMany(s.stamps, 0, &b);
  EXPECT_LT((a - b).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(TrajectoryModel, JsonRoundTripEvaluatesBitIdentically) {
  // Two gaps: three segments.
  const Samples s = Drone(20.0, 0.0005, 2);
  const Compression compressed = Compress(s.stamps, s.positions);
  ASSERT_EQ(compressed.model.segments.size(), 3u);
  const std::string text = WriteModelJson(compressed.model);
  const TrajectoryModel read = ParseModelJson(text, "model.json");
  EXPECT_EQ(WriteModelJson(read), text);  // and the text is a fixed point
  const std::vector<int64_t> stamps = DenseStamps(compressed.model);
  Eigen::MatrixXd original, back;
  CurveFromModel(compressed.model).EvaluateMany(stamps, 0, &original);
  CurveFromModel(read).EvaluateMany(stamps, 0, &back);
  ASSERT_EQ(original.rows(), static_cast<Eigen::Index>(stamps.size()));
  EXPECT_TRUE((original.array() == back.array()).all());
  ASSERT_TRUE(read.reconstruction.has_value());
  EXPECT_EQ(read.reconstruction->max, compressed.error.max);
  EXPECT_EQ(read.reconstruction->worst_stamp_ns, compressed.error.worst_stamp_ns);
  EXPECT_EQ(read.noise_sigma, compressed.model.noise_sigma);
  EXPECT_FALSE(read.tolerance.has_value());
}

// Random byte mutations of a written model: each is refused with an InputError or evaluates to
// bit-identical samples. Before the checksum, 26 of 150 such mutations were accepted, two of them
// moving positions by 1e7 m and 1e30 m.
TEST(ModelJson, EveryByteMutationIsRefusedOrHarmless) {
  const Samples s = Drone(4.0, 0.0005, 1);
  const TrajectoryModel model = Compress(s.stamps, s.positions).model;
  const std::string text = WriteModelJson(model);
  const std::vector<int64_t> stamps = DenseStamps(model);
  Eigen::MatrixXd original;
  CurveFromModel(model).EvaluateMany(stamps, 0, &original);
  std::mt19937_64 random(13);
  int refused = 0, accepted = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    std::string mutated = text;
    const int bytes = 1 + trial % 3;  // one, two or three bytes
    for (int b = 0; b < bytes; ++b) {
      const size_t at = random() % mutated.size();
      // Half the time a digit (the mutations that change a number), else any byte.
      mutated[at] = trial % 2 == 0 ? static_cast<char>('0' + random() % 10) : static_cast<char>(random() % 256);
    }
    if (mutated == text) continue;
    TrajectoryModel read;
    try {
      read = ParseModelJson(mutated, "m.json");
    } catch (const InputError& e) {
      ASSERT_EQ(std::string(e.what()).rfind("m.json:", 0), 0u) << e.what();
      ++refused;
      continue;
    }
    ++accepted;
    Eigen::MatrixXd back;
    try {
      CurveFromModel(read).EvaluateMany(stamps, 0, &back);
    } catch (const ComputeError& e) {
      ADD_FAILURE() << "an accepted mutation does not cover the model's stamps: " << e.what();
      continue;
    }
    ASSERT_TRUE((back.array() == original.array()).all()) << "mutation " << trial << " accepted with other samples";
  }
  EXPECT_GT(refused, 2500);
  // Layout is not covered by the checksum, only the numbers: whitespace added between tokens is
  // accepted and harmless. Checked directly: a random mutation makes such a change only by chance
  // (3 of the 3000 on a release build, none on the sanitizer build of 2026-12-05).
  std::string relaid = text;
  relaid.insert(relaid.find('{') + 1, "\n \t ");
  TrajectoryModel read;
  ASSERT_NO_THROW(read = ParseModelJson(relaid, "m.json"));
  Eigen::MatrixXd back;
  CurveFromModel(read).EvaluateMany(stamps, 0, &back);
  EXPECT_TRUE((back.array() == original.array()).all());
  RecordProperty("accepted_mutations", accepted);
}

std::string SmallModel();  // below

// The checksum covers the numbers, not the layout: a reformatted model reads; a changed number in it
// does not ("checksum mismatch"); a model written before the checksum (version 1) still reads.
TEST(ModelJson, ChecksumCoversTheNumbersNotTheLayout) {
  const TrajectoryModel model = ParseModelJson(SmallModel(), "m.json");
  const std::string text = WriteModelJson(model);
  EXPECT_NE(text.find("\"version\": 2,"), std::string::npos) << text;
  EXPECT_NE(text.find(fmt::format("\"checksum\": \"fnv1a64:{:016x}\"", ModelChecksum(model))), std::string::npos)
      << text;
  std::string flat;
  for (char c : text) {
    if (c != '\n' && c != ' ') flat += c;
  }
  EXPECT_EQ(WriteModelJson(ParseModelJson(flat, "m.json")), text);
  std::string changed = text;
  changed.replace(changed.find("[1.25, 0]"), 9, "[1.25, 1]");
  try {
    ParseModelJson(changed, "m.json");
    ADD_FAILURE() << "a changed value was accepted";
  } catch (const InputError& e) {
    const std::string expected = "m.json:0:0: error: checksum: checksum mismatch: the file says \"fnv1a64:";
    EXPECT_EQ(std::string(e.what()).rfind(expected, 0), 0u)
        << e.what();
  }
  // Any change of a stored number changes the checksum, even the sign of a zero.
  TrajectoryModel other = model;
  other.segments[0].windows[0].values[0][2] = -0.0;
  EXPECT_NE(ModelChecksum(other), ModelChecksum(model));
  other = model;
  other.origin_ns += 1;
  EXPECT_NE(ModelChecksum(other), ModelChecksum(model));
}

TEST(ModelJson, ADirectoryIsAnInputError) {
  const std::string dir = ::testing::TempDir();
  try {
    ReadModel(dir);
    ADD_FAILURE() << "a directory was read as a model";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(":0:0: error: is a directory; expected a model JSON file from cheval "
                                         "compress"),
              std::string::npos)
        << e.what();
  }
}

TEST(TrajectoryModel, CountsWhatItStores) {
  const Samples s = Drone(10.0, 0.0005);
  const Compression c = Compress(s.stamps, s.positions);
  Eigen::Index values = 0, windows = 0;
  for (const ModelSegment& segment : c.model.segments) {
    for (const ModelWindow& w : segment.windows) {
      ++windows;
      for (size_t k = 0; k < 3; ++k) values += w.degree(k) + 1;
    }
  }
  EXPECT_EQ(ModelValueCount(c.model), values);
  EXPECT_EQ(ModelNumberCount(c.model),
            values + 4 * windows + 2 * static_cast<Eigen::Index>(c.model.segments.size()) + 1);
  EXPECT_EQ(c.input_numbers, 3 * static_cast<Eigen::Index>(s.stamps.size()));
  EXPECT_DOUBLE_EQ(c.ratio, static_cast<double>(c.input_numbers) / static_cast<double>(c.model_numbers));
  EXPECT_EQ(c.error.samples, static_cast<Eigen::Index>(s.stamps.size()));
}

TEST(Compress, NoiseFreeMotionIsReconstructedToNanometres) {
  // Exact positions of every simulated kind: what is left is the chopped tail of the series. Measured
  // max errors 2.8e-10 (legged) to 1.5e-7 m (car, 100 s at 15 m/s): 1 µm bounds all with margin,
  // and RMS sits at a third of the max.
  for (const sim::MotionKind kind :
       {sim::MotionKind::kCar, sim::MotionKind::kLegged, sim::MotionKind::kDrone, sim::MotionKind::kHandheld}) {
    const sim::MotionModel motion = Motion(kind, sim::DefaultsFor(kind).duration_s);
    const Samples s = FromTrajectory(sim::GenerateMotion(motion));
    const Compression c = Compress(s.stamps, s.positions);
    EXPECT_LT(c.error.max, 1e-6) << sim::ToString(kind);
    EXPECT_LT(c.error.rms, 0.5 * c.error.max) << sim::ToString(kind);
    EXPECT_GT(c.ratio, 4.0) << sim::ToString(kind);
  }
}

// A short noisy recording (1 s of hand-held motion at 100 Hz under 0.5 mm, seeds 1–4) is one window,
// and its model stores that window alone: the end caps that serve the velocity of such a recording
// ("End caps", short segments) would store its positions in 2.5x the numbers for the same error.
TEST(Compress, AShortRecordingIsOneWindow) {
  for (uint64_t seed = 1; seed <= 4; ++seed) {
    sim::MotionOptions motion;
    motion.kind = sim::MotionKind::kHandheld;
    motion.seed = seed;
    motion.duration_s = 1.0;
    sim::MeasurementOptions measurement;
    measurement.noise_m = 5e-4;
    const Samples s = FromTrajectory(sim::Measure(sim::MotionModel(motion), measurement));
    const Compression c = Compress(s.stamps, s.positions);
    ASSERT_EQ(c.model.segments.size(), 1u);
    EXPECT_EQ(c.model.segments[0].windows.size(), 1u) << "seed " << seed;
  }
}

TEST(Compress, ToleranceIsMetAndSpentWhenAchievable) {
  const Samples s = Drone(30.0, 0.0005);
  const Compression automatic = Compress(s.stamps, s.positions);
  // With σ = 0.5 mm per axis the largest of 6001 3-D errors is about 4σ = 2 mm, even for the truth.
  EXPECT_GT(automatic.error.max, 0.0015);
  EXPECT_LT(automatic.error.max, 0.003);
  double previous_ratio = 0.0;
  for (const double tolerance : {0.0025, 0.005, 0.02}) {
    CompressOptions options;
    options.tolerance = tolerance;
    const Compression c = Compress(s.stamps, s.positions, options);
    EXPECT_LE(c.error.max, tolerance);
    EXPECT_EQ(*c.model.tolerance, tolerance);
    EXPECT_FALSE(c.automatic);  // a tolerance above the automatic error buys a smaller model
    EXPECT_GT(c.ratio, automatic.ratio);
    EXPECT_GT(c.ratio, previous_ratio);  // looser: smaller
    previous_ratio = c.ratio;
  }
}

TEST(Compress, ToleranceBelowTheAutomaticErrorRefinesWithinTheConditioningLimit) {
  // Noise-free drone: the automatic fit is within ~1e-8 m; 1e-9 needs higher degrees. With the
  // degree capped at 12, the windows must shrink until degree 12 (and N²/m <= 8) meets it.
  const Samples s = FromTrajectory(sim::GenerateMotion(Motion(sim::MotionKind::kDrone, 10.0)));
  CompressOptions options;
  options.tolerance = 1e-9;
  const Compression fine = Compress(s.stamps, s.positions, options);
  EXPECT_LE(fine.error.max, 1e-9);
  options.curve.max_degree = 12;
  const Compression capped = Compress(s.stamps, s.positions, options);
  EXPECT_LE(capped.error.max, 1e-9);
  size_t windows = 0;
  for (const ModelSegment& segment : capped.model.segments) {
    for (const ModelWindow& w : segment.windows) {
      ++windows;
      const auto in_fit = std::count_if(s.stamps.begin(), s.stamps.end(), [&](int64_t stamp) {
        const double t = static_cast<double>(stamp - capped.model.origin_ns) * 1e-9;
        return t >= w.fit_begin && t <= w.fit_end;
      });
      for (size_t k = 0; k < 3; ++k) {
        EXPECT_LE(w.degree(k), 12);
        EXPECT_LE(w.degree(k) * w.degree(k), 8 * in_fit);
      }
    }
  }
  size_t uncapped = 0;
  for (const ModelSegment& segment : fine.model.segments) uncapped += segment.windows.size();
  EXPECT_GT(windows, uncapped);
}

TEST(Compress, ToleranceBelowTheNoiseIsAnErrorThatSaysWhatCanBeReached) {
  const Samples s = Drone(10.0, 0.0005);
  CompressOptions options;
  options.tolerance = 0.001;
  try {
    Compress(s.stamps, s.positions, options);
    FAIL() << "a tolerance of 2σ cannot be met";
  } catch (const ComputeError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.rfind("cannot meet the tolerance of 0.001 m: the most accurate model cheval can build from these "
                            "samples (N^2/m <= 8 and degree <= 400 per window, windows down to 24 samples) has a max "
                            "error of 0.00",
                            0),
              0u)
        << message;
    EXPECT_NE(message.find("a smaller max error means following the noise"), std::string::npos) << message;
  }
}

TEST(Compress, TooFewSamplesEqualStampsAndBadTolerances) {
  const Eigen::MatrixXd one = Eigen::MatrixXd::Zero(1, 3);
  try {
    Compress(std::vector<int64_t>{5}, one);
    FAIL();
  } catch (const ComputeError& e) {
    EXPECT_STREQ(e.what(), "a fit needs at least 2 samples, got 1");
  }
  const Eigen::MatrixXd three = Eigen::MatrixXd::Random(3, 3);
  try {
    Compress(std::vector<int64_t>{7, 7, 7}, three);
    FAIL();
  } catch (const ComputeError& e) {
    EXPECT_STREQ(e.what(), "all 3 stamps are equal: there is no time to fit over");
  }
  const std::pair<double, const char*> bad_tolerances[] = {
      {0.0, "0"}, {-1.0, "-1"}, {std::nan(""), "nan"}, {std::numeric_limits<double>::infinity(), "inf"}};
  for (const auto& [bad, text] : bad_tolerances) {
    CompressOptions options;
    options.tolerance = bad;
    try {
      Compress(std::vector<int64_t>{1, 2, 3}, three, options);
      FAIL() << bad;
    } catch (const OptionError& e) {
      EXPECT_EQ(e.field(), "tolerance");
      EXPECT_EQ(std::string(e.what()),
                std::string("CompressOptions::tolerance must be a positive number of metres, got ") + text);
    }
  }
  // The curve options are validated too, before any work.
  CompressOptions bad_curve;
  bad_curve.curve.min_window_samples = 1;
  try {
    Compress(std::vector<int64_t>{1, 2, 3}, three, bad_curve);
    FAIL();
  } catch (const OptionError& e) {
    EXPECT_STREQ(e.what(), "CurveOptions::min_window_samples must be at least 2, got 1");
  }
  // Three samples are interpolated: any tolerance is met.
  CompressOptions options;
  options.tolerance = 1e-9;
  EXPECT_LE(Compress(std::vector<int64_t>{0, 1'000'000, 3'000'000}, three, options).error.max, 1e-9);
}

// A small valid model: one segment of 2 s from origin 1e18 ns with two windows of degrees (2, 1, 0)
// and (1, 1, 1), the second coordinate a line through 0 and 2 m.
std::string SmallModel() {
  return R"({"format": "cheval-trajectory-model", "version": 1, "dimension": 3, "origin_ns": 1000000000000000000,
  "segments": [{"first_ns": 1000000000000000000, "last_ns": 1000000002000000000, "windows": [
    {"core": [0, 1], "fit": [0, 1.25], "values": [[1, 0.5, 0], [1.25, 0], [3]]},
    {"core": [1, 2], "fit": [0.75, 2], "values": [[0, 0], [2, 0.75], [3, 3]]}]}]})";
}

// fuzz_model found that a stored -0.0 came back as +0.0 ("-0" reads as the integer 0): the sign of
// every zero survives the round trip now, so the text is a fixed point for every model.
TEST(ModelJson, NegativeZeroKeepsItsSign) {
  TrajectoryModel model = ParseModelJson(SmallModel(), "m.json");
  model.segments[0].windows[0].values[0][2] = -0.0;
  const std::string text = WriteModelJson(model);
  EXPECT_NE(text.find("-0.0"), std::string::npos);
  const TrajectoryModel read = ParseModelJson(text, "m.json");
  EXPECT_TRUE(std::signbit(read.segments[0].windows[0].values[0][2]));
  EXPECT_EQ(WriteModelJson(read), text);
}

TEST(ModelJson, ReadsAHandWrittenModel) {
  const TrajectoryModel model = ParseModelJson(SmallModel(), "m.json");
  EXPECT_EQ(model.origin_ns, 1'000'000'000'000'000'000);
  EXPECT_EQ(ModelValueCount(model), 6 + 6);
  EXPECT_EQ(ModelNumberCount(model), 12 + 8 + 2 + 1);
  Eigen::VectorXd p(3);
  const Curve curve = CurveFromModel(model);
  curve.EvaluateValue(1'000'000'000'500'000'000, p);  // t = 0.5 s, inside the first core only
  // x: values 1, 0.5, 0 at t = 1.25, 0.625, 0 -> the line t / 1.25; y: 1.25 and 0 at 1.25 and 0 -> t.
  EXPECT_NEAR(p[0], 0.4, 1e-15);
  EXPECT_NEAR(p[1], 0.5, 1e-15);
  EXPECT_EQ(p[2], 3.0);
  EXPECT_FALSE(model.reconstruction.has_value());
  EXPECT_EQ(model.noise_sigma.size(), 0);
}

struct BadModel {
  std::string from, to;  // replace the first `from` in SmallModel() by `to`
  std::string message;
};

TEST(ModelJson, EveryMalformedModelIsAnInputErrorNamingTheElement) {
  const std::vector<BadModel> cases = {
      {R"("format": "cheval-trajectory-model")", R"("format": "tum")",
       R"(m.json:0:0: error: format: expected "cheval-trajectory-model", got "tum")"},
      {R"("format": "cheval-trajectory-model", )", "",
       R"(m.json:0:0: error: format: expected "cheval-trajectory-model", got no such key)"},
      {R"("version": 1)", R"("version": 3)",
       "m.json:0:0: error: version: expected 1 or 2 (the versions this cheval reads), got 3"},
      {R"("version": 1)", R"("version": 2)",
       "m.json:0:0: error: checksum: missing; expected \"fnv1a64:<16 hex digits>\" in a version 2 model"},
      {R"("version": 1, )", R"("version": 1, "checksum": "fnv1a64:0000000000000000", )",
       "m.json:0:0: error: checksum: unexpected in a version 1 model (version 1 models have none)"},
      {R"("version": 1, )", "", "m.json:0:0: error: version: missing; expected it in the model"},
      {R"("dimension": 3)", R"("dimension": 5)",
       "m.json:0:0: error: dimension: expected an integer from 1 to 4 (coordinates per sample), got 5"},
      {R"("origin_ns": 1000000000000000000)", R"("origin_ns": 1.5e18)",
       "m.json:0:0: error: origin_ns: expected an integer stamp in nanoseconds, got 1.5e+18"},
      {R"("origin_ns": 1000000000000000000)", R"("origin_ns": 18446744073709551615)",
       "m.json:0:0: error: origin_ns: expected an integer stamp in nanoseconds, got 18446744073709551615"},
      {R"("dimension": 3)", R"("dimension": 3, "segmnets": [])",
       "m.json:0:0: error: model: unknown key \"segmnets\"; expected only format, version, dimension, origin_ns, "
       "noise_sigma, residual_rms, reconstruction, tolerance, segments, checksum"},
      {R"("dimension": 3)", R"("dimension": 3, "noise_sigma": [1, 2])",
       "m.json:0:0: error: noise_sigma: expected an array of 3 non-negative numbers (one per coordinate), got an "
       "array of 2 elements"},
      {R"("dimension": 3)", R"("dimension": 3, "residual_rms": [1, -2, 3])",
       "m.json:0:0: error: residual_rms[1]: expected a finite non-negative number, got -2"},
      {R"("dimension": 3)", R"("dimension": 3, "tolerance": 0)",
       "m.json:0:0: error: tolerance: expected a positive finite number, got 0"},
      {R"("dimension": 3)", R"("dimension": 3, "reconstruction": {"samples": 3, "max_error": 1e999})",
       "m.json:0:0: error: reconstruction.max_error: the number '1e999' is too large for a double (at most 1.8e308 in "
       "magnitude)"},
      {R"("dimension": 3)", R"("dimension": 3, "reconstruction": {"samples": 3, "max_error": -1})",
       "m.json:0:0: error: reconstruction.max_error: expected a finite non-negative number, got -1"},
      {R"("dimension": 3)", R"("dimension": 3, "reconstruction": {"samples": 3, "max_error": 1, "rms_error": 1})",
       "m.json:0:0: error: reconstruction.worst_stamp_ns: missing; expected it in reconstruction"},
      {R"("segments": [{"first_ns")", R"("segments": [], "x": [{"first_ns")",
       "m.json:0:0: error: model: unknown key \"x\"; expected only format, version, dimension, origin_ns, "
       "noise_sigma, residual_rms, reconstruction, tolerance, segments, checksum"},
      {R"("first_ns": 1000000000000000000)", R"("first_ns": 999999999999999999)",
       "m.json:0:0: error: segments[0].first_ns: expected a stamp not before origin_ns (1000000000000000000), got "
       "999999999999999999"},
      {R"("last_ns": 1000000002000000000)", R"("last_ns": 999999999999999999)",
       "m.json:0:0: error: segments[0].last_ns: expected a stamp not before first_ns (1000000000000000000), got "
       "999999999999999999"},
      {R"("last_ns": 1000000002000000000)", R"("last_ns": 9223372036854775807)",
       "m.json:0:0: error: segments[0].last_ns: expected a stamp at most 2^53 ns (about 104 days) after origin_ns "
       "(1000000000000000000), got 9223372036854775807"},
      {R"("windows": [)", R"("windowz": [)",
       "m.json:0:0: error: segments[0]: unknown key \"windowz\"; expected only first_ns, last_ns, windows"},
      {R"("core": [0, 1])", R"("core": [0, 1, 2])",
       "m.json:0:0: error: segments[0].windows[0].core: expected [begin, end], two finite numbers (seconds from "
       "origin_ns) with begin < end, got an array of 3 elements"},
      {R"("core": [0, 1])", R"("core": [1, 1])",
       "m.json:0:0: error: segments[0].windows[0].core: expected [begin, end], two finite numbers (seconds from "
       "origin_ns) with begin < end, got [1,1]"},
      {R"("core": [0, 1])", R"("core": [0.5, 1])",
       "m.json:0:0: error: segments[0].windows[0].core: expected to begin at or before the segment's first stamp "
       "(0 s from origin_ns), got 0.5"},
      {R"("fit": [0, 1.25])", R"("fit": [0.1, 1.25])",
       "m.json:0:0: error: segments[0].windows[0].fit: expected an interval containing core [0, 1], got [0.1, 1.25]"},
      {R"("core": [1, 2])", R"("core": [1.5, 2])",
       "m.json:0:0: error: segments[0].windows[1].core: expected to begin where windows[0].core ends (1), got 1.5"},
      {R"("core": [1, 2])", R"("core": [1, 1.75])",
       "m.json:0:0: error: segments[0].windows[1].core: expected to end at or after the segment's last stamp (2 s "
       "from origin_ns), got 1.75"},
      {R"([[1, 0.5, 0], [1.25, 0], [3]])", R"([[1, 0.5, 0], [1.25, 0]])",
       "m.json:0:0: error: segments[0].windows[0].values: expected an array of 3 arrays (one per coordinate), got an "
       "array of 2 elements"},
      {R"([1.25, 0])", "[]",
       "m.json:0:0: error: segments[0].windows[0].values[1]: expected a non-empty array of finite numbers (the values "
       "at the Chebyshev points), got an array of 0 elements"},
      {R"([1.25, 0])", R"([1.25, "0"])",
       "m.json:0:0: error: segments[0].windows[0].values[1][1]: expected a finite number, got \"0\""},
      {R"("values": [[1, 0.5, 0])", R"("values": [[1, 0.5, null])",
       "m.json:0:0: error: segments[0].windows[0].values[0][2]: expected a finite number, got null"},
      {R"({"format")", R"([{"format")",
       "m.json:4:82: error: expected JSON (a cheval trajectory model): syntax error while parsing array - unexpected "
       "end of input; expected ']'"},
  };
  for (const BadModel& c : cases) {
    std::string text = SmallModel();
    const size_t at = text.find(c.from);
    ASSERT_NE(at, std::string::npos) << c.from;
    text.replace(at, c.from.size(), c.to);
    try {
      ParseModelJson(text, "m.json");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()), c.message) << text;
    }
  }
  const std::vector<std::pair<std::string, std::string>> whole = {
      {"",
       "m.json:1:1: error: expected JSON (a cheval trajectory model): syntax error while parsing value - unexpected "
       "end of input; expected '[', '{', or a literal"},
      {"[1, 2]",
       "m.json:0:0: error: model: expected a JSON object (a cheval trajectory model), got an array of 2 "
       "elements"},
      {R"({"format": "cheval-trajectory-model", "version": 1, "dimension": 3, "origin_ns": 0, "segments": {}})",
       "m.json:0:0: error: segments: expected a non-empty array, got an object"},
  };
  for (const auto& [text, message] : whole) {
    try {
      ParseModelJson(text, "m.json");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()), message) << text;
    }
  }
  try {
    ReadModel("/nonexistent/model.json");
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "/nonexistent/model.json:0:0: error: cannot open file: No such file or directory");
  }
}

TEST(ModelSampling, GridSkipsGapsAndCoverageNamesTheStamp) {
  TrajectoryModel model = ParseModelJson(SmallModel(), "m.json");
  // A second segment after a gap: 3 s .. 4 s (the same windows, halved and shifted by 3 s).
  ModelSegment second = model.segments[0];
  second.first_ns = model.origin_ns + 3'000'000'000;
  second.last_ns = model.origin_ns + 4'000'000'000;
  for (ModelWindow& w : second.windows) {
    w.core_begin = w.core_begin * 0.5 + 3.0;
    w.core_end = w.core_end * 0.5 + 3.0;
    w.fit_begin = w.fit_begin * 0.5 + 3.0;
    w.fit_end = w.fit_end * 0.5 + 3.0;
  }
  model.segments.push_back(second);
  const ModelSegment& first = model.segments[0];
  // 2 Hz: 0, 0.5, 1, 1.5, 2 | gap (2.5) | 3, 3.5, 4.
  const std::vector<int64_t> grid = ModelGridStamps(model, 2.0);
  std::vector<int64_t> expected;
  for (const double t : {0.0, 0.5, 1.0, 1.5, 2.0, 3.0, 3.5, 4.0}) {
    expected.push_back(first.first_ns + std::llround(t * 1e9));
  }
  EXPECT_EQ(grid, expected);
  EXPECT_NO_THROW(CheckModelCovers(model, grid));
  Eigen::MatrixXd positions;
  EXPECT_NO_THROW(CurveFromModel(model).EvaluateMany(grid, 0, &positions));

  const int64_t origin = first.first_ns;
  auto message = [&](int64_t stamp) {
    try {
      CheckModelCovers(model, std::vector<int64_t>{origin, stamp});
    } catch (const ComputeError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message(origin - 1),
            "stamp #2 (999999999.999999999 s) is outside the modelled time range "
            "1000000000.000000000 s to 1000000004.000000000 s");
  EXPECT_EQ(message(origin + 4'000'000'001),
            "stamp #2 (1000000004.000000001 s) is outside the modelled time range "
            "1000000000.000000000 s to 1000000004.000000000 s");
  EXPECT_EQ(message(origin + 2'500'000'000),
            "stamp #2 (1000000002.500000000 s) is inside a gap of the model: no "
            "samples from 1000000002.000000000 s to 1000000003.000000000 s");
  EXPECT_EQ(message(origin + 2'000'000'000), "no error");  // the ends are included

  const std::pair<double, const char*> bad_rates[] = {{0.0, "0"}, {-5.0, "-5"}, {std::nan(""), "nan"}};
  for (const auto& [bad, text] : bad_rates) {
    try {
      ModelGridStamps(model, bad);
      ADD_FAILURE() << bad;
    } catch (const OptionError& e) {
      EXPECT_EQ(std::string(e.what()), std::string("ModelGridStamps::rate_hz must be a positive number of Hz, got ") + text);
    }
  }
  try {
    ModelGridStamps(model, 1e9);
    ADD_FAILURE();
  } catch (const OptionError& e) {
    EXPECT_STREQ(e.what(),
                 "ModelGridStamps::rate_hz must give at most 100000000 stamps over the model's 4.000 s; 1000000000 Hz "
                 "gives 4e+09");
  }
}

}  // namespace
}  // namespace cheval::cheb
