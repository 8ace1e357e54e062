// `cheval report` end to end through the executable: the data the page embeds (its APE and ASE
// results are exactly what `cheval ape|ase --json` write with the same options; the series are
// decimated but keep their extremes; the fit diagnostics are there), the page is self-contained,
// and bad input gives the documented exit codes and leaves no output file. The page in a browser:
// tests/report/browser_test.js.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <tuple>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "report_page.h"

namespace cheval {
namespace {

// The page's APE and ASE results are `cheval ape --json` / `cheval ase --json` with the same
// options, key for key and number for number; an estimate without velocity has no ASE and a note.
TEST_F(ReportCliTest, EmbeddedResultsAreThoseOfApeAndAse) {
  Simulate(20);
  const std::string ref = Path("mocap.tum"), a = Path("noisy_v.tumv"), b = Path("poses.tum");
  // The same options given to report, ape and ase (the report aligns with SE(3) by default; ape and
  // ase do not align unless told).
  struct Case {
    std::string report, ape, ase;
  };
  const std::string continuous = "--align posyaw --t-offset 0.002 --association continuous";
  for (const Case& c :
       {Case{"", "--align se3", "--align se3"},
        Case{"--align sim3 -r full --gt-velocity central --t-max-diff 0.004", "--align sim3 -r full --t-max-diff 0.004",
             "--align sim3 --gt-velocity central --t-max-diff 0.004"},
        Case{continuous, continuous, continuous}}) {
    SCOPED_TRACE(c.report);
    // --show-paths: the embedded results name the files as `cheval ape --json` does.
    const auto run = Cheval(fmt::format("report {} {} {} {} --show-paths -o {}", ref, a, b, c.report, Path("r.html")));
    ASSERT_EQ(run.exit_code, 0) << run.err;
    EXPECT_NE(run.out.find("poses.tum has no velocity"), std::string::npos) << run.out;
    const Json data = EmbeddedData(Slurp(Path("r.html")));
    ASSERT_EQ(Cheval(fmt::format("ape {} {} {} {} --json {}", ref, a, b, c.ape, Path("ape.json"))).exit_code, 0);
    ASSERT_EQ(Cheval(fmt::format("ase {} {} {} --json {}", ref, a, c.ase, Path("ase.json"))).exit_code, 0);
    const Json ape = Json::parse(Slurp(Path("ape.json"))), ase = Json::parse(Slurp(Path("ase.json")));
    ASSERT_EQ(data["estimates"].size(), 2u);
    EXPECT_EQ(data["estimates"][0]["ape"], ape[0]);
    EXPECT_EQ(data["estimates"][1]["ape"], ape[1]);
    EXPECT_EQ(data["estimates"][0]["ase"], ase);
    EXPECT_TRUE(data["estimates"][1]["ase"].is_null());
    EXPECT_FALSE(data["estimates"][1].contains("velocity"));
    EXPECT_FALSE(data["estimates"][1].contains("ase_series"));
    const auto& notes = data["notes"];
    EXPECT_TRUE(std::any_of(notes.begin(), notes.end(), [&](const Json& n) {
      return n.get<std::string>().find("poses.tum has no velocity") != std::string::npos;
    })) << notes;
  }
}

// Every plotted series has at most --max-points points, keeps the extremes of the errors, and the
// statistics still come from every pair.
TEST_F(ReportCliTest, SeriesAreDecimatedWithTheirExtremes) {
  Simulate(30);  // 6001 reference poses
  const auto run = Cheval(fmt::format("report {} {} {} --max-points 400 -o {}", Path("truth.tumv"),
                                      Path("noisy_v.tumv"), Path("poses.tum"), Path("r.html")));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const Json data = EmbeddedData(Slurp(Path("r.html")));
  EXPECT_EQ(data["options"]["max_points"], 400);
  EXPECT_EQ(data["time_axis"], "s");
  const auto bounded = [](const Json& series, const char* key, size_t n) {
    EXPECT_LE(series[key].size(), 400u) << key;
    EXPECT_GT(series[key].size(), 100u) << key;
    EXPECT_EQ(series["n"], n);
  };
  bounded(data["reference"]["path_xyz"], "x", 6001);
  const Json& first = data["estimates"][0];
  const size_t pairs = first["ape"]["association"]["pairs"];
  EXPECT_EQ(first["ape"]["stats"]["n"], pairs);
  bounded(first["ape_series"], "error", pairs);
  bounded(first["ase_series"], "total", pairs);
  bounded(first["velocity"], "speed", 1501);
  // Min/max buckets keep the largest and smallest error (rounded to 6 significant digits).
  for (const auto& [series, key, stats] :
       {std::tuple{first["ape_series"], "error", first["ape"]["stats"]},
        std::tuple{first["ase_series"], "total", first["ase"]["stats"]},
        std::tuple{first["ase_series"], "velocity", first["ase"]["parts"]["velocity"]}}) {
    const std::vector<double> values = series[key];
    EXPECT_NEAR(*std::max_element(values.begin(), values.end()), stats["max"].get<double>(),
                1e-5 * stats["max"].get<double>())
        << key;
    EXPECT_NEAR(*std::min_element(values.begin(), values.end()), stats["min"].get<double>(),
                1e-5 * stats["max"].get<double>())
        << key;
  }
  // Times are seconds from the reference's first stamp, increasing.
  const std::vector<double> t = first["ape_series"]["t"];
  EXPECT_TRUE(std::is_sorted(t.begin(), t.end()));
  EXPECT_GE(t.front(), 0.0);
  EXPECT_LE(t.back(), 30.0 + 1e-9);
  // The reference velocity three ways (the truth has its own columns): every series the same length.
  for (const char* source : {"given", "chebyshev", "central"}) {
    ASSERT_TRUE(data["reference_velocity"].contains(source)) << source;
    const Json& v = data["reference_velocity"][source];
    for (const char* key : {"vx", "vy", "vz", "speed"}) EXPECT_EQ(v[key].size(), v["t"].size()) << source << key;
    bounded(v, "speed", 6001);
  }
  // The truth's own velocity and its Chebyshev velocity agree (the truth is exact and noise-free).
  const std::vector<double> given = data["reference_velocity"]["given"]["speed"];
  const std::vector<double> chebyshev = data["reference_velocity"]["chebyshev"]["speed"];
  EXPECT_EQ(data["reference_velocity"]["given"]["t"], data["reference_velocity"]["chebyshev"]["t"]);
  double worst = 0;
  for (size_t i = 0; i < given.size(); ++i) worst = std::max(worst, std::abs(given[i] - chebyshev[i]));
  // Measured 1e-5 m/s: exactly one step of the plotted values' 6 significant digits at speeds of 1 to
  // 10 m/s (the fits themselves agree to ~1e-9 m/s, tests/cli/eval_cli_test.cc). Two rounded values of
  // speeds that close differ by at most one step, so 1.5 steps bounds it.
  EXPECT_LE(worst, 1.5e-5) << "m/s";
}

// The fit diagnostics: every window with its degrees, the coefficient magnitudes of some windows
// (at least as many as the chosen degree + 1), the noise level and the residual.
TEST_F(ReportCliTest, FitDiagnosticsOfTheReference) {
  Simulate(20);
  const auto run = Cheval(fmt::format("report {} {} -o {}", Path("mocap.tum"), Path("noisy_v.tumv"), Path("r.html")));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const Json fit = EmbeddedData(Slurp(Path("r.html")))["fit"];
  ASSERT_TRUE(fit.is_object());
  ASSERT_GE(fit["windows"].size(), 2u);
  double previous_end = -1;
  for (const Json& w : fit["windows"]) {
    ASSERT_EQ(w["degrees"].size(), 3u);
    for (const Json& d : w["degrees"]) EXPECT_GE(d.get<int>(), 1);
    EXPECT_LT(w["core_begin"].get<double>(), w["core_end"].get<double>());
    EXPECT_GE(w["core_begin"].get<double>(), previous_end - 1e-6) << "windows in time order";
    previous_end = w["core_end"];
  }
  ASSERT_GE(fit["coefficients"].size(), 1u);
  EXPECT_LE(fit["coefficients"].size(), std::min<size_t>(64, fit["windows"].size()));
  for (const Json& c : fit["coefficients"]) {
    const Json& w = fit["windows"][c["window"].get<size_t>()];
    ASSERT_EQ(c["magnitudes"].size(), 3u);
    for (int axis = 0; axis < 3; ++axis) {
      EXPECT_GT(c["magnitudes"][axis].size(), w["degrees"][axis].get<size_t>());
      EXPECT_GT(c["noise_level"][axis].get<double>(), 0.0);
    }
  }
  // The simulator's 0.5 mm noise is what the fit estimates (within 10 %).
  for (const Json& sigma : fit["noise_sigma"]) EXPECT_NEAR(sigma.get<double>(), 0.0005, 0.00005);
  // Each tested window carries the σ it was tested against (the noise profile's), never below the
  // recording's; the profile's largest is reported beside it.
  ASSERT_EQ(fit["noise_sigma_max"].size(), 3u);
  EXPECT_TRUE(fit.contains("noisier_samples"));
  EXPECT_TRUE(fit.contains("stamp_noise_s"));
  ASSERT_EQ(fit["resolution"].size(), 3u);  // the simulator's positions are not rounded
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_EQ(fit["resolution"][axis].get<double>(), 0.0);
    EXPECT_FALSE(fit["at_rounding"][axis].get<bool>());
  }
  for (const Json& w : fit["windows"]) {
    if (!w.contains("residual_rms")) continue;
    ASSERT_EQ(w["noise_sigma"].size(), 3u);
    for (int axis = 0; axis < 3; ++axis) {
      EXPECT_GE(w["noise_sigma"][axis].get<double>(), 0.999 * fit["noise_sigma"][axis].get<double>());
      EXPECT_LE(w["noise_sigma"][axis].get<double>(), 1.001 * fit["noise_sigma_max"][axis].get<double>());
    }
  }
}

// One file, nothing fetched: the chart library, the page script and the data are inline, and a file
// name cannot end the data element.
TEST_F(ReportCliTest, PageIsSelfContained) {
  Simulate(10);
  const std::string odd = Path("odd <!-- name.tumv");
  std::filesystem::copy_file(Path("noisy_v.tumv"), odd);
  const auto run = Cheval(fmt::format("report {} '{}' -o {}", Path("mocap.tum"), odd, Path("r.html")));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const std::string page = Slurp(Path("r.html"));
  EXPECT_EQ(page.rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_EQ(Count(page, "<script"), 3u) << "data, chart library, page script";
  EXPECT_EQ(Count(page, "</script>"), 3u);
  EXPECT_EQ(Count(page, "<!--"), 0u);
  EXPECT_EQ(Count(page, " src="), 0u);
  EXPECT_EQ(Count(page, "<link"), 0u);
  EXPECT_NE(page.find("uPlot"), std::string::npos);
  EXPECT_EQ(EmbeddedData(page)["estimates"][0]["path"], "odd <!-- name.tumv") << "the label, not the path";
  EXPECT_NE(run.out.find("r.html: "), std::string::npos) << run.out;
}

// A reference without stamps (KITTI): the APE pairs pose i with pose i and the page is still
// written, on a pose-index axis; the ASE (its reference velocity needs stamps), the reference's
// velocity and its fit are notes, not errors.
TEST_F(ReportCliTest, ReferenceWithoutStampsGivesNotesNotErrors) {
  Simulate(10);
  ASSERT_EQ(Cheval(fmt::format("convert {} -o {} --to kitti", Path("mocap.tum"), Path("ref.kitti"))).exit_code, 0);
  const auto run = Cheval(fmt::format("report {} {} -o {}", Path("ref.kitti"), Path("truth.tumv"), Path("r.html")));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const Json data = EmbeddedData(Slurp(Path("r.html")));
  EXPECT_EQ(data["time_axis"], "index");
  const Json& e = data["estimates"][0];
  EXPECT_EQ(e["ape"]["association"]["method"], "index");
  EXPECT_EQ(e["ape"]["association"]["pairs"], 2001);
  EXPECT_TRUE(e["ase"].is_null());
  EXPECT_EQ(e["ase_absent"], "no ASE");
  EXPECT_EQ(e["velocity"]["n"], 2001) << "the estimate's own velocity is still drawn";
  EXPECT_TRUE(data["reference_velocity"].empty());
  EXPECT_TRUE(data["fit"].is_null());
  const std::string notes = data["notes"].dump();
  EXPECT_NE(notes.find("the ASE of truth.tumv cannot be computed"), std::string::npos) << notes;
  EXPECT_NE(notes.find("needs stamps"), std::string::npos) << notes;
  EXPECT_NE(notes.find("ref.kitti has no stamps"), std::string::npos) << notes;
}

// Bad input: the exit codes and messages of `cheval ape`, and no output (an existing file is kept).
TEST_F(ReportCliTest, BadInputGivesTheDocumentedExitCodesAndNoFile) {
  Simulate(10);
  const std::string ref = Path("mocap.tum"), est = Path("noisy_v.tumv"), out = Path("r.html");
  const auto expect_failure = [&](const std::string& args, int code, const std::string& message) {
    const auto run = Cheval(fmt::format("report {} -o {}", args, out));
    EXPECT_EQ(run.exit_code, code) << args << "\n" << run.err;
    EXPECT_NE(run.err.find(message), std::string::npos) << run.err;
    EXPECT_FALSE(std::filesystem::exists(out)) << args;
    return run.err;
  };
  expect_failure(fmt::format("{} {}", ref, Path("missing.tum")), 2, "missing.tum");
  const std::string bad = fmt::format("{}/bad/truncated_last_line.txt", CHEVAL_TEST_DATA_DIR);
  const std::string err = expect_failure(fmt::format("{} {}", ref, bad), 2, "truncated last line");
  EXPECT_EQ(err, Cheval(fmt::format("ape {} {}", ref, bad)).err) << "the same message as cheval ape";
  expect_failure(fmt::format("{} {} --t-offset 1000", ref, est), 3, "--t-max-diff");
  expect_failure(fmt::format("{} {} --align bogus", ref, est), 1, "--align");
  expect_failure(fmt::format("{} {} --max-points 3", ref, est), 1, "--max-points");
  expect_failure(fmt::format("{} {} --t-max-diff -1", ref, est), 1, "--t-max-diff");
  // An estimate too short to align (2 poses): exit 3 as in `cheval ape --align se3`.
  {
    std::ifstream in(est);
    std::ofstream two(Path("two.tum"));
    std::string line;
    for (int i = 0; i < 2 && std::getline(in, line); ++i) two << line << "\n";
  }
  expect_failure(fmt::format("{} {}", ref, Path("two.tum")), 3, "at least 3 associated pairs");
  // An existing report is not clobbered by a failed run.
  std::ofstream(out) << "old";
  const auto failed = Cheval(fmt::format("report {} {} --t-offset 1000 -o {}", ref, est, out));
  EXPECT_EQ(failed.exit_code, 3);
  EXPECT_EQ(Slurp(out), "old");
  // An output that cannot be written: exit 4.
  const auto unwritable = Cheval(fmt::format("report {} {} -o {}", ref, est, Path("no/such/dir/r.html")));
  EXPECT_EQ(unwritable.exit_code, 4) << unwritable.err;
  EXPECT_NE(unwritable.err.find("cannot write"), std::string::npos) << unwritable.err;
}

// Issue 13: `--max-points -1` (wrapped to 2^64 - 1) grew without end (16.8 GB, exit 70). Now any
// number of points at or above the poses keeps them all; what the plotted series would cost is checked
// against the memory limit first (exit 3: it depends on the data); --n-align 0 is not ignored; an
// APE that is not finite is exit 3.
TEST_F(ReportCliTest, MaxPointsIsBoundedByWhatItCosts) {
  Simulate(20);
  const std::string ref = Path("truth.tumv"), est = Path("noisy_v.tumv"), out = Path("r.html");
  const std::string report = fmt::format("{} report {} {} -o {} --quiet", CHEVAL_EXE, ref, est, out);
  auto run = Shell(report + " --max-points 18446744073709551615");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const Json data = EmbeddedData(Slurp(out));
  EXPECT_EQ(data["estimates"][0]["ape_series"]["t"].size(), data["estimates"][0]["ape_series"]["n"].get<size_t>());
  std::filesystem::remove(out);
  // 4001 + 1001 poses: every value of every series needs about 5 MB, the default 5000 points the same.
  run = Shell("CHEVAL_MEMORY_LIMIT=1M " + report + " --max-points 18446744073709551615");
  EXPECT_EQ(run.exit_code, 3) << run.err;
  EXPECT_NE(run.err.find("cheval: error: --max-points would need about"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("plotted values for 4001 poses of the reference and 1 estimate(s)); the limit is 1.05 MB"),
            std::string::npos)
      << run.err;
  EXPECT_FALSE(std::filesystem::exists(out));
  run = Shell("CHEVAL_MEMORY_LIMIT=1M " + report + " --max-points 100");
  EXPECT_EQ(run.exit_code, 0) << run.err;
  std::filesystem::remove(out);
  run = Cheval(fmt::format("report {} {} -o {} --n-align 0", ref, est, out));
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_NE(run.err.find("--n-align must be at least 1"), std::string::npos) << run.err;
  {
    std::ofstream huge(Path("huge.tum"));
    for (int i = 0; i < 20; ++i) huge << 1.0 + 0.1 * i << " " << 1e300 * (1 + i) << " 0 0 0 0 0 1\n";
    std::ofstream small(Path("small.tum"));
    for (int i = 0; i < 20; ++i) small << 1.0 + 0.1 * i << " " << i << " 0 0 0 0 0 1\n";
  }
  run = Cheval(fmt::format("report {} {} -o {} --align none", Path("huge.tum"), Path("small.tum"), out));
  EXPECT_EQ(run.exit_code, 3) << run.err;
  EXPECT_NE(run.err.find("not a finite number: the coordinates are too large"), std::string::npos) << run.err;
  EXPECT_FALSE(std::filesystem::exists(out));
  // The APE of a file against itself is 0, but its speed from 1e300 positions overflows: the page
  // held nulls with exit 0.
  run = Cheval(fmt::format("report {} {} -o {} --align none", Path("huge.tum"), Path("huge.tum"), out));
  EXPECT_EQ(run.exit_code, 3) << run.err;
  EXPECT_NE(run.err.find("cheval: error: the report's value /reference_velocity/"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find(", not a finite number: the coordinates are too large"), std::string::npos) << run.err;
  EXPECT_FALSE(std::filesystem::exists(out));
}

// A build without the chart library: `cheval report` says so (exit 1) before reading anything.
TEST(ReportUnavailableTest, SaysHowToGetTheReport) {
  if (CHEVAL_REPORT_AVAILABLE) GTEST_SKIP() << "built with the report (CHEVAL_BUILD_REPORT=ON)";
  const auto folder = std::filesystem::temp_directory_path();
  const std::string out = (folder / "cheval_report_unavailable.html").string();
  const std::string err = (folder / "cheval_report_unavailable.err").string();
  const int status =
      std::system(fmt::format("{} report missing.tum missing2.tum -o {} 2>{}", CHEVAL_EXE, out, err).c_str());
  EXPECT_EQ(WEXITSTATUS(status), 1);
  EXPECT_NE(Slurp(err).find("CHEVAL_BUILD_REPORT"), std::string::npos) << Slurp(err);
  EXPECT_FALSE(std::filesystem::exists(out));
  std::filesystem::remove(err);
}

}  // namespace
}  // namespace cheval
