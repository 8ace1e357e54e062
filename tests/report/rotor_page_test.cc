// The rotor-speed page of `cheval estimate rotors --report` (include/cheval/report/rotor_page.h): its
// data holds the four motors' estimated, measured and baseline speeds equal to the estimate's (in
// rpm, to the page's 6 significant digits), decimated within max_points with every extreme kept,
// the error table's numbers, the spans outside the scored samples; the page around it is
// self-contained and names files without folders.
#include "cheval/report/rotor_page.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cheval/common/error.h"

namespace cheval::report {
namespace {

using Json = nlohmann::json;
constexpr double kRpm = 30.0 / std::numbers::pi;
constexpr double kDt = 0.01;
const char* const kColumns[] = {"estimated", "measured", "baseline"};

// Speed of motor m, column c (0 estimated, 1 measured, 2 baseline) at sample i, rad/s: smooth, with
// a spike every 997 samples that a stride would lose.
double Speed(size_t i, int m, int c) {
  return 1700.0 + 100.0 * m + 10.0 * c + 200.0 * std::sin(0.003 * static_cast<double>(i) + m + 0.5 * c) +
         (i % 997 == 13 ? 400.0 * (c + 1) : 0.0);
}

// An estimate of n samples at 100 Hz, scored in [first_scored, last_scored).
estim::RotorEstimate Estimate(size_t n, size_t first_scored, size_t last_scored) {
  estim::RotorEstimate e;
  e.error.rpm = {101, 102, 103, 104};
  e.error.percent = {1.5, 2.5, 3.5, 4.5};
  e.baseline.rpm = {201, 202, 203, 204};
  e.baseline.percent = {5.25, 6.25, 7.25, 8.25};
  e.duration_s = static_cast<double>(n - 1) * kDt;
  e.scored_samples = static_cast<int>(last_scored - first_scored);
  for (size_t i = 0; i < n; ++i) {
    estim::RotorStateEstimate s;
    s.t = 3.0 + static_cast<double>(i) * kDt;
    s.p.setZero();
    s.v.setZero();
    s.w.setZero();
    s.q.setIdentity();
    for (int m = 0; m < 4; ++m) {
      s.rotor[m] = Speed(i, m, 0);
      s.measured[m] = Speed(i, m, 1);
      s.baseline[m] = Speed(i, m, 2);
    }
    s.scored = i >= first_scored && i < last_scored;
    e.samples.push_back(s);
  }
  return e;
}

// The page's values have 6 significant digits: half a unit of the sixth digit of `expected`.
double Rounding(double expected) { return 0.5 * std::pow(10.0, std::floor(std::log10(std::abs(expected))) - 5); }

size_t IndexOf(double t) { return static_cast<size_t>(std::lround((t - 3.0) / kDt)); }

Json Data(const estim::RotorEstimate& e, size_t max_points) {
  RotorPageOptions options;
  options.max_points = max_points;
  options.flight_path = "/secret/folder/square.csv";
  options.vehicle_path = "/secret/folder/cf.json";
  return Json::parse(RotorPageData(e, options));
}

TEST(RotorPageTest, ShortFlightEverySampleEqualToTheEstimate) {
  const estim::RotorEstimate e = Estimate(300, 50, 250);
  const Json data = Data(e, 5000);
  EXPECT_EQ(data["page"], "rotors");
  EXPECT_EQ(data["flight"], "square.csv");
  EXPECT_EQ(data["vehicle"], "cf.json");
  EXPECT_EQ(data["samples"], 300);
  EXPECT_EQ(data["scored_samples"], 200);
  for (int m = 0; m < 4; ++m) {
    EXPECT_EQ(data["error"]["rpm"][m].get<double>(), e.error.rpm[m]);
    EXPECT_EQ(data["error"]["percent"][m].get<double>(), e.error.percent[m]);
    EXPECT_EQ(data["baseline"]["rpm"][m].get<double>(), e.baseline.rpm[m]);
    EXPECT_EQ(data["baseline"]["percent"][m].get<double>(), e.baseline.percent[m]);
  }
  ASSERT_EQ(data["motors"].size(), 4u);
  for (int m = 0; m < 4; ++m) {
    const Json& motor = data["motors"][m];
    EXPECT_EQ(motor["name"], "m" + std::to_string(m + 1));
    const Json& s = motor["series"];
    EXPECT_EQ(s["n"], 300);
    ASSERT_EQ(s["t"].size(), 300u);
    for (size_t i = 0; i < 300; ++i) {
      EXPECT_DOUBLE_EQ(s["t"][i].get<double>(), e.samples[i].t);
      for (int c = 0; c < 3; ++c) {
        const double expected = Speed(i, m, c) * kRpm;
        EXPECT_NEAR(s[kColumns[c]][i].get<double>(), expected, Rounding(expected)) << m << " " << c << " " << i;
      }
    }
  }
  // The runs outside the scored samples, reaching to their scored neighbours.
  const Json& unscored = data["unscored"];
  ASSERT_EQ(unscored.size(), 2u);
  EXPECT_DOUBLE_EQ(unscored[0][0].get<double>(), e.samples[0].t);
  EXPECT_DOUBLE_EQ(unscored[0][1].get<double>(), e.samples[50].t);
  EXPECT_DOUBLE_EQ(unscored[1][0].get<double>(), e.samples[249].t);
  EXPECT_DOUBLE_EQ(unscored[1][1].get<double>(), e.samples[299].t);
}

TEST(RotorPageTest, LongFlightDecimatedWithinBoundsKeepingExtremes) {
  const size_t n = 60'000;  // ten minutes at 100 Hz
  const estim::RotorEstimate e = Estimate(n, 50, n - 50);
  for (const size_t max_points : {16u, 500u, 5000u}) {
    const Json data = Data(e, max_points);
    for (int m = 0; m < 4; ++m) {
      const Json& s = data["motors"][m]["series"];
      EXPECT_EQ(s["n"], n);
      const size_t kept = s["t"].size();
      EXPECT_LE(kept, max_points);
      // (max_points − 2) / 6 buckets (3 columns), each keeping at least a smallest and a largest sample.
      EXPECT_GE(kept, 2 * ((max_points - 2) / 6));
      EXPECT_EQ(IndexOf(s["t"][0].get<double>()), 0u);
      EXPECT_EQ(IndexOf(s["t"][kept - 1].get<double>()), n - 1);
      for (int c = 0; c < 3; ++c) {
        double top = -1e300, bottom = 1e300, top_in = -1e300, bottom_in = 1e300;
        for (size_t i = 0; i < n; ++i) {
          top_in = std::max(top_in, Speed(i, m, c) * kRpm);
          bottom_in = std::min(bottom_in, Speed(i, m, c) * kRpm);
        }
        for (size_t k = 0; k < kept; ++k) {
          if (k > 0) {
            ASSERT_LT(s["t"][k - 1].get<double>(), s["t"][k].get<double>());
          }
          // Every plotted point is the sample at its time.
          const double v = s[kColumns[c]][k].get<double>();
          const double expected = Speed(IndexOf(s["t"][k].get<double>()), m, c) * kRpm;
          ASSERT_NEAR(v, expected, Rounding(expected)) << max_points << " " << m << " " << c << " " << k;
          top = std::max(top, v);
          bottom = std::min(bottom, v);
        }
        EXPECT_NEAR(top, top_in, Rounding(top_in)) << "the largest speed (a spike) is plotted";
        EXPECT_NEAR(bottom, bottom_in, Rounding(bottom_in)) << "the smallest speed is plotted";
      }
    }
  }
}

TEST(RotorPageTest, BadOptionsAndEmptyEstimate) {
  const estim::RotorEstimate e = Estimate(100, 10, 90);
  EXPECT_THROW(Data(e, 15), OptionError);
  EXPECT_THROW(Data(estim::RotorEstimate{}, 5000), ComputeError);
}

TEST(RotorPageTest, SelfContainedPageWithoutFolders) {
  RotorPageOptions options;
  options.flight_path = "/secret/folder/square.csv";
  options.vehicle_path = "/secret/folder/cf.json";
  const estim::RotorEstimate e = Estimate(300, 50, 250);
  if (!ReportPageAvailable()) {
    EXPECT_THROW(RotorPageHtml(e, options), UsageError);
    return;
  }
  const std::string page = RotorPageHtml(e, options);
  EXPECT_NE(page.find("<title>cheval estimate rotors: square.csv with cf.json</title>"), std::string::npos);
  EXPECT_NE(page.find(R"("page":"rotors")"), std::string::npos);
  EXPECT_NE(page.find("id=\"motors\""), std::string::npos) << "the rotor page's template";
  EXPECT_NE(page.find("'rotor-' + motor.name"), std::string::npos) << "the rotor page's script";
  EXPECT_EQ(page.find("{{"), std::string::npos) << "every marker replaced";
  EXPECT_EQ(page.find("/secret/folder"), std::string::npos);
  EXPECT_EQ(page.find(" src="), std::string::npos) << "nothing loaded from elsewhere";
  EXPECT_EQ(page.find("<link"), std::string::npos);
  size_t scripts = 0;
  for (size_t at = page.find("<script"); at != std::string::npos; at = page.find("<script", at + 1)) ++scripts;
  EXPECT_EQ(scripts, 3u) << "data, chart library, page script";
}

}  // namespace
}  // namespace cheval::report
