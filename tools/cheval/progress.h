#pragma once
// Progress on the terminal: one line on stderr, redrawn in place ("\r"), only when stderr is a
// terminal and --quiet is not given; silent otherwise (pipes, files, CI logs). The bar is erased
// when a stage ends, so nothing of it is left in the output a user copies.
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>

#include "cheval/common/progress.h"

namespace cheval::cli {

class TerminalProgress {
 public:
  /// Draws on `out` when `enabled`; redraws at most every `interval`.
  TerminalProgress(std::FILE* out, bool enabled,
                   std::chrono::milliseconds interval = std::chrono::milliseconds(100));
  ~TerminalProgress() { Clear(); }
  TerminalProgress(const TerminalProgress&) = delete;
  TerminalProgress& operator=(const TerminalProgress&) = delete;

  /// The ProgressFn of the library (cheval/common/progress.h). Empty when disabled, so the library
  /// skips even the calls.
  ProgressFn Fn();

  /// Shows `stage` at done of total (total 0: a count without a bar).
  void Update(std::string_view stage, int64_t done, int64_t total);
  /// Erases the line if one is shown.
  void Clear();

  bool enabled() const { return enabled_; }

 private:
  std::FILE* out_;
  bool enabled_;
  std::chrono::milliseconds interval_;
  std::chrono::steady_clock::time_point last_draw_{};
  std::string last_stage_;
  bool shown_ = false;
};

/// Whether `cheval -q/--quiet` was given: no progress and no informational lines on stderr (errors
/// and warnings are still printed).
bool Quiet();
void SetQuiet(bool quiet);

/// The process's progress display on stderr: enabled when stderr is a terminal and not Quiet().
TerminalProgress& Progress();

}  // namespace cheval::cli
