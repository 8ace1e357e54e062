#pragma once
// The CLI's spelling of the library's options: one table from each options field (`STRUCT::FIELD`,
// as the library names it in OptionError and in its messages) to its flag. The subcommands bind
// their flags by field (Flag) and main() passes every library message through Spell, so the user
// reads "--n-align needs --align (...)" where the library says "AlignmentOptions::n_align needs
// AlignmentOptions::method (...)". A field missing from the table stays STRUCT::FIELD.

#include <span>
#include <string>
#include <string_view>
#include <vector>

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

/// One of evo's spellings and what cheval spells for it (docs/cli.md, "evo's flags"). `cheval` is
/// the cheval flag the evo spelling is an alias of (the same option, so the same result), or a
/// note for the spellings that are not plain aliases (-a, -s, -v, --align_origin, -p).
struct EvoSpelling {
  std::string_view evo;
  std::string_view cheval;
  /// True when `evo` is registered as a second name of the option `cheval` (same value syntax).
  bool alias;
};

/// Every evo spelling cheval knows, in the order of docs/cli.md.
std::span<const EvoSpelling> EvoSpellings();

/// The CLI11 names of the option of `field` (Flag(field, prefix)) followed by its evo aliases from
/// EvoSpellings, e.g. "--t-max-diff,--t_max_diff"; `short_name` ("-r") goes first when given.
std::string Names(std::string_view field, std::string_view prefix = "", std::string_view short_name = "");

/// The CLI11 names of `flag` (a flag without a library field) and, when `with_evo`, its evo aliases.
std::string FlagNames(const std::string& flag, bool with_evo = true, std::string_view short_name = "");

/// The message for flags a command does not take: for each, the cheval spelling when it is one of
/// evo's (EvoSpellings), else the closest flag of `command` ("did you mean"), and a pointer to
/// `cheval COMMAND --help`. `command` empty for the top level.
std::string UnknownFlagsMessage(const std::vector<std::string>& flags, const std::vector<std::string>& known,
                                std::string_view command);

}  // namespace cheval::cli
