#pragma once
/// \file
/// Validation of options structs. Every options struct of the library has `void Validate() const`,
/// which throws OptionError naming the first field whose value is out of range (the role Ceres'
/// `Solver::Options::IsValid` plays, with the field kept apart from the sentence so that the CLI and
/// Python can spell it their way). Library functions call Validate() before any work.
///
///     void CurveOptions::Validate() const {
///       const OptionCheck check("CurveOptions");
///       check(max_degree >= 2, "max_degree", "must be >= 2, got {}", max_degree);
///     }

#include <string>
#include <string_view>
#include <utility>

#include <fmt/format.h>

#include "cheval/common/error.h"

namespace cheval {

/// Checks the fields of one options struct (named once, at construction).
class OptionCheck {
 public:
  explicit OptionCheck(std::string options) : options_(std::move(options)) {}

  /// Throws OptionError(options, field, rule formatted with args) unless `ok`. The rule starts with
  /// a verb and says what was given: "must be > 0, got {}".
  template <class... Args>
  void operator()(bool ok, std::string_view field, fmt::format_string<Args...> rule, Args&&... args) const {
    if (!ok) throw OptionError(options_, std::string(field), fmt::format(rule, std::forward<Args>(args)...));
  }

 private:
  std::string options_;
};

}  // namespace cheval
