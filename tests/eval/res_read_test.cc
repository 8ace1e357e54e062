// Reading result files (common/zip.h, common/npy.h, eval/res_read.h, eval/res_table.h): evo's own
// zips give the statistics their stats.json holds when computed from their error arrays; zips written
// by cheval's writer read back; every damaged zip or .npy is an InputError naming the member.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <numeric>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "cheval/common/error.h"
#include "cheval/common/npy.h"
#include "cheval/common/zip.h"
#include "cheval/eval/res_file.h"
#include "cheval/eval/res_read.h"
#include "cheval/eval/res_table.h"
#include "../support/test_data.h"
#include "../../fuzz/res_fuzz_checks.h"

namespace cheval::eval {
namespace {

std::string ReadBytes(const std::string& path) {
  std::string out;
  FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) return out;
  char buffer[65536];
  for (size_t n; (n = std::fread(buffer, 1, sizeof buffer, f)) > 0;) out.append(buffer, n);
  std::fclose(f);
  return out;
}

double Stat(const ResultFile& r, const std::string& key) {
  for (const auto& [k, v] : r.stats) {
    if (k == key) return v;
  }
  ADD_FAILURE() << "no statistic " << key;
  return NAN;
}

// evo's statistics (numpy: mean, median, std with ddof 0, sse = sum of squares) from the definitions.
TEST(ResRead, EvoZipsHoldTheStatisticsOfTheirErrorArrays) {
  CHEVAL_REQUIRE_SHARED_DATA();
  const std::string dir = ::cheval::testing::SharedDataDir() + "/evo/res_files/";
  for (const char* name : {"orb_ape.zip", "sptam_ape.zip", "orb_rpe.zip", "sptam_rpe.zip"}) {
    SCOPED_TRACE(name);
    const ResultFile r = ParseResultZip(ReadBytes(dir + name), name);
    const NpyArray* a = r.Array("error_array");
    ASSERT_NE(a, nullptr);
    std::vector<double> e = a->values;
    ASSERT_GT(e.size(), 100u);
    const double n = static_cast<double>(e.size());
    double sum = 0, sse = 0;
    for (double v : e) {
      sum += v;
      sse += v * v;
    }
    const double mean = sum / n;
    double var = 0;
    for (double v : e) var += (v - mean) * (v - mean);
    std::sort(e.begin(), e.end());
    const double median = e.size() % 2 ? e[e.size() / 2] : (e[e.size() / 2 - 1] + e[e.size() / 2]) / 2;
    const std::vector<std::pair<std::string, double>> expected = {
        {"rmse", std::sqrt(sse / n)}, {"mean", mean}, {"median", median}, {"std", std::sqrt(var / n)},
        {"min", e.front()},           {"max", e.back()}, {"sse", sse}};
    for (const auto& [key, value] : expected) EXPECT_NEAR(Stat(r, key), value, 1e-12 * std::abs(value)) << key;
    EXPECT_EQ(r.Info("ref_name"), "../data/KITTI_00_gt.txt");
  }
}

// evo_rpe-for-each: one mean per delta, the deltas in seconds_from_start.
TEST(ResRead, EvoForEachZipHoldsOneMeanPerDelta) {
  CHEVAL_REQUIRE_SHARED_DATA();
  const std::string path = ::cheval::testing::SharedDataDir() + "/evo/res_files/orb_rpe-for-each.zip";
  const ResultFile r = ParseResultZip(ReadBytes(path), path);
  const NpyArray *e = r.Array("error_array"), *d = r.Array("seconds_from_start");
  ASSERT_TRUE(e != nullptr && d != nullptr);
  ASSERT_EQ(e->values.size(), 5u);
  for (size_t k = 0; k < 5; ++k) EXPECT_EQ(Stat(r, fmt::format("{:.1f}", d->values[k])), e->values[k]);
  const ResTable t = BuildResTable({r}, {});
  EXPECT_EQ(t.labels, std::vector<std::string>{"ORB-SLAM"});
  EXPECT_EQ(t.columns, (std::vector<std::string>{"40.0", "10.0", "20.0", "50.0", "30.0"}));
}

std::string Zip(const std::vector<std::pair<std::string, std::string>>& members) { return StoredZip(members); }

std::vector<std::pair<std::string, std::string>> GoodMembers() {
  return {{"info.json", R"j({"title": "T", "est_name": "dir/est.txt", "label": "APE (m)"})j"},
          {"stats.json", R"({"rmse": 2.0, "mean": 1.5})"},
          {"error_array.npy", NpyFloat64(std::vector<double>{1.0, 2.0, 3.0})},
          {"timestamps.npy", NpyFloat64(std::vector<double>{10.0, 11.0, 12.0})}};
}

void ExpectError(const std::string& bytes, const std::string& needle) {
  try {
    ParseResultZip(bytes, "r.zip");
    ADD_FAILURE() << "accepted; expected an error with " << needle;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("r.zip:0:0: error:"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

TEST(ResRead, WrittenZipReadsBack) {
  const ResultFile r = ParseResultZip(Zip(GoodMembers()), "r.zip");
  EXPECT_EQ(r.Array("error_array")->values, (std::vector<double>{1, 2, 3}));
  EXPECT_EQ(r.Array("timestamps")->values, (std::vector<double>{10, 11, 12}));
  EXPECT_EQ(r.Info("est_name"), "dir/est.txt");
  const ResTable t = BuildResTable({r}, {});
  EXPECT_EQ(t.labels[0], "est.txt");
  EXPECT_EQ(t.title, "T");
  EXPECT_EQ(EvoResText(t), "        rmse mean\nest.txt  2.0  1.5");  // pandas: " 2.0" per object float
  EXPECT_EQ(ResTableCsv(t), ",rmse,mean\nest.txt,2.0,1.5\n");
  EXPECT_EQ(BuildResTable({r}, {.labels = {"mine"}}).labels[0], "mine");
  EXPECT_THROW(BuildResTable({r, r}, {}), UsageError);  // two rows named est.txt
}

TEST(ResRead, DamagedZipsNameWhatIsWrong) {
  const std::string good = Zip(GoodMembers());
  ExpectError(good.substr(0, good.size() - 5), "no end of central directory");
  ExpectError(good.substr(0, 40) + good.substr(good.size() - 200), "");
  ExpectError("PK", "not a zip archive");
  std::string bad_crc = good;
  bad_crc[good.find("{\"rmse\"") + 3] ^= 1;  // a byte of stats.json
  ExpectError(bad_crc, "member stats.json: CRC-32");
  auto without = [](const std::string& name) {
    auto m = GoodMembers();
    m.erase(std::remove_if(m.begin(), m.end(), [&](const auto& p) { return p.first == name; }), m.end());
    return StoredZip(m);
  };
  ExpectError(without("info.json"), "member info.json is missing");
  ExpectError(without("stats.json"), "member stats.json is missing");
  ExpectError(without("error_array.npy"), "member error_array.npy is missing");
  auto with = [](const std::string& name, const std::string& data) {
    auto m = GoodMembers();
    for (auto& p : m) {
      if (p.first == name) p.second = data;
    }
    return StoredZip(m);
  };
  ExpectError(with("stats.json", R"({"rmse": "x"})"), "member stats.json: \"rmse\"");
  ExpectError(with("info.json", "[1]"), "member info.json");
  ExpectError(with("error_array.npy", "not numpy"), "member error_array.npy: not a .npy array");
  std::string object = NpyFloat64(std::vector<double>{1, 2, 3});
  object.replace(object.find("<f8"), 3, "|O8");
  ExpectError(with("error_array.npy", object), "member error_array.npy: dtype '|O8' is not a plain number");
  std::string truncated = NpyFloat64(std::vector<double>{1, 2, 3});
  ExpectError(with("error_array.npy", truncated.substr(0, truncated.size() - 1)), "member error_array.npy: 23 bytes of data");
  ExpectError(with("error_array.npy", truncated.substr(0, 30)), "member error_array.npy: truncated .npy header");
  ExpectError(with("timestamps.npy", NpyFloat64(std::vector<double>{1})), "member timestamps: 1 values");
  // Another compression method (6, implode) in the central directory entry of the first member.
  std::string method = good;
  const size_t central = method.find("PK\x01\x02");
  method[central + 10] = 6;
  ExpectError(method, "member info.json: compression method 6");
}

// numpy's other dtypes and orders: big-endian and float32 and integers convert exactly; Fortran order.
TEST(ResRead, NpyDtypes) {
  auto npy = [](const std::string& descr, const std::string& shape, bool fortran, const std::string& data) {
    std::string header = fmt::format("{{'descr': '{}', 'fortran_order': {}, 'shape': {}, }}", descr,
                                     fortran ? "True" : "False", shape);
    while ((10 + header.size() + 1) % 64 != 0) header += ' ';
    header += '\n';
    std::string out("\x93NUMPY\x01\x00", 8);
    out += static_cast<char>(header.size() & 0xff);
    out += static_cast<char>(header.size() >> 8);
    return out + header + data;
  };
  const std::string be("\x40\x00\x00\x00\x00\x00\x00\x00", 8);  // 2.0 big-endian
  EXPECT_EQ(ParseNpy(npy(">f8", "(1,)", false, be), "p", "a").values, std::vector<double>{2.0});
  const float f = 0.1f;
  std::string fdata(4, '\0');
  std::memcpy(fdata.data(), &f, 4);
  EXPECT_EQ(ParseNpy(npy("<f4", "(1,)", false, fdata), "p", "a").values, std::vector<double>{static_cast<double>(f)});
  const int64_t i = -3;
  std::string idata(8, '\0');
  std::memcpy(idata.data(), &i, 8);
  EXPECT_EQ(ParseNpy(npy("<i8", "()", false, idata), "p", "a").values, std::vector<double>{-3.0});
  EXPECT_EQ(ParseNpy(npy("|u1", "(2,)", false, "\x05\xff"), "p", "a").values, (std::vector<double>{5, 255}));
  // (2, 3) in Fortran order: columns first.
  std::string fo;
  for (double v : {1.0, 4.0, 2.0, 5.0, 3.0, 6.0}) fo.append(reinterpret_cast<const char*>(&v), 8);
  const NpyArray m = ParseNpy(npy("<f8", "(2, 3)", true, fo), "p", "a");
  EXPECT_EQ(m.shape, (std::vector<uint64_t>{2, 3}));
  EXPECT_EQ(m.values, (std::vector<double>{1, 2, 3, 4, 5, 6}));
  EXPECT_THROW(ParseNpy(npy("<c16", "(1,)", false, std::string(16, '\0')), "p", "a"), InputError);
  EXPECT_THROW(ParseNpy(npy("<f8", "(99999999999,99999999999)", false, ""), "p", "a"), InputError);
  EXPECT_THROW(ParseNpy(npy("<f8", "(1,)", false, std::string(9, '\0')), "p", "a"), InputError);
}

// The kept inputs of fuzz_res (tests/data/fuzz/res, fuzz/make_res_seeds.sh and what runs found),
// through exactly the checks the target runs (docs/fuzzing.md).
TEST(ResRead, FuzzInputsKeepTheirProperties) {
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(std::filesystem::path(CHEVAL_TEST_DATA_DIR) / "fuzz" / "res")) {
    files.push_back(entry.path());
  }
  ASSERT_GE(files.size(), 9u);
  for (const auto& file : files) EXPECT_EQ(fuzz::CheckResultFileInput(ReadBytes(file.string())), std::nullopt) << file;
}

}  // namespace
}  // namespace cheval::eval
