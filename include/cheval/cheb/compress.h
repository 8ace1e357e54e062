#pragma once
/// \file
/// Compressing sampled positions into a TrajectoryModel (model.h), optionally to a guaranteed
/// maximum error at the samples: `cheval compress` (docs/compress.md).

#include <cstdint>
#include <optional>
#include <span>
#include <string>

#include <Eigen/Core>

#include "cheval/cheb/curve.h"
#include "cheval/cheb/model.h"

namespace cheval::cheb {

/// Options of Compress; Validate() is called by Compress.
struct CompressOptions {
  /// The automatic fit (FitCurve) and the limits of the tolerance fit (max_conditioning,
  /// max_degree, min_window_samples, overlap); the defaults need no tuning. A model represents
  /// every sample: no sample is left out as an outlier, windows are judged by their coefficients
  /// (the residual test would store more than the samples of nearly noise-free ground truth), and
  /// they stop at 24 samples (velocity's 12 serve its σ → 0 limit). A recording of one or two
  /// windows gets no end caps: they serve its velocity, and would store its positions in 2.5x the
  /// numbers.
  CurveOptions curve = CompressionCurveOptions();
  static CurveOptions CompressionCurveOptions() {
    CurveOptions options;
    options.robust = false;
    options.lack_of_fit = false;
    options.min_window_samples = 24;
    options.short_segment_caps = false;
    return options;
  }
  /// The largest reconstruction error accepted (units of the samples: metres for positions): the
  /// Euclidean norm of (model - sample) at every sample must not exceed it. It is a budget the
  /// model spends: the result is the smallest model found within it, coarser than the automatic
  /// fit when the tolerance is loose, finer when it is tight. nullopt: the automatic fit.
  std::optional<double> tolerance;

  /// Throws OptionError naming the first field out of range: tolerance, when given, not positive
  /// and finite ("CompressOptions::tolerance must be a positive number of metres, got nan"); then
  /// curve.Validate().
  void Validate() const;
};

/// A model and what it costs and achieves.
struct Compression {
  TrajectoryModel model;
  /// The error of `model` as stored (through its values, CurveFromModel) at every input sample.
  ReconstructionError error;
  /// Numbers in the input's coordinate columns: dimension x samples (stamps not counted).
  Eigen::Index input_numbers = 0;
  /// ModelNumberCount(model) (values, window intervals, segment stamps, origin).
  Eigen::Index model_numbers = 0;
  /// input_numbers / model_numbers.
  double ratio = 0;
  /// Whether `model` is the automatic fit (always without a tolerance; with one, when the
  /// automatic fit meets it with fewer numbers than the tolerance fit).
  bool automatic = true;
};

/// Fits `values` (m x d; row i sampled at stamps_ns[i], any order) with FitCurve and stores the
/// result as a model. With a tolerance M, each gap-free segment (as FitCurve splits them) is
/// covered top-down instead: a window (first the whole segment) is fitted by least squares at the
/// highest degree its samples allow — N²/m <= curve.max_conditioning, <= curve.max_degree,
/// below the number of distinct stamps, well-conditioned normal equations — and if that fit is
/// within M at every sample where the curve may use the window (its core and half its overlap),
/// the window keeps the smallest degrees within M (per coordinate by bisection, then the
/// coordinate that dominates the worst sample raised until the Euclidean norm is within M too);
/// otherwise it is halved (windows overlap by curve.overlap of their core, as FitCurve's), down to
/// curve.min_window_samples samples per core. Blending windows that are within M keeps the curve
/// within M. The automatic model is kept instead when it meets M with fewer numbers.
///
/// Throws OptionError for bad options (CompressOptions::Validate); ComputeError when the
/// data cannot be fitted (FitCurve: fewer than 2 samples, all stamps equal) or M cannot be met,
/// giving the max and RMS error of the most accurate model found and the estimated noise.
Compression Compress(std::span<const int64_t> stamps_ns, const Eigen::Ref<const Eigen::MatrixXd>& values,
                     const CompressOptions& options = {});

/// What CompressionJson reports besides the compression: the files as the caller names them and the run.
struct CompressionRun {
  std::string input_path;
  Eigen::Index input_poses = 0;
  bool input_has_orientation = false;
  std::string model_path;
  size_t model_bytes = 0;       ///< size of the model file's text
  std::optional<double> tolerance_m;  ///< CompressOptions::tolerance as given
  double seconds = 0;           ///< wall-clock time of the run as the caller measured it
};

/// The JSON object of `cheval compress --json` (docs/compress.md): command, input, model,
/// tolerance_m, segments, windows, degrees (per window and coordinate), input_numbers, model_values,
/// model_numbers, compression_ratio, max_error_m, rms_error_m, worst_stamp (seconds, exact),
/// noise_sigma_m, automatic and seconds; two-space indented, with a final newline.
std::string CompressionJson(const CompressionRun& run, const Compression& compression);

}  // namespace cheval::cheb
