#pragma once
/// \file
/// Reading result files for `cheval res`: evo's result zips (`file_interface.save_res_file`, any
/// evo version: `NAME.npy` members, or `NAME.npz` as evo wrote before 1.13), cheval's own
/// `--save-results` zips, and cheval's `--json` output (one result per estimate). docs/cli.md,
/// "cheval res".

#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "cheval/common/npy.h"

namespace cheval::eval {

/// One result, as evo's `load_res_file` gives it.
struct ResultFile {
  /// The file it came from.
  std::string path;
  /// info.json in file order: strings as they are, other JSON values as their JSON text.
  std::vector<std::pair<std::string, std::string>> info;
  /// stats.json in file order (rmse, mean, ... or, for evo_rpe-for-each, one mean per delta).
  std::vector<std::pair<std::string, double>> stats;
  /// The arrays (member name without folders and extension: error_array, timestamps, ...), in member
  /// order; a later member of the same name replaces an earlier one, as in evo.
  std::vector<std::pair<std::string, NpyArray>> arrays;
  /// Trajectory members kept by evo (`*.tum`, `*.kitti`), by member name.
  std::vector<std::string> trajectories;

  /// The info value of `key`, or empty.
  std::string Info(std::string_view key) const;
  /// The array `name`, or nullptr.
  const NpyArray* Array(std::string_view name) const;
};

/// The result in a zip's bytes. InputError (`path:0:0: error: ...`, naming the member) when the zip is
/// bad (common/zip.h), info.json, stats.json or error_array (.npy or .npz) is missing, a JSON member is
/// not an object (stats: of numbers), an array is not a readable .npy (common/npy.h), error_array is
/// not 1-D, or timestamps / seconds_from_start differ from it in length.
ResultFile ParseResultZip(std::string_view bytes, const std::string& path);

/// The results in the JSON of `cheval ape|rpe|ase --json` (an object, or an array of them for several
/// estimates): info has est_name (the label, else the estimate's path), ref_name and label ("APE (m)");
/// stats the seven statistics. InputError naming the key that is missing or wrong.
std::vector<ResultFile> ParseResultJson(std::string_view bytes, const std::string& path);

/// Reads `path` as a zip (by its magic PK) or as cheval JSON (first non-blank byte '{' or '[').
std::vector<ResultFile> ReadResultFile(const std::string& path);

}  // namespace cheval::eval
