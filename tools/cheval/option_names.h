#pragma once
// The CLI's spelling of the library's options: one table from each options field (`STRUCT::FIELD`,
// as the library names it in OptionError and in its messages) to its flag. The subcommands bind
// their flags by field (Flag) and main() passes every library message through Spell, so the user
// reads "--n-align needs --align (...)" where the library says "AlignmentOptions::n_align needs
// AlignmentOptions::method (...)". A field missing from the table stays STRUCT::FIELD.

#include <span>
#include <string>
#include <string_view>

#include "cheval/common/option_names.h"

namespace cheval::cli {

/// The flag of `field` ("AlignmentOptions::n_align" -> "--n-align"; a flag that names a value, as
/// "--association continuous", without it); `prefix` goes after the dashes ("ref-": "--ref-format").
/// The field must be in the table (a programming error otherwise: std::logic_error).
std::string Flag(std::string_view field, std::string_view prefix = "");

/// `message` with every field of the table spelled as its flag.
std::string Spell(std::string_view message);

/// The table, for library functions that quote messages in their output (report::ReportOptions).
std::span<const OptionName> FlagNames();

}  // namespace cheval::cli
