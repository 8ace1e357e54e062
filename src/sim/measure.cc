// The measured copy of a motion (gaps, dropouts, jitter, position and orientation noise) and noise
// added to any trajectory (docs/sim.md, "The measured copy").
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "cheval/common/error.h"
#include "cheval/common/options.h"
#include "cheval/common/random.h"
#include "cheval/sim/motion.h"
#include "internal/streams.h"

namespace cheval::sim {

void MeasurementOptions::Validate() const {
  const OptionCheck check("MeasurementOptions");
  check(noise_m >= 0 && std::isfinite(noise_m), "noise_m", "must be a non-negative number of metres, got {}", noise_m);
  check(jitter_s >= 0 && std::isfinite(jitter_s), "jitter_s", "must be a non-negative number of seconds, got {}",
        jitter_s);
  check(rotation_noise_rad >= 0 && std::isfinite(rotation_noise_rad), "rotation_noise_rad",
        "must be a non-negative number of radians, got {}", rotation_noise_rad);
  check(dropout_probability >= 0 && dropout_probability < 1, "dropout_probability",
        "must be a probability in [0, 1), got {}", dropout_probability);
  check(gap_count >= 0, "gap_count", "must be non-negative, got {}", gap_count);
  if (gap_count > 0) {
    check(gap_s > 0 && std::isfinite(gap_s), "gap_s", "must be a positive number of seconds when there are gaps, got {}",
          gap_s);
  } else {
    check(gap_s == 0, "gap_s", "must be 0 when the gap count is 0, got {}", gap_s);
  }
}

traj::Trajectory Measure(const MotionModel& model, const MeasurementOptions& measurement) {
  measurement.Validate();
  const MotionOptions& options = model.options();
  const double duration = *options.duration_s, rate = *options.rate_hz;
  const double noise = measurement.noise_m, jitter = measurement.jitter_s;
  const double rotation_noise = measurement.rotation_noise_rad;
  const double dropout = measurement.dropout_probability;
  const int gap_count = measurement.gap_count;
  const double gap_s = measurement.gap_s;
  // The rules that depend on the model's duration and rate.
  const OptionCheck check("MeasurementOptions");
  check(jitter < duration, "jitter_s", "must be below the duration ({} s), got {}", duration, jitter);
  const double slot = gap_count > 0 ? duration / gap_count : 0.0;
  const double margin = 1.0 / rate;
  check(gap_count == 0 || gap_s + 2.0 * margin < slot, "gap_s",
        "must fit {} gaps in the duration ({} s): each needs a slot of duration / gap count longer than the gap plus "
        "two sample periods, got {}",
        gap_count, duration, gap_s);

  const std::vector<int64_t> nominal = model.NominalStamps();
  const int64_t start = options.start_stamp_ns;
  // Gaps as [begin, end) offsets in ns from the start, one per slot.
  std::vector<std::pair<int64_t, int64_t>> gaps;
  Random gap_random(options.seed, internal::kGaps);
  for (int k = 0; k < gap_count; ++k) {
    const double begin = k * slot + margin + gap_random.Uniform() * (slot - gap_s - 2.0 * margin);
    gaps.emplace_back(std::llround(begin * 1e9), std::llround((begin + gap_s) * 1e9));
  }
  Random dropout_random(options.seed, internal::kDropout), jitter_random(options.seed, internal::kJitter),
      noise_random(options.seed, internal::kNoise), rotation_random(options.seed, internal::kRotationNoise);

  struct Sample {
    int64_t stamp;
    Eigen::Vector3d noise;
    Eigen::Vector3d rotation_noise;
  };
  std::vector<Sample> kept;
  kept.reserve(nominal.size());
  size_t gap = 0;
  for (const int64_t stamp : nominal) {
    // Every stream draws for every nominal sample, so each effect is independent of the others.
    const bool dropped = dropout_random.Uniform() < dropout;
    const double offset_s = jitter_random.Normal() * jitter;
    const Eigen::Vector3d n = internal::NormalVector(noise_random);
    const Eigen::Vector3d r = internal::NormalVector(rotation_random);
    const int64_t offset = stamp - start;
    while (gap < gaps.size() && offset >= gaps[gap].second) ++gap;
    const bool in_gap = gap < gaps.size() && offset >= gaps[gap].first;
    if (dropped || in_gap) continue;
    kept.push_back({stamp + static_cast<int64_t>(std::llround(offset_s * 1e9)), noise * n, rotation_noise * r});
  }
  check(kept.size() >= 2, "dropout_probability",
        "must leave, with the gaps, at least 2 of the {} samples (it left {}), got {}", nominal.size(), kept.size(),
        dropout);
  // Jittered stamps: sorted, then each one not above its predecessor moved to predecessor + 1 ns.
  std::stable_sort(kept.begin(), kept.end(), [](const Sample& a, const Sample& b) { return a.stamp < b.stamp; });
  std::vector<int64_t> stamps(kept.size());
  for (size_t i = 0; i < kept.size(); ++i) {
    if (i > 0 && kept[i].stamp <= kept[i - 1].stamp) kept[i].stamp = kept[i - 1].stamp + 1;
    stamps[i] = kept[i].stamp;
  }

  const traj::Trajectory truth = SampleMotion(model, stamps);
  traj::Trajectory measured(traj::Channels{traj::OrientationKind::kQuaternion, false, false, true});
  measured.Reserve(truth.size());
  const auto quaternions = truth.View().quaternions();
  for (Eigen::Index i = 0; i < truth.size(); ++i) {
    const Eigen::Vector3d p = truth.positions().col(i) + kept[static_cast<size_t>(i)].noise;
    Eigen::Vector4d q = quaternions.col(i);
    const Eigen::Vector3d& r = kept[static_cast<size_t>(i)].rotation_noise;
    if (rotation_noise > 0) {
      const double angle = r.norm();
      const Eigen::Quaterniond perturbed =
          Eigen::Quaterniond(q[3], q[0], q[1], q[2]) *
          Eigen::Quaterniond(Eigen::AngleAxisd(angle, angle > 0 ? Eigen::Vector3d(r / angle) : Eigen::Vector3d::UnitX()));
      q << perturbed.x(), perturbed.y(), perturbed.z(), perturbed.w();
    }
    measured.Append(stamps[static_cast<size_t>(i)], p.data(), q.data());
  }
  return measured;
}

traj::Trajectory AddPositionNoise(const traj::TrajectoryView& truth, double sigma_m, uint64_t seed) {
  if (!(sigma_m >= 0) || !std::isfinite(sigma_m)) {
    throw UsageError(fmt::format("AddPositionNoise: sigma_m must be a non-negative number of metres, got {}", sigma_m));
  }
  traj::Channels channels = truth.channels();
  channels.velocity = false;
  channels.angular_velocity = false;
  traj::Trajectory measured(channels);
  measured.Reserve(truth.size());
  Random random(seed, internal::kAddNoise);
  const auto p = truth.positions();
  const int stride = traj::OrientationStride(channels.orientation);
  std::vector<double> orientation(static_cast<size_t>(std::max(stride, 1)));
  for (Eigen::Index i = 0; i < truth.size(); ++i) {
    const Eigen::Vector3d noisy =
        p.col(i) + sigma_m * internal::NormalVector(random);
    if (channels.orientation == traj::OrientationKind::kQuaternion) {
      const Eigen::Vector4d q = truth.quaternions().col(i);
      std::copy(q.data(), q.data() + 4, orientation.begin());
    } else if (channels.orientation == traj::OrientationKind::kMatrix) {
      const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> R = truth.Rotation(i);
      std::copy(R.data(), R.data() + 9, orientation.begin());
    }
    measured.Append(truth.stamps_ns()[i], noisy.data(), orientation.data());
  }
  return measured;
}

}  // namespace cheval::sim
