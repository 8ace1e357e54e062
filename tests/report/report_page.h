#pragma once
// What the `cheval report` tests through the executable share: the page's embedded data and a
// simulated flight (report_cli_test.cc, report_sections_test.cc).
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../cli/cli_runner.h"

namespace cheval {

using Json = nlohmann::json;
using testing::CliTest;
using testing::Slurp;

// The JSON of <script type="application/json" id="cheval-data"> in a report page.
inline Json EmbeddedData(const std::string& page) {
  const std::string open = "<script type=\"application/json\" id=\"cheval-data\">";
  const size_t begin = page.find(open);
  EXPECT_NE(begin, std::string::npos) << "no data element";
  const size_t end = page.find("</script>", begin);
  return Json::parse(page.substr(begin + open.size(), end - begin - open.size()));
}

inline size_t Count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

class ReportCliTest : public CliTest {
 protected:
  void SetUp() override {
    CliTest::SetUp();
    if (!CHEVAL_REPORT_AVAILABLE) GTEST_SKIP() << "built with CHEVAL_BUILD_REPORT=OFF (ReportUnavailableTest runs)";
  }

  // A simulated drone flight: motion-capture-like positions as the reference (no velocity), the
  // truth (with velocity), a noisy 50 Hz copy given velocity by `cheval velocity`, and a noisier 20 Hz
  // copy without velocity.
  void Simulate(double seconds) {
    const std::string duration = fmt::format("--duration {}", seconds);
    ASSERT_EQ(Cheval(fmt::format("sim motion --kind drone --seed 3 --noise 0.0005 {} -o {} --truth {}", duration,
                                 Path("mocap.tum"), Path("truth.tumv")))
                  .exit_code,
              0);
    ASSERT_EQ(
        Cheval(fmt::format("sim motion --kind drone --seed 3 --noise 0.01 --rotation-noise 0.003 --rate 50 {} -o {}",
                           duration, Path("noisy.tum")))
            .exit_code,
        0);
    ASSERT_EQ(Cheval(fmt::format("velocity {} -o {}", Path("noisy.tum"), Path("noisy_v.tumv"))).exit_code, 0);
    ASSERT_EQ(Cheval(fmt::format("sim motion --kind drone --seed 3 --noise 0.03 --rate 20 {} -o {}", duration,
                                 Path("poses.tum")))
                  .exit_code,
              0);
  }
};

}  // namespace cheval
