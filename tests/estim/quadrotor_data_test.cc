// The quadrotor data folder as an output: written whole or not at all, an earlier run replaced
// whole, any other non-empty folder refused (include/cheval/estim/quadrotor_data.h).
#include "cheval/estim/quadrotor_data.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "cheval/common/error.h"
#include "cheval/estim/vehicle.h"
#include "cheval/sim/quadrotor.h"

namespace cheval {
namespace {

namespace fs = std::filesystem;

const std::string kVehicle = std::string(CHEVAL_SOURCE_DIR) + "/data/vehicles/flightgoggles.json";

estim::QuadrotorData Simulated(uint64_t seed, bool with_truth) {
  sim::QuadrotorSimOptions options;
  options.duration_s = 0.5;
  options.seed = seed;
  estim::QuadrotorData data = sim::SimulateQuadrotor(estim::ReadVehicle(kVehicle), options);
  if (!with_truth) data.truth.clear();
  return data;
}

std::set<std::string> Entries(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.insert(entry.path().filename().string());
  return names;
}

// Names in `parent` that start with "." (a staging folder left behind would be one).
int HiddenEntries(const fs::path& parent) {
  int count = 0;
  for (const auto& entry : fs::directory_iterator(parent)) count += entry.path().filename().string()[0] == '.';
  return count;
}

class QuadrotorDataFolder : public ::testing::Test {
 protected:
  void SetUp() override {
    parent_ = fs::temp_directory_path() / ("cheval_data_folder_" + std::to_string(::getpid()));
    fs::remove_all(parent_);
    fs::create_directories(parent_);
  }
  void TearDown() override { fs::remove_all(parent_); }
  fs::path parent_;
};

// A second run over the folder of a first one replaces it whole: the first run had truth.csv, the
// second has none, so a mixed folder would still hold the first run's truth.csv.
TEST_F(QuadrotorDataFolder, AnEarlierRunIsReplacedWholeNotMixed) {
  const fs::path dir = parent_ / "flight";
  estim::WriteQuadrotorData(Simulated(1, true), dir.string());
  EXPECT_EQ(Entries(dir).count("truth.csv"), 1u);
  const estim::QuadrotorData second = Simulated(2, false);
  estim::WriteQuadrotorData(second, dir.string());
  EXPECT_EQ(Entries(dir), (std::set<std::string>{"vehicle.json", "landmarks.csv", "measurements.csv", "initial.csv"}));
  const estim::QuadrotorData back = estim::ReadQuadrotorData(dir.string());
  EXPECT_TRUE(back.truth.empty());
  ASSERT_EQ(back.pixels.size(), second.pixels.size());
  EXPECT_EQ(back.pixels.front().uv, second.pixels.front().uv);
  EXPECT_EQ(HiddenEntries(parent_), 0);
}

// A folder that holds anything else is not cheval's to delete: refused, left exactly as it was.
TEST_F(QuadrotorDataFolder, AForeignNonEmptyFolderIsRefusedAndUntouched) {
  const fs::path dir = parent_ / "notes";
  fs::create_directories(dir);
  std::ofstream(dir / "thesis.tex") << "keep me\n";
  try {
    estim::WriteQuadrotorData(Simulated(1, true), dir.string());
    ADD_FAILURE() << "a foreign folder was written into";
  } catch (const OutputError& e) {
    EXPECT_NE(std::string(e.what()).find(dir.string()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("not empty"), std::string::npos) << e.what();
  }
  EXPECT_EQ(Entries(dir), std::set<std::string>{"thesis.tex"});
  EXPECT_EQ(HiddenEntries(parent_), 0);
}

// A data-folder file name among foreign ones does not make the folder a data folder.
TEST_F(QuadrotorDataFolder, AFolderMixingDataFilesAndOthersIsRefused) {
  const fs::path dir = parent_ / "mixed";
  estim::WriteQuadrotorData(Simulated(1, true), dir.string());
  std::ofstream(dir / "README") << "mine\n";
  EXPECT_THROW(estim::WriteQuadrotorData(Simulated(2, true), dir.string()), OutputError);
  EXPECT_EQ(Entries(dir).count("README"), 1u);
  EXPECT_EQ(Entries(dir).count("truth.csv"), 1u);
}

// An empty folder (e.g. made by mkdir beforehand) and a missing one are both fine.
TEST_F(QuadrotorDataFolder, EmptyAndMissingFoldersAreWritten) {
  fs::create_directories(parent_ / "empty");
  estim::WriteQuadrotorData(Simulated(1, false), (parent_ / "empty").string());
  estim::WriteQuadrotorData(Simulated(1, false), (parent_ / "new").string());
  EXPECT_EQ(Entries(parent_ / "empty"), Entries(parent_ / "new"));
  EXPECT_EQ(Entries(parent_ / "new").size(), 4u);
}

}  // namespace
}  // namespace cheval
