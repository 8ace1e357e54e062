#include "progress.h"

#include <unistd.h>

#include <algorithm>
#include <memory>

#include <fmt/format.h>

namespace cheval::cli {

TerminalProgress::TerminalProgress(std::FILE* out, bool enabled, std::chrono::milliseconds interval)
    : out_(out), enabled_(enabled), interval_(interval) {}

ProgressFn TerminalProgress::Fn() {
  if (!enabled_) return {};
  return [this](std::string_view stage, int64_t done, int64_t total) { Update(stage, done, total); };
}

void TerminalProgress::Update(std::string_view stage, int64_t done, int64_t total) {
  if (!enabled_) return;
  const bool finished = total > 0 && done >= total;
  if (finished) {
    Clear();
    return;
  }
  const auto now = std::chrono::steady_clock::now();
  // A new stage is drawn at once; within a stage at most every interval_.
  if (shown_ && stage == last_stage_ && now - last_draw_ < interval_) return;
  last_draw_ = now;
  last_stage_.assign(stage);
  std::string line;
  if (total > 0) {
    constexpr int kWidth = 24;
    const double fraction = std::clamp(static_cast<double>(done) / static_cast<double>(total), 0.0, 1.0);
    const int filled = static_cast<int>(fraction * kWidth);
    line = fmt::format("{} [{}{}] {:3.0f}% ({}/{})", stage, std::string(filled, '#'), std::string(kWidth - filled, ' '),
                       100.0 * fraction, done, total);
  } else {
    line = fmt::format("{} ({})", stage, done);
  }
  // \r to the line's start, the text, then erase what a longer previous line left (ESC[K).
  fmt::print(out_, "\r{}\x1b[K", line);
  std::fflush(out_);
  shown_ = true;
}

void TerminalProgress::Clear() {
  if (!shown_) return;
  fmt::print(out_, "\r\x1b[K");
  std::fflush(out_);
  shown_ = false;
  last_stage_.clear();
}

namespace {
bool g_quiet = false;
}  // namespace

bool Quiet() { return g_quiet; }
void SetQuiet(bool quiet) { g_quiet = quiet; }

TerminalProgress& Progress() {
  // Created on first use, after the command line (and so --quiet) has been parsed.
  static TerminalProgress progress(stderr, !Quiet() && ::isatty(STDERR_FILENO) == 1);
  return progress;
}

}  // namespace cheval::cli
