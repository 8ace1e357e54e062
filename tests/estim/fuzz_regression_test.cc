// The kept inputs of the estimator's fuzz targets (tests/data/fuzz/vehicle, quadrotor_data, and the
// model corpus for the checksum's mutation check), passed to exactly the checks the targets run
// (fuzz/estim_fuzz_checks.cc, docs/fuzzing.md): every input is refused with an InputError naming its
// file or read with the documented properties.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "../../fuzz/estim_fuzz_checks.h"

namespace cheval {
namespace {

namespace fs = std::filesystem;

std::vector<fs::path> Inputs(const std::string& target) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(fs::path(CHEVAL_TEST_DATA_DIR) / "fuzz" / target)) {
    files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::string Slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), {});
}

TEST(EstimFuzzRegression, VehicleInputs) {
  const std::vector<fs::path> files = Inputs("vehicle");
  ASSERT_GE(files.size(), 7u);
  for (const fs::path& file : files) EXPECT_EQ(fuzz::CheckVehicleInput(Slurp(file)), std::nullopt) << file;
}

TEST(EstimFuzzRegression, QuadrotorDataInputs) {
  const std::vector<fs::path> files = Inputs("quadrotor_data");
  ASSERT_GE(files.size(), 9u);
  for (const fs::path& file : files) EXPECT_EQ(fuzz::CheckQuadrotorDataInput(Slurp(file)), std::nullopt) << file;
}

TEST(EstimFuzzRegression, ModelMutationInputs) {
  const std::vector<fs::path> files = Inputs("model");
  ASSERT_GE(files.size(), 7u);
  for (const fs::path& file : files) EXPECT_EQ(fuzz::CheckModelMutationInput(Slurp(file)), std::nullopt) << file;
}

}  // namespace
}  // namespace cheval
