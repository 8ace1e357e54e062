#pragma once
/// \file
/// What the fuzz target of the result-file readers (`fuzz_res`: common/zip.h, common/npy.h,
/// eval/res_read.h) runs and checks (docs/fuzzing.md). Returns the violated property (with the input)
/// or nullopt; the target traps on a violation and tests/eval/res_read_test.cc replays
/// tests/data/fuzz/res through the same function. Needs the library only.

#include <optional>
#include <string>
#include <string_view>

namespace cheval::fuzz {

/// The bytes as a result zip (eval::ParseResultZip) and as a lone .npy array (ParseNpy): each either
/// throws an InputError whose message begins with "res.zip:0:0: error: " and names a member (zip) or
/// the array, or gives a result whose error_array is 1-D with timestamps of its length, finite or not,
/// whose arrays have as many values as their shapes say; a read result written again with StoredZip and
/// NpyFloat64 reads back to the same statistics and bit-identical error_array; and the table of it
/// (BuildResTable, EvoResText, Markdown, LaTeX, CSV) is made without an exception.
std::optional<std::string> CheckResultFileInput(std::string_view data);

}  // namespace cheval::fuzz
