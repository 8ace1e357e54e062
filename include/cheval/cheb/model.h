#pragma once
/// \file
/// The pseudo-spectral form of a fitted trajectory: what `cheval compress` stores and `cheval
/// sample` evaluates (docs/compress.md has the JSON schema).
///
/// A TrajectoryModel is a windowed Chebyshev curve (cheb::Curve) held by the VALUES of each window's
/// polynomials at their Chebyshev–Gauss–Lobatto points rather than by coefficients: a value is a
/// position in metres a user can read, and the two are equivalent (ValuesToCoefficients, a DCT-I).
/// Coordinate c of a window of degree N_c stores N_c + 1 values f_j = p(t_j) at
/// t_j = FromUnit(cos(jπ/N_c)), j = 0..N_c, on the window's fit interval — descending in time, the
/// first value at the end of the interval (chebyshev.h's convention). Degree 0 stores the constant.
/// Times are seconds from `origin_ns` (never epoch seconds); segment ends are exact int64 stamps.

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "cheval/cheb/curve.h"

namespace cheval::cheb {

/// One window of a model: its core and fit interval (seconds from the model's origin, as in
/// CurveWindow) and, per coordinate, the values of its polynomial at the Chebyshev points of the
/// fit interval.
struct ModelWindow {
  double core_begin = 0, core_end = 0;
  double fit_begin = 0, fit_end = 0;
  /// values[c] has degree_c + 1 entries: p_c(t_j) at t_j = fit interval's FromUnit(cos(jπ/degree_c)),
  /// j = 0..degree_c (descending t); one entry, the constant, for degree 0.
  std::vector<Eigen::VectorXd> values;

  /// The degree of coordinate c (values[c].size() - 1).
  int degree(size_t c) const { return static_cast<int>(values[c].size()) - 1; }
};

/// A gap-free stretch of the modelled data: the stamps of its first and last sample and its
/// windows in time order, whose cores tile [first, last].
struct ModelSegment {
  int64_t first_ns = 0, last_ns = 0;
  std::vector<ModelWindow> windows;
};

/// How far a curve is from samples: per sample the Euclidean norm of (curve - sample) over the
/// coordinates (metres for positions), its maximum and root mean square.
struct ReconstructionError {
  Eigen::Index samples = 0;
  double max = 0;
  double rms = 0;
  int64_t worst_stamp_ns = 0;  ///< stamp of the sample with the largest error
};

/// A trajectory's pseudo-spectral model. Plain data: build it with ModelFromCurve (or Compress,
/// compress.h) or ParseModelJson, evaluate it through CurveFromModel.
struct TrajectoryModel {
  /// Stamp of t = 0 for every time in the model (the first sample's stamp for fitted models).
  int64_t origin_ns = 0;
  /// Coordinates per sample (3 for positions), 1..4.
  int dimension = 0;
  std::vector<ModelSegment> segments;
  /// Diagnostics of the fit the model came from, per coordinate (zeros when unknown): the noise σ
  /// the degrees were chosen for and the RMS of the fit residuals (Curve::noise_sigma, residual_rms).
  Eigen::VectorXd noise_sigma;
  Eigen::VectorXd residual_rms;
  /// Informational: the error of this model at the samples it was built from, and the tolerance
  /// asked for (Compress fills both; they are not needed to evaluate the model).
  std::optional<ReconstructionError> reconstruction;
  std::optional<double> tolerance;
};

/// The model of a curve: each coordinate's coefficients (up to its own degree) turned into values
/// at the Chebyshev points (CoefficientsToValues). Segment stamps are recovered exactly from the
/// curve's segment times (the stamp whose offset from the origin converts to that time).
TrajectoryModel ModelFromCurve(const Curve& curve);

/// The curve of a model (ValuesToCoefficients per coordinate, Curve::FromParts). Deterministic: the
/// same model gives bit-identical evaluations. Throws std::invalid_argument for an inconsistent
/// model (ParseModelJson never returns one).
Curve CurveFromModel(const TrajectoryModel& model);

/// Numbers stored in the model's `values` arrays: Σ over windows and coordinates of degree + 1.
Eigen::Index ModelValueCount(const TrajectoryModel& model);

/// Every number the model needs to be evaluated: the values, 4 interval ends per window (core and
/// fit), 2 stamps per segment and the origin. Degrees are not counted: they are the lengths of the
/// value arrays. This is the denominator of the compression ratio (compress.h).
Eigen::Index ModelNumberCount(const TrajectoryModel& model);

/// The FNV-1a 64-bit hash of the model's content in a fixed order (docs/compress.md, "Checksum"):
/// dimension, origin, the diagnostics (with their lengths and whether present), then per segment
/// its stamps and window count, per window its four interval ends and per coordinate the number of
/// values and their IEEE-754 bit patterns; every item as 8 bytes, least significant first. Equal
/// for two models exactly when (but for hash collisions) every stored number is bit-identical, so
/// reformatting the JSON keeps it and changing any number changes it.
uint64_t ModelChecksum(const TrajectoryModel& model);

/// ReconstructionError of `curve` at samples `values` (m x d) taken at `stamps_ns` (any order).
/// Throws ComputeError when a stamp lies outside the curve (outside its data or in a gap).
ReconstructionError MeasureReconstruction(const Curve& curve, std::span<const int64_t> stamps_ns,
                                          const Eigen::Ref<const Eigen::MatrixXd>& values);

/// Throws ComputeError unless every stamp lies inside a segment of the model (between its first
/// and last stamp, ends included): the message names the first stamp that does not (1-based index
/// and value) and whether it is before, after or between the modelled stretches.
void CheckModelCovers(const TrajectoryModel& model, std::span<const int64_t> stamps_ns);

/// The stamps origin_ns + round(k·1e9/rate_hz) ns, k = 0, 1, ..., that lie inside a segment (from
/// the first modelled stamp to the last; stamps in gaps between segments are left out). Throws
/// OptionError ("ModelGridStamps::rate_hz must be ...") unless rate_hz is positive and finite and
/// the grid has at most 1e8 stamps over the model's span.
std::vector<int64_t> ModelGridStamps(const TrajectoryModel& model, double rate_hz);

/// The model as JSON text (docs/compress.md): `"format": "cheval-trajectory-model"`, `"version": 2`,
/// and last `"checksum": "fnv1a64:<16 hex digits>"` (ModelChecksum). Every double is written in the
/// shortest form that reads back to the same double, stamps as integers, so
/// ParseModelJson(WriteModelJson(m)) evaluates bit-identically to m.
std::string WriteModelJson(const TrajectoryModel& model);

/// Parses and validates a model. Throws InputError (`path:LINE:COLUMN` for invalid JSON, else
/// `path:0:0`) naming the element and what was expected, e.g.
/// `segments[0].windows[2].values[1]: expected an array of finite numbers, got "x"`, for
/// anything that would not give a valid curve: wrong format or version, unknown or missing keys,
/// non-finite numbers, empty arrays, unordered segments, windows that do not tile their segment or
/// whose fit interval does not contain their core, value arrays per window other than `dimension`;
/// for version 2 (what WriteModelJson writes) a missing checksum or one that differs from
/// ModelChecksum of the numbers read ("checksum: checksum mismatch: ..."). Version 1 (written
/// before the checksum existed) is read without one, with every structural check above.
TrajectoryModel ParseModelJson(std::string_view text, const std::string& path);

/// Reads and parses a model file (InputError when it cannot be opened or is invalid). Write one
/// with WriteOutput(path, WriteModelJson(model)) (common/output.h).
TrajectoryModel ReadModel(const std::string& path);

}  // namespace cheval::cheb
