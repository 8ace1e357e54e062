#pragma once
/// \file
/// How a face (the CLI, Python) spells the library's option fields. The library names an option as
/// `STRUCT::FIELD` ("AlignmentOptions::n_align") in every message, OptionError or not; each face
/// keeps one table from those names to its own spelling (`--n-align`, `n_align`) and passes every
/// message through SpellOptions before showing it. A name missing from the table stays as the
/// library wrote it.

#include <span>
#include <string>
#include <string_view>

namespace cheval {

/// One option as a face spells it.
struct OptionName {
  /// The library's `STRUCT::FIELD`, e.g. "AssociationOptions::max_diff_ns".
  std::string_view field;
  /// The face's spelling in messages, e.g. `--t-max-diff` or `t_max_diff`.
  std::string_view name;
};

/// `text` with every `STRUCT::FIELD` (identifier characters around "::") that `names` lists replaced
/// by its spelling; everything else unchanged.
std::string SpellOptions(std::string_view text, std::span<const OptionName> names);

}  // namespace cheval
