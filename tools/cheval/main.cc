// cheval: one executable, one subcommand per file. main() parses, runs the chosen action and maps
// the library's typed errors to the documented exit codes (docs/cli.md), each message with the
// library's option fields spelled as flags (option_names.h).
#include <cstdio>
#include <exception>
#include <string>

#include <fmt/format.h>

#include "cheval/common/error.h"
#include "common.h"
#include "option_names.h"
#include "progress.h"

int main(int argc, char** argv) {
  using cheval::ExitCode;
  CLI::App app{"cheval: evaluate and estimate robot state trajectories with Chebyshev pseudo-spectral methods",
               "cheval"};
  app.set_version_flag("--version", std::string(CHEVAL_VERSION));
  app.require_subcommand(1);
  // Global flags may also follow the subcommand (`cheval velocity IN -o OUT --quiet`).
  app.fallthrough();
  bool quiet = false;
  app.add_flag("-q,--quiet", quiet, "No progress display and no informational lines on stderr (errors and warnings stay)");
  cheval::cli::Action action;
  cheval::cli::RegisterInfo(app, &action);
  cheval::cli::RegisterConvert(app, &action);
  cheval::cli::RegisterSim(app, &action);
  cheval::cli::RegisterVelocity(app, &action);
  cheval::cli::RegisterCompress(app, &action);
  cheval::cli::RegisterSample(app, &action);
  cheval::cli::RegisterApe(app, &action);
  cheval::cli::RegisterRpe(app, &action);
  cheval::cli::RegisterAse(app, &action);
  cheval::cli::RegisterReport(app, &action);
  cheval::cli::RegisterSimQuadrotor(app, &action);
  cheval::cli::RegisterEstimate(app, &action);
  cheval::cli::RegisterEstimateThrust(app, &action);

  auto fail = [](ExitCode code, const std::string& message) {
    std::fprintf(stderr, "%s\n", cheval::cli::Spell(message).c_str());
    return static_cast<int>(code);
  };
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    return fail(ExitCode::kUsage, fmt::format("cheval: error: {}\nRun 'cheval --help' for usage.", e.what()));
  }
  cheval::cli::SetQuiet(quiet);
  try {
    if (action) action();
    return static_cast<int>(ExitCode::kOk);
  } catch (const cheval::InputError& e) {
    return fail(ExitCode::kInput, e.what());
  } catch (const cheval::UsageError& e) {
    return fail(ExitCode::kUsage, fmt::format("cheval: error: {}", e.what()));
  } catch (const cheval::ComputeError& e) {
    return fail(ExitCode::kCompute, fmt::format("cheval: error: {}", e.what()));
  } catch (const cheval::OutputError& e) {
    return fail(ExitCode::kOutput, e.what());
  } catch (const std::exception& e) {
    return fail(ExitCode::kInternal, fmt::format("cheval: internal error (please report): {}", e.what()));
  }
}
