#pragma once
/// \file
/// The output layer of every command (docs/output.md has the full contract): where a path leads
/// (`-` is standard output; a FIFO, a device or /dev/stdout is written in place; a symlink's target is
/// replaced; a regular file is replaced atomically, keeping its mode and owner), same-file checks
/// before any work, folders built beside their target and published whole, and temporaries removed
/// when the process is ended by SIGINT, SIGTERM, SIGHUP or SIGPIPE.
///
/// Messages name the path as the caller gave it; standard output is named `<stdout>`
/// ("<stdout>: error: cannot write: No space left on device").

#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace cheval {

/// The path that names standard output (file descriptor 1).
inline constexpr std::string_view kStandardOutput = "-";

/// Receives an output's text a piece at a time (OutputFile::write).
using TextSink = std::function<void(std::string_view piece)>;

/// One output of WriteOutputs: where, and the whole text, or a function that writes it a piece at a
/// time, so that a large output is never held whole in memory.
struct OutputFile {
  /// The whole text, held by the caller until the output is written.
  OutputFile(std::string where, std::string_view whole) : path(std::move(where)), text(whole) {}
  /// The text written by `write`, called once with a sink that writes each piece it is given (and
  /// throws to stop it when a write fails). What `write` throws is passed on, as any failure, with
  /// nothing replaced; but an output written in place (standard output, a FIFO) cannot take back the
  /// pieces already given, so `write` should check everything before its first piece.
  OutputFile(std::string where, std::function<void(const TextSink& sink)> pieces)
      : path(std::move(where)), write(std::move(pieces)) {}

  std::string path;
  std::string_view text;
  std::function<void(const TextSink& sink)> write;  ///< when set, used instead of `text`
};

/// Writes several outputs as one. Each path is resolved first:
/// - `-`, /dev/stdout, /dev/fd/N, /proc/self/fd/N: written to the open descriptor (standard output
///   for `-`), at its offset, never reopened or renamed over;
/// - a FIFO, a character or block device: opened write-only (no create, no truncate) and written; a
///   FIFO blocks until it has a reader;
/// - a symlink: followed (a chain too, a dangling one creates its target); what it leads to is written
///   as below and the link is kept;
/// - a regular file or a new name: the text goes to a temporary `.NAME.tmp-PID-RAND` in the file's
///   folder, flushed to disk (fsync); an existing file's mode and owner (where permitted) are given to
///   it; then it is renamed over the file. A new file gets 0666 & ~umask.
/// Order: every temporary is written first (a failure removes them all and replaces nothing), then the
/// in-place outputs, then the renames. Text already written to a stream or device cannot be taken back.
/// Throws OutputError "PATH: error: cannot write: REASON" (PATH as given, `<stdout>` for `-`) on any
/// failed open, write, fsync or close (ENOSPC, EPIPE when SIGPIPE is ignored, ...), and UsageError when
/// two files resolve to the same output (CheckOutputs gives the better message before any work).
void WriteOutputs(std::span<const OutputFile> files);

/// WriteOutputs for one output.
void WriteOutput(const std::string& path, std::string_view text);

/// What an output of a command is, for CheckOutputs.
enum class OutputKind {
  kFile,            ///< a file, `-`, a FIFO or a device (WriteOutputs)
  kNewFolder,       ///< a folder that must not exist yet or be empty (StagedFolder, FolderExisting::kRefuse)
  kReplacedFolder,  ///< a folder replaced whole if it exists (StagedFolder, FolderExisting::kReplace)
};

/// An output as the face names it: `label` is the face's own name for it (`--json`, `json_path`; may
/// be empty) and is used only in messages. An empty `path` means "not given" and is skipped.
struct OutputPath {
  std::string label;
  std::string path;
  OutputKind kind = OutputKind::kFile;
};

/// Checks a command's outputs before any work; throws UsageError naming the first problem:
/// - an output is the same file as an input (same device and inode after following symlinks; for an
///   output that does not exist yet, the same canonical folder and name): "LABEL PATH names the same
///   file as the input INPUT";
/// - two outputs are the same file or both standard output: "LABEL1 PATH1 and LABEL2 PATH2 name the
///   same file" / "... both write to standard output";
/// - a kFile output is an existing folder; a kNewFolder output exists and is not an empty folder; a
///   kReplacedFolder output exists and is not a folder, or holds an input.
/// Character devices (/dev/null, a terminal) may repeat and may be both input and output: writing to
/// them twice harms nothing. `-` as an input (standard input) is never compared; `-` as two outputs is
/// an error. Inputs that do not exist are compared by canonical path (reading them will fail anyway).
/// Without a label an output is called "output PATH".
void CheckOutputs(std::span<const std::string> inputs, std::span<const OutputPath> outputs);

/// What StagedFolder::Publish does when the target folder exists and is not empty.
enum class FolderExisting {
  kRefuse,   ///< throw OutputError; the existing folder is untouched
  kReplace,  ///< replace it whole: the old files are removed, none is mixed with the new ones
};

/// A folder output written whole or not at all: files are written into a staging folder
/// `.NAME.tmp-PID-RAND` beside the target (a symlink to a folder is followed), then Publish() renames
/// it into place. Destroying an unpublished StagedFolder (a failure, an exception) removes the staging
/// folder, so the target is never partial and never mixes two runs.
class StagedFolder {
 public:
  /// Creates the staging folder beside `path`. Throws OutputError "PATH: error: cannot write: ...".
  explicit StagedFolder(std::string path);
  ~StagedFolder();
  StagedFolder(const StagedFolder&) = delete;
  StagedFolder& operator=(const StagedFolder&) = delete;

  /// Writes file `name` (a plain name, no `/`) into the staging folder, flushed to disk. Throws
  /// OutputError "PATH/NAME: error: cannot write: ..." (the staging folder stays until destruction).
  void Write(const std::string& name, std::string_view text);
  /// Write() of `file.path` (a plain name) with its text, or piece by piece (OutputFile::write).
  void Write(const OutputFile& file);

  /// Renames the staging folder into place. A missing target or an empty folder is replaced by one
  /// rename. A non-empty folder is refused (OutputError, kRefuse) or replaced (kReplace): the two are
  /// exchanged in one renameat2(RENAME_EXCHANGE) and the old one is removed; where the file system
  /// cannot exchange, the old folder is first renamed to `.NAME.old-PID-RAND` (between the two renames
  /// the target is missing, both versions are on disk). The new folder gets the old one's mode.
  void Publish(FolderExisting existing = FolderExisting::kRefuse);

  /// The target as given.
  const std::string& path() const { return path_; }

 private:
  std::string path_;     // as given, for messages
  std::string target_;   // the resolved target
  std::string staging_;  // the staging folder
  int slot_ = -1;        // its entry in the signal-time cleanup registry
  std::vector<std::pair<std::string, int>> files_;  // the files written into it, with their entries
  bool published_ = false;
};

/// The files of a folder output, written whole (StagedFolder); `path` of each file is its plain name.
void WriteFolder(const std::string& path, std::span<const OutputFile> files,
                 FolderExisting existing = FolderExisting::kRefuse);

}  // namespace cheval
