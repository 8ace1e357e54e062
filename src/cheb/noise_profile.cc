#include "noise_profile.h"

#include <algorithm>

namespace cheval::cheb::internal {

NoiseProfile::NoiseProfile(const Eigen::VectorXd& level) : level_(level), maximum_(level) {}

NoiseProfile::NoiseProfile(const Eigen::VectorXd& level, const DifferenceMagnitudes& magnitudes, Eigen::Index m)
    : level_(level), maximum_(level) {
  const Eigen::Index d = level.size();
  cumulative_ = Eigen::MatrixXd::Zero(m + 1, d);
  const Eigen::VectorXd raise = kRaise * level, burst = kBurst * level;
  // Where the 4th differences' median over a stretch cannot exceed a threshold (their counts say
  // so), no median is taken.
  const Eigen::MatrixXi counts = magnitudes.CountsAbove(raise), burst_counts = magnitudes.CountsAbove(burst);
  auto may_exceed = [d](const Eigen::MatrixXi& above_counts, Eigen::Index from, Eigen::Index to) {
    for (Eigen::Index c = 0; c < d; ++c) {
      const int usable = above_counts(to, 2 * c) - above_counts(from, 2 * c);
      const int above = above_counts(to, 2 * c + 1) - above_counts(from, 2 * c + 1);
      if (usable > 0 && above >= usable - usable / 2) return true;
    }
    return false;
  };
  const Eigen::Index blocks = (m + kBlock - 1) / kBlock;
  Eigen::MatrixXd bursts = Eigen::MatrixXd::Zero(blocks, d);
  for (Eigen::Index b = 0; b < blocks; ++b) {
    const Eigen::Index begin = b * kBlock, end = std::min(m, begin + kBlock);
    if (!may_exceed(burst_counts, begin, end)) continue;
    const Eigen::VectorXd own = magnitudes.SigmaIfAbove(begin, end, burst);
    for (Eigen::Index c = 0; c < d; ++c) {
      if (own[c] > burst[c]) bursts(b, c) = own[c];
    }
  }
  for (Eigen::Index begin = 0; begin < m; begin += kBlock) {
    const Eigen::Index end = std::min(m, begin + kBlock);
    const Eigen::Index from = std::max<Eigen::Index>(0, begin - kPooledBlocks * kBlock);
    const Eigen::Index to = std::min(m, end + kPooledBlocks * kBlock);
    Eigen::VectorXd local = may_exceed(counts, from, to) ? magnitudes.SigmaIfAbove(from, to, raise) : level;
    // A burst shorter than half the pool leaves its median; the block's own estimate shows it,
    // and the blocks beside it take it too (a burst's edge half fills its block, whose own
    // estimate may stay below the threshold while its windows fit the burst's noise).
    const Eigen::Index b = begin / kBlock;
    for (Eigen::Index k = std::max<Eigen::Index>(0, b - 1); k <= std::min(blocks - 1, b + 1); ++k) {
      local = local.cwiseMax(bursts.row(k).transpose());
    }
    Eigen::RowVectorXd variance = level.cwiseAbs2().transpose();
    bool raised = false;
    for (Eigen::Index c = 0; c < d; ++c) {
      if (local[c] > raise[c]) {
        variance[c] = local[c] * local[c];
        maximum_[c] = std::max(maximum_[c], local[c]);
        raised = true;
      }
    }
    if (raised) raised_samples_ += end - begin;
    for (Eigen::Index i = begin; i < end; ++i) cumulative_.row(i + 1) = cumulative_.row(i) + variance;
  }
  if (raised_samples_ == 0) cumulative_.resize(0, 0);
}

Eigen::VectorXd NoiseProfile::Over(Eigen::Index first, Eigen::Index count) const {
  if (count <= 0 || cumulative_.size() == 0) return level_;
  const Eigen::RowVectorXd sum = cumulative_.row(first + count) - cumulative_.row(first);
  return (sum.transpose() / static_cast<double>(count)).cwiseMax(0.0).cwiseSqrt();
}

}  // namespace cheval::cheb::internal
