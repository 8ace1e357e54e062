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

// ---------------------------------------------------------------------------------------------
// Reading a data folder: every bad value names file:line, the same as the trajectory readers.

std::string Slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), {});
}

// Replaces line `line` (1-based) of a folder's file.
void ReplaceLine(const fs::path& file, int line, const std::string& text) {
  std::string content = Slurp(file);
  size_t at = 0;
  for (int i = 1; i < line; ++i) at = content.find('\n', at) + 1;
  const size_t end = content.find('\n', at);
  content.replace(at, end - at, text);
  std::ofstream(file, std::ios::binary) << content;
}

class QuadrotorDataReader : public QuadrotorDataFolder {
 protected:
  void SetUp() override {
    QuadrotorDataFolder::SetUp();
    dir_ = parent_ / "flight";
    estim::WriteQuadrotorData(Simulated(1, true), dir_.string());
  }
  // The message of reading the folder, from the file's name on ("" when it reads).
  std::string Error() {
    try {
      estim::ReadQuadrotorData(dir_.string());
    } catch (const InputError& e) {
      const std::string message = e.what();
      return message.substr(message.find(dir_.string()) == 0 ? dir_.string().size() + 1 : 0);
    }
    return "";
  }
  fs::path dir_;
};

// A zero quaternion in initial.csv gave "segment 0 has a negative rotor-rate energy" (a
// UsageError with no file) once the estimator ran; now the reader names the line.
TEST_F(QuadrotorDataReader, AZeroQuaternionNamesItsLine) {
  ReplaceLine(dir_ / "initial.csv", 3, "0.033333333333333333,0,0,1.5,0,0,0,0");
  EXPECT_EQ(Error(),
            "initial.csv:3:0: error: expected a rotation: the quaternion (qw, qx, qy, qz) = (0, 0, 0, 0) has a squared "
            "norm 0 (it must be > 1e-12 and finite)");
  ReplaceLine(dir_ / "initial.csv", 3, "0.033333333333333333,0,0,1.5,1e200,0,0,0");
  EXPECT_NE(Error().find("initial.csv:3:0: error: expected a rotation"), std::string::npos) << Error();
}

// A file of the folder that is a directory was read as empty ("no camera measurements", exit 3).
TEST_F(QuadrotorDataReader, AFileThatIsADirectoryIsAnInputError) {
  fs::remove(dir_ / "measurements.csv");
  fs::create_directories(dir_ / "measurements.csv");
  EXPECT_EQ(Error(), "measurements.csv:0:0: error: is a directory; expected a CSV file of a quadrotor data folder");
}

// CRLF line ends (a folder edited on Windows) read exactly as LF ones; they were "expected ','".
TEST_F(QuadrotorDataReader, CrlfLinesReadAsLf) {
  const estim::QuadrotorData lf = estim::ReadQuadrotorData(dir_.string());
  for (const char* name : {"landmarks.csv", "measurements.csv", "initial.csv", "truth.csv"}) {
    std::string text = Slurp(dir_ / name), crlf;
    for (char c : text) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
    std::ofstream(dir_ / name, std::ios::binary) << crlf;
  }
  const estim::QuadrotorData crlf = estim::ReadQuadrotorData(dir_.string());
  ASSERT_EQ(crlf.pixels.size(), lf.pixels.size());
  ASSERT_EQ(crlf.initial.size(), lf.initial.size());
  ASSERT_EQ(crlf.truth.size(), lf.truth.size());
  EXPECT_EQ(crlf.landmarks, lf.landmarks);
  EXPECT_EQ(crlf.pixels.back().uv, lf.pixels.back().uv);
  EXPECT_EQ(crlf.initial.back().q.coeffs(), lf.initial.back().q.coeffs());
  EXPECT_EQ(crlf.truth.back().rotor, lf.truth.back().rotor);
}

// Every value within the documented bounds (quadrotor_data.h), with its line.
TEST_F(QuadrotorDataReader, ValuesOutsideTheirBoundsNameTheLine) {
  ReplaceLine(dir_ / "landmarks.csv", 2, "0,1e300,0,0");
  EXPECT_EQ(Error(), "landmarks.csv:2:0: error: a landmark coordinate must be within [-1e+06, 1e+06] m, got 1e+300");
  estim::WriteQuadrotorData(Simulated(1, true), dir_.string());
  ReplaceLine(dir_ / "measurements.csv", 2, "0,3.5,100,100");
  EXPECT_EQ(Error(), "measurements.csv:2:1: error: unknown landmark id 3.5 (landmarks.csv has ids 0 to 599)");
  ReplaceLine(dir_ / "measurements.csv", 2, "0,3,100,-1e7");
  EXPECT_EQ(Error(), "measurements.csv:2:0: error: the pixel v must be within [-1e+06, 1e+06] px, got -10000000");
  estim::WriteQuadrotorData(Simulated(1, true), dir_.string());
  ReplaceLine(dir_ / "initial.csv", 3, "0,0,0,1.5,1,0,0,0");
  EXPECT_EQ(Error(), "initial.csv:3:1: error: times must increase: 0 after 0");
  ReplaceLine(dir_ / "initial.csv", 3, "1e11,0,0,1.5,1,0,0,0");
  EXPECT_EQ(Error(), "initial.csv:3:0: error: the time t must be within [-1e+10, 1e+10] s, got 100000000000");
  estim::WriteQuadrotorData(Simulated(1, true), dir_.string());
  std::string row = "0,0,0,1.5,1,0,0,0,0,0,0,0,0,0,1000,1000,1000,-1";
  ReplaceLine(dir_ / "truth.csv", 2, row);
  EXPECT_EQ(Error(), "truth.csv:2:0: error: a rotor speed must be within [0, 1e+06] rad/s, got -1");
  ReplaceLine(dir_ / "truth.csv", 2, "0,0,0,1.5,1,0,0,0,0,0,0,0,0,0,1000,1000,1000,1000,");
  EXPECT_EQ(Error(), "truth.csv:2:51: error: expected a number after ','");
}

}  // namespace
}  // namespace cheval
