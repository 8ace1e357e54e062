// The report's sections added for papers (docs/report.md), through the executable: labels instead
// of paths; the RPE per distance equal to `cheval rpe` with the same options; the distributions
// from every pair (their box equals the APE's statistics); the ASE rotation part in degrees; the
// paths with time, roll/pitch/yaw and the per-pose error of the top view coloured by error.
#include <cmath>
#include <filesystem>
#include <numbers>
#include <numeric>
#include <string>

#include "report_page.h"

namespace cheval {
namespace {

using testing::Slurp;

// Two estimates of the same file name in different folders: the labels are the file names with
// the folder that tells them apart, and no path of this machine is in the page unless asked.
TEST_F(ReportCliTest, PageNamesFilesByLabelAndHasNoPaths) {
  Simulate(10);
  std::filesystem::create_directories(Path("run1"));
  std::filesystem::create_directories(Path("run2"));
  std::filesystem::copy_file(Path("noisy_v.tumv"), Path("run1/est.tumv"));
  std::filesystem::copy_file(Path("poses.tum"), Path("run2/est.tumv"));
  const auto run = Cheval(fmt::format("report {} {} {} -o {}", Path("mocap.tum"), Path("run1/est.tumv"),
                                      Path("run2/est.tumv"), Path("r.html")));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const std::string page = Slurp(Path("r.html"));
  const std::string folder = std::filesystem::path(Path("r.html")).parent_path().string();
  EXPECT_EQ(page.find(folder), std::string::npos) << "the page contains " << folder;
  const Json data = EmbeddedData(page);
  EXPECT_EQ(data["reference"]["label"], "mocap.tum");
  EXPECT_EQ(data["estimates"][0]["label"], "run1/est.tumv");
  EXPECT_EQ(data["estimates"][1]["label"], "run2/est.tumv");
  EXPECT_EQ(data["estimates"][0]["ape"]["estimate"]["path"], "run1/est.tumv");
  EXPECT_NE(page.find("<title>cheval report: 2 estimate(s) against mocap.tum</title>"), std::string::npos);

  const auto shown = Cheval(fmt::format("report {} {} --show-paths -o {}", Path("mocap.tum"), Path("run1/est.tumv"),
                                        Path("r2.html")));
  ASSERT_EQ(shown.exit_code, 0) << shown.err;
  const Json with_paths = EmbeddedData(Slurp(Path("r2.html")));
  EXPECT_EQ(with_paths["estimates"][0]["path"], Path("run1/est.tumv"));
  EXPECT_EQ(with_paths["estimates"][0]["label"], "est.tumv");
}

// The RPE section: distances at 10..50 % of the reference's length, and per distance the statistics
// of `cheval rpe --delta D --delta-unit meters --all-pairs` (translation and angle in degrees).
TEST_F(ReportCliTest, RpeIsThatOfChevalRpePerDistance) {
  Simulate(20);
  const std::string ref = Path("mocap.tum"), est = Path("noisy_v.tumv");
  ASSERT_EQ(Cheval(fmt::format("report {} {} --max-points 600 -o {}", ref, est, Path("r.html"))).exit_code, 0);
  const Json data = EmbeddedData(Slurp(Path("r.html")));
  const Json& distances = data["rpe_distances"];
  ASSERT_EQ(distances.size(), 5u);
  const Json& rpe = data["estimates"][0]["rpe"];
  EXPECT_EQ(rpe["relation"], "trans_part");
  ASSERT_EQ(rpe["distances"].size(), 5u);
  for (size_t k = 0; k < 5; ++k) {
    const double delta = distances[k];
    if (k > 0) {
      EXPECT_GT(delta, distances[k - 1].get<double>());
    }
    const Json& entry = rpe["distances"][k];
    EXPECT_EQ(entry["delta"], delta);
    for (const auto& [key, relation] : {std::pair{"trans", "trans_part"}, std::pair{"rot", "angle_deg"}}) {
      SCOPED_TRACE(fmt::format("{} m, {}", delta, relation));
      ASSERT_EQ(Cheval(fmt::format("rpe {} {} --align se3 -r {} --delta {} --delta-unit meters --all-pairs --json {}", ref,
                                   est, relation, delta, Path("rpe.json")))
                    .exit_code,
                0);
      const Json stats = Json::parse(Slurp(Path("rpe.json")))["stats"];
      const Json& box = entry[key];
      EXPECT_EQ(box["n"], stats["n"]);
      EXPECT_EQ(entry["pairs"], stats["n"]);
      for (const char* s : {"rmse", "mean", "median", "min", "max"}) {
        EXPECT_NEAR(box[s].get<double>(), stats[s].get<double>(), 1e-5 * std::abs(stats[s].get<double>()) + 1e-12) << s;
      }
      EXPECT_LE(box["q1"].get<double>(), box["median"].get<double>());
      EXPECT_LE(box["median"].get<double>(), box["q3"].get<double>());
      EXPECT_LE(box["whisker_high"].get<double>(), box["max"].get<double>());
      EXPECT_LE(entry["series"][key].size(), 600u);
    }
  }
}

// Distributions from every pair; the ASE rotation part in degrees; paths with time, attitude and error.
TEST_F(ReportCliTest, DistributionsRotationDegreesAndPaths) {
  Simulate(20);
  ASSERT_EQ(Cheval(fmt::format("report {} {} {} --max-points 500 -o {}", Path("mocap.tum"), Path("noisy_v.tumv"),
                               Path("poses.tum"), Path("r.html")))
                .exit_code,
            0);
  const Json data = EmbeddedData(Slurp(Path("r.html")));
  const Json& e = data["estimates"][0];
  const Json& d = e["ape_distribution"];
  const Json& stats = e["ape"]["stats"];
  const size_t pairs = e["ape"]["association"]["pairs"];
  size_t counted = 0;
  for (const Json& c : d["counts"]) counted += c.get<size_t>();
  EXPECT_EQ(counted, pairs) << "the histogram counts every pair, not the plotted samples";
  EXPECT_EQ(d["box"]["n"], pairs);
  for (const char* s : {"median", "max", "min", "rmse", "mean"}) {
    EXPECT_NEAR(d["box"][s].get<double>(), stats[s].get<double>(), 1e-5 * stats[s].get<double>()) << s;
  }
  // The density integrates to about 1 (trapezoids; the kernel's tail below 0 is clipped).
  double area = 0;
  for (size_t k = 1; k < d["density"].size(); ++k) {
    area += 0.5 * (d["density"][k].get<double>() + d["density"][k - 1].get<double>()) *
            (d["density_at"][k].get<double>() - d["density_at"][k - 1].get<double>());
  }
  EXPECT_NEAR(area, 1.0, 0.1);
  // ‖R − I‖_F = 2√2 sin(θ/2): the largest rotation part as an angle.
  const double part_max = e["ase"]["parts"]["rotation"]["max"];
  const double degrees = 2 * std::asin(part_max / (2 * std::numbers::sqrt2)) * 180 / std::numbers::pi;
  EXPECT_NEAR(e["ase_rotation_deg"]["max"].get<double>(), degrees, 1e-5 * degrees);
  EXPECT_TRUE(e["ase_series"].contains("rotation_deg"));
  EXPECT_FALSE(e["ase_series"].contains("rotation"));
  EXPECT_TRUE(e.contains("ase_distribution"));
  EXPECT_FALSE(data["estimates"][1].contains("ase_distribution"));
  // Paths: time, roll/pitch/yaw in degrees and the APE of each plotted pose.
  const Json& path = e["path_xyz"];
  for (const char* key : {"t", "x", "y", "z", "roll", "pitch", "yaw", "error"}) {
    ASSERT_TRUE(path.contains(key)) << key;
    EXPECT_EQ(path[key].size(), path["x"].size()) << key;
    EXPECT_LE(path[key].size(), 500u) << key;
  }
  for (const Json& yaw : path["yaw"]) EXPECT_LE(std::abs(yaw.get<double>()), 180.0);
  double largest = 0;
  for (const Json& error : path["error"]) {
    if (!error.is_null()) largest = std::max(largest, error.get<double>());
  }
  EXPECT_GT(largest, 0.0);
  EXPECT_LE(largest, stats["max"].get<double>() * (1 + 1e-3));
  EXPECT_FALSE(data["reference"]["path_xyz"].contains("error"));
  EXPECT_EQ(data["reference"]["path_xyz"]["t"][0], 0.0);
}

}  // namespace
}  // namespace cheval
