#pragma once
/// \file
/// Progress of long work: reading big files, fitting many windows, solver iterations. Library code
/// reports through a ProgressFn that the caller may leave empty and never prints anything itself;
/// the CLI draws a bar on stderr when stderr is a terminal (tools/cheval/progress.h), the Python
/// module passes none.

#include <cstdint>
#include <functional>
#include <string_view>

namespace cheval {

/// Called with the stage's name (e.g. "fitting windows"), the units done so far and their total
/// (0 when unknown), from the thread doing the work, which may be a thread the library started
/// for it (never two calls at once; done never falls within a stage). A stage ends with
/// done == total. Calls are cheap for the caller to make: at most a few hundred per stage.
using ProgressFn = std::function<void(std::string_view stage, int64_t done, int64_t total)>;

/// Calls `progress` when it is set.
inline void ReportProgress(const ProgressFn& progress, std::string_view stage, int64_t done, int64_t total) {
  if (progress) progress(stage, done, total);
}

}  // namespace cheval
