#pragma once
/// \file
/// evo's result files (`evo.tools.file_interface.save_res_file`, read by `load_res_file` and
/// `evo_res`): a zip archive, members stored uncompressed as evo writes them, holding
/// `info.json` (title, ref_name, est_name, label), `stats.json` (rmse, mean, median, std, min, max,
/// sse) and one `NAME.npz` per array, each a plain `.npy` 1-D float64 array despite the extension:
/// `error_array`, `timestamps` (estimate stamps, seconds) and `seconds_from_start`.
/// docs/evaluation.md, "evo result files".

#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "cheval/eval/evaluate.h"

namespace cheval::eval {

/// A 1-D little-endian float64 `.npy` array (format version 1.0), as numpy.save writes it.
std::string NpyFloat64(std::span<const double> values);

/// A zip archive of `members` (name, bytes), stored without compression, with CRC-32 and sizes.
/// Throws ComputeError when a member exceeds the zip format's 4 GiB limits (no zip64).
std::string StoredZip(const std::vector<std::pair<std::string, std::string>>& members);

/// CRC-32 (ISO-HDLC, the zip and gzip checksum) of `bytes`.
uint32_t Crc32(std::string_view bytes);

/// The evo result zip of one evaluation. `report.estimate_label` (or the path) is evo's est_name.
std::string EvoResultZip(const EvaluationReport& report);

}  // namespace cheval::eval
