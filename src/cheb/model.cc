#include "cheval/cheb/model.h"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "cheval/cheb/chebyshev.h"
#include "cheval/common/error.h"
#include "cheval/common/options.h"
#include "cheval/traj/stamp.h"

namespace cheval::cheb {
namespace {

// Seconds from the origin of a stamp, exactly as FitCurve computes sample times.
double OffsetSeconds(int64_t stamp_ns, int64_t origin_ns) { return static_cast<double>(stamp_ns - origin_ns) * 1e-9; }

// The stamp whose offset from the origin converts to `seconds` (the inverse of OffsetSeconds on
// the times a curve's segments hold): the rounded guess, or a neighbour of it when the double
// product lost a nanosecond (offsets beyond ~26 days).
int64_t StampAtOffset(int64_t origin_ns, double seconds) {
  const auto guess = static_cast<int64_t>(std::llround(seconds * 1e9));
  for (int64_t delta : {0, -1, 1, -2, 2}) {
    if (OffsetSeconds(origin_ns + guess + delta, origin_ns) == seconds) return origin_ns + guess + delta;
  }
  return origin_ns + guess;
}

Eigen::VectorXd OrZeros(const Eigen::VectorXd& v, int dimension) {
  return v.size() == dimension ? v : Eigen::VectorXd::Zero(dimension);
}

}  // namespace

TrajectoryModel ModelFromCurve(const Curve& curve) {
  TrajectoryModel model;
  model.origin_ns = curve.origin_ns();
  model.dimension = curve.dimension();
  model.noise_sigma = OrZeros(curve.noise_sigma(), model.dimension);
  model.residual_rms = OrZeros(curve.residual_rms(), model.dimension);
  for (const CurveSegment& segment : curve.segments()) {
    ModelSegment stored;
    stored.first_ns = StampAtOffset(model.origin_ns, segment.begin);
    stored.last_ns = StampAtOffset(model.origin_ns, segment.end);
    for (const CurveWindow& window : segment.windows) {
      ModelWindow w{window.core_begin, window.core_end, window.fit_begin, window.fit_end, {}};
      for (int c = 0; c < model.dimension; ++c) {
        const int degree = window.degrees[static_cast<size_t>(c)];
        w.values.push_back(CoefficientsToValues(window.series.coefficients.col(c).head(degree + 1)));
      }
      stored.windows.push_back(std::move(w));
    }
    model.segments.push_back(std::move(stored));
  }
  return model;
}

Curve CurveFromModel(const TrajectoryModel& model) {
  const int d = model.dimension;
  std::vector<CurveSegment> segments;
  for (const ModelSegment& stored : model.segments) {
    CurveSegment segment;
    segment.begin = OffsetSeconds(stored.first_ns, model.origin_ns);
    segment.end = OffsetSeconds(stored.last_ns, model.origin_ns);
    for (const ModelWindow& w : stored.windows) {
      if (static_cast<int>(w.values.size()) != d) {
        throw std::invalid_argument("CurveFromModel: a window has a value array count other than the dimension");
      }
      CurveWindow window;
      window.core_begin = w.core_begin;
      window.core_end = w.core_end;
      window.fit_begin = w.fit_begin;
      window.fit_end = w.fit_end;
      int top = 0;
      for (int c = 0; c < d; ++c) {
        if (w.values[static_cast<size_t>(c)].size() == 0) throw std::invalid_argument("CurveFromModel: empty values");
        window.degrees.push_back(w.degree(static_cast<size_t>(c)));
        top = std::max(top, window.degrees.back());
      }
      window.series.interval = Interval{w.fit_begin, w.fit_end};
      window.series.coefficients = Eigen::MatrixXd::Zero(top + 1, d);
      for (int c = 0; c < d; ++c) {
        window.series.coefficients.col(c).head(window.degrees[static_cast<size_t>(c)] + 1) =
            ValuesToCoefficients(w.values[static_cast<size_t>(c)]);
      }
      segment.windows.push_back(std::move(window));
    }
    segments.push_back(std::move(segment));
  }
  return Curve::FromParts(model.origin_ns, std::move(segments), OrZeros(model.noise_sigma, d),
                          OrZeros(model.residual_rms, d));
}

namespace {

// FNV-1a, 64 bits (Fowler, Noll, Vo): per byte, xor then multiply by the FNV prime.
class Fnv1a64 {
 public:
  void Add(uint64_t word) {  // 8 bytes, least significant first, whatever the machine's order
    for (int i = 0; i < 8; ++i) {
      hash_ ^= (word >> (8 * i)) & 0xff;
      hash_ *= 0x100000001b3ULL;
    }
  }
  void Add(double x) { Add(std::bit_cast<uint64_t>(x)); }
  void Add(int64_t x) { Add(static_cast<uint64_t>(x)); }
  void Add(const Eigen::VectorXd& v) {
    Add(static_cast<int64_t>(v.size()));
    for (Eigen::Index i = 0; i < v.size(); ++i) Add(v[i]);
  }
  uint64_t hash() const { return hash_; }

