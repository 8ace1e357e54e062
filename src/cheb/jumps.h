#pragma once
// Isolated defects of sampled motion that no smooth curve should absorb (FitCurve, robust fits):
// a sample displaced from its neighbours (a glitch) or a few consecutive ones (an excursion: a
// marker swap, a lost track), a jump of the positions that persists (a relocalisation of the
// ground truth), and a jump of the velocity (an impact). Found on the slopes
// between consecutive samples, d_j = (z_{j+1} − z_j)/(t_{j+1} − t_j), each compared with straight
// lines fitted to its neighbours on either side; docs/velocity.md, "Jumps and glitches".

#include <utility>
#include <vector>

#include <Eigen/Core>

namespace cheval::cheb::internal {

struct Jumps {
  /// Samples to leave out of the fit (glitches and excursions), ascending, each once.
  std::vector<Eigen::Index> outliers;
  /// Boundaries b (ascending) where the motion jumps between samples b and b + 1 and its rate does
  /// not go on across (an impact, or a jump too close to another to tell): the fit is split there
  /// as at a gap.
  std::vector<Eigen::Index> breaks;
  /// Boundaries b (ascending) where the values step between samples b and b + 1 while the rate goes
  /// on across (a correction of filtered ground truth): b and the step, to be taken out of the
  /// samples after b before fitting and added back to the curve's values.
  std::vector<std::pair<Eigen::Index, Eigen::VectorXd>> steps;
};

class NoiseProfile;

/// t: sorted times (s), z: m x d samples, gaps: boundaries b that are already gaps (not crossed by
/// the neighbour lines), noise: the samples' noise σ per coordinate (sets the floor of the local
/// scale), `profile` (optional): the samples' noise profile, which raises that floor where the
/// samples are noisier (a burst's slopes are not jumps). O(m) for a fixed neighbourhood; each
/// pass's departures and scales are taken on up to `threads` threads.
Jumps FindJumps(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, const std::vector<Eigen::Index>& gaps,
                const Eigen::VectorXd& noise, const NoiseProfile* profile = nullptr, int threads = 1);

}  // namespace cheval::cheb::internal
