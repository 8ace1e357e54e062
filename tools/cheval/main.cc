// cheval: one executable, one subcommand per file. main() parses, runs the chosen action and maps
// the library's typed errors to the documented exit codes (docs/cli.md), each message with the
// library's option fields spelled as flags (option_names.h).
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>
#include <new>
#include <string>
#include <system_error>

#include <malloc.h>

#include <fmt/format.h>

#include "cheval/common/error.h"
#include "common.h"
#include "eval_command.h"
#include "option_names.h"
#include "progress.h"

namespace {

// glibc gives freed memory back to the kernel as soon as 128 KiB of it (more after large frees) sits
// at the top of a heap, worker threads' heaps included; a fit allocates and frees blocks of up to a
// few MB per window, whose pages then fault in again, at up to ~10 µs each. A command keeps up to
// 64 MiB free per heap and serves blocks below 32 MiB from the heaps: `cheval velocity` on 100k
// samples faults 17k -> 12k pages and its peak memory is unchanged (docs/velocity.md, "Speed").
void KeepFreedMemoryForReuse() {
#ifdef M_TRIM_THRESHOLD
  mallopt(M_TRIM_THRESHOLD, 64 << 20);
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
#endif
}

}  // namespace

int main(int argc, char** argv) {
  using cheval::ExitCode;
  KeepFreedMemoryForReuse();
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
  cheval::cli::RegisterEstimateRotors(app, &action);
  cheval::cli::RegisterIdentifyRotors(app, &action);
  cheval::cli::RegisterTable(app, &action);
  cheval::cli::RegisterRes(app, &action);
  cheval::cli::CheckNumericOptions(&app);

  auto fail = [](ExitCode code, const std::string& message) {
    std::fprintf(stderr, "%s\n", cheval::cli::Spell(message).c_str());
    return static_cast<int>(code);
  };
  // What a command prints on standard output is part of its result: a write that failed (a full disk,
  // a closed pipe when SIGPIPE is ignored) is exit 4, not a success with the result lost.
  auto stdout_failed = [&fail](const std::string& reason) {
    return fail(ExitCode::kOutput, fmt::format("<stdout>: error: cannot write: {}", reason));
  };
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ExtrasError& e) {
    // evo's spellings and near misses: the cheval flag and `cheval COMMAND --help` (option_names.h).
    return fail(ExitCode::kUsage, cheval::cli::UnknownFlags(app, app.remaining(true)));
  } catch (const CLI::ParseError& e) {
    return fail(ExitCode::kUsage, fmt::format("cheval: error: {}\nRun 'cheval --help' for usage.", e.what()));
  }
  cheval::cli::SetQuiet(quiet);
  try {
    if (action) action();
    errno = 0;
    if (std::fflush(stdout) != 0 || std::ferror(stdout)) {
      return stdout_failed(errno != 0 ? std::strerror(errno) : "write error");
    }
    return static_cast<int>(ExitCode::kOk);
  } catch (const cheval::InputError& e) {
    return fail(ExitCode::kInput, e.what());
  } catch (const cheval::UsageError& e) {
    return fail(ExitCode::kUsage, fmt::format("cheval: error: {}", e.what()));
  } catch (const cheval::ComputeError& e) {
    return fail(ExitCode::kCompute, fmt::format("cheval: error: {}", e.what()));
  } catch (const cheval::OutputError& e) {
    return fail(ExitCode::kOutput, e.what());
  } catch (const std::bad_alloc&) {
    // The limits of docs/cli.md refuse what options and inputs would need beyond the memory limit
    // before allocating; what still does not fit is a computation that cannot be done here.
    return fail(ExitCode::kCompute, "cheval: error: out of memory (the machine or the process's limits do not "
                                    "have the memory this run needs)");
  } catch (const std::system_error& e) {
    // fmt::print throws when a write to standard output fails.
    if (std::ferror(stdout)) return stdout_failed(e.code().message());
    return fail(ExitCode::kInternal, fmt::format("cheval: internal error (please report): {}", e.what()));
  } catch (const std::exception& e) {
    return fail(ExitCode::kInternal, fmt::format("cheval: internal error (please report): {}", e.what()));
  }
}