 private:
  uint64_t hash_ = 0xcbf29ce484222325ULL;
};

}  // namespace

uint64_t ModelChecksum(const TrajectoryModel& model) {
  Fnv1a64 h;
  h.Add(int64_t{model.dimension});
  h.Add(model.origin_ns);
  h.Add(model.noise_sigma);
  h.Add(model.residual_rms);
  h.Add(int64_t{model.reconstruction.has_value()});
  if (model.reconstruction) {
    h.Add(static_cast<int64_t>(model.reconstruction->samples));
    h.Add(model.reconstruction->max);
    h.Add(model.reconstruction->rms);
    h.Add(model.reconstruction->worst_stamp_ns);
  }
  h.Add(int64_t{model.tolerance.has_value()});
  if (model.tolerance) h.Add(*model.tolerance);
  h.Add(static_cast<int64_t>(model.segments.size()));
  for (const ModelSegment& segment : model.segments) {
    h.Add(segment.first_ns);
    h.Add(segment.last_ns);
    h.Add(static_cast<int64_t>(segment.windows.size()));
    for (const ModelWindow& window : segment.windows) {
      for (double end : {window.core_begin, window.core_end, window.fit_begin, window.fit_end}) h.Add(end);
      h.Add(static_cast<int64_t>(window.values.size()));
      for (const Eigen::VectorXd& values : window.values) h.Add(values);
    }
  }
  return h.hash();
}

Eigen::Index ModelValueCount(const TrajectoryModel& model) {
  Eigen::Index count = 0;
  for (const ModelSegment& segment : model.segments) {
    for (const ModelWindow& window : segment.windows) {
      for (const Eigen::VectorXd& values : window.values) count += values.size();
    }
  }
  return count;
}

Eigen::Index ModelNumberCount(const TrajectoryModel& model) {
  Eigen::Index count = ModelValueCount(model) + 1;
  for (const ModelSegment& segment : model.segments) {
    count += 2 + 4 * static_cast<Eigen::Index>(segment.windows.size());
  }
  return count;
}

ReconstructionError MeasureReconstruction(const Curve& curve, std::span<const int64_t> stamps_ns,
                                          const Eigen::Ref<const Eigen::MatrixXd>& values) {
  ReconstructionError error;
  error.samples = static_cast<Eigen::Index>(stamps_ns.size());
  if (error.samples == 0) return error;
  Eigen::MatrixXd fitted;
  curve.EvaluateMany(stamps_ns, 0, &fitted);
  const Eigen::VectorXd squares = (fitted - values).rowwise().squaredNorm();
  Eigen::Index worst = 0;
  error.max = std::sqrt(squares.maxCoeff(&worst));
  error.rms = std::sqrt(squares.mean());
  error.worst_stamp_ns = stamps_ns[static_cast<size_t>(worst)];
  return error;
}

void CheckModelCovers(const TrajectoryModel& model, std::span<const int64_t> stamps_ns) {
  if (model.segments.empty()) throw ComputeError("the model has no segments");
  const int64_t first = model.segments.front().first_ns, last = model.segments.back().last_ns;
  for (size_t i = 0; i < stamps_ns.size(); ++i) {
    const int64_t stamp = stamps_ns[i];
    if (stamp < first || stamp > last) {
      throw ComputeError(fmt::format("stamp #{} ({} s) is outside the modelled time range {} s to {} s", i + 1,
                                     traj::FormatSeconds(stamp), traj::FormatSeconds(first),
                                     traj::FormatSeconds(last)));
    }
    // The last segment starting at or before the stamp; inside it unless the stamp is in the gap after it.
    const auto next = std::upper_bound(model.segments.begin(), model.segments.end(), stamp,
                                       [](int64_t s, const ModelSegment& segment) { return s < segment.first_ns; });
    const ModelSegment& segment = *std::prev(next);
    if (stamp > segment.last_ns) {
      throw ComputeError(fmt::format("stamp #{} ({} s) is inside a gap of the model: no samples from {} s to {} s",
                                     i + 1, traj::FormatSeconds(stamp), traj::FormatSeconds(segment.last_ns),
                                     traj::FormatSeconds(next->first_ns)));
    }
  }
}

std::vector<int64_t> ModelGridStamps(const TrajectoryModel& model, double rate_hz) {
  const OptionCheck check("ModelGridStamps");
  check(rate_hz > 0.0 && std::isfinite(rate_hz), "rate_hz", "must be a positive number of Hz, got {}", rate_hz);
  if (model.segments.empty()) throw ComputeError("the model has no segments");
  constexpr double kMaxStamps = 1e8;
  const double span_s = OffsetSeconds(model.segments.back().last_ns, model.origin_ns);
  const double count = std::floor(span_s * rate_hz) + 1.0;
  check(count <= kMaxStamps, "rate_hz", "must give at most {:.0f} stamps over the model's {:.3f} s; {} Hz gives {:.4g}",
        kMaxStamps, span_s, rate_hz, count);
  std::vector<int64_t> stamps;
  auto segment = model.segments.begin();
  for (int64_t k = 0; k < static_cast<int64_t>(count) && segment != model.segments.end(); ++k) {
    const int64_t stamp = model.origin_ns + std::llround(static_cast<double>(k) * 1e9 / rate_hz);
    while (segment != model.segments.end() && stamp > segment->last_ns) ++segment;
    if (segment != model.segments.end() && stamp >= segment->first_ns) stamps.push_back(stamp);
  }
  return stamps;
}

}  // namespace cheval::cheb
