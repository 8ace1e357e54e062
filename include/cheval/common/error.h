#pragma once
/// \file
/// Typed errors of cheval. Library code reports every failure by throwing one of these; it never
/// exits or aborts. The CLI maps each type to a fixed exit code (see ExitCode and docs/cli.md).

#include <cstdint>
#include <stdexcept>
#include <string>

namespace cheval {

/// Exit codes of the `cheval` executable, one per error type. Stable: scripts depend on them.
enum class ExitCode : int {
  kOk = 0,            ///< success
  kUsage = 1,         ///< bad command line: unknown flag, bad option value, missing argument
  kInput = 2,         ///< an input file is missing, unreadable or malformed (InputError)
  kCompute = 3,       ///< the input is well formed but the computation is impossible (ComputeError)
  kOutput = 4,        ///< an output file could not be written (OutputError)
  kInternal = 70,     ///< a bug in cheval (an unexpected exception); please report it
};

/// Base of all cheval errors; what() is the complete, user-facing message.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Bad input data: the message has the form `PATH:LINE:COLUMN: error: WHAT`. LINE and COLUMN are
/// 1-based; 0 means "the file as a whole" (a file that cannot be opened, or a problem that belongs to
/// no single line).
class InputError : public Error {
 public:
  InputError(std::string path, int64_t line, int64_t column, const std::string& what);

  const std::string& path() const { return path_; }
  int64_t line() const { return line_; }
  int64_t column() const { return column_; }
  /// The explanation alone, without the location prefix.
  const std::string& detail() const { return detail_; }

 private:
  std::string path_;
  int64_t line_;
  int64_t column_;
  std::string detail_;
};

/// A bad option value or combination given by the caller (validated before any work is done).
class UsageError : public Error {
 public:
  using Error::Error;
};

/// A bad value of one field of an options struct, named by the struct and the field as the library
/// spells them: what() is `STRUCT::FIELD RULE` ("QuadrotorEstimateOptions::degree must be >= 2, got
/// 1"). The faces (CLI, Python) translate the field into their own spelling with Message(), so the
/// library never names a flag or a keyword argument.
class OptionError : public UsageError {
 public:
  /// `options`: the struct ("CurveOptions"); `field`: the member ("degree"); `rule`: what the value
  /// breaks, starting with a verb ("must be >= 2, got 1").
  OptionError(std::string options, std::string field, std::string rule);

  const std::string& options() const { return options_; }
  const std::string& field() const { return field_; }
  const std::string& rule() const { return rule_; }
  /// The message with the field spelled as `name` (a flag such as `--degree`, a keyword such as `degree`).
  std::string Message(const std::string& name) const { return name + " " + rule_; }

 private:
  std::string options_;
  std::string field_;
  std::string rule_;
};

/// Well-formed input on which the requested computation cannot be done (e.g. too few samples).
class ComputeError : public Error {
 public:
  using Error::Error;
};

/// An output file could not be written; nothing partial is left behind.
class OutputError : public Error {
 public:
  using Error::Error;
};

}  // namespace cheval
