#pragma once
/// \file
/// Time association of a reference and an estimate: which reference pose each estimate pose is
/// compared with. The semantics are evo's (`evo.core.sync.associate_trajectories`, v1.36.5;
/// docs/evaluation.md, "Association"), computed in O((n + m) log m) instead of evo's O(n·m) brute force:
///
/// - iterate over the **shorter** list (the estimate when both have the same length) in file order;
/// - for each of its stamps s take the **nearest** stamp of the other list (reference stamps minus the
///   offset, or estimate stamps plus the offset), the **first** in file order on exact ties;
/// - keep the pair when |dt| <= max_diff (**inclusive**);
/// - the nearest stamp and the tolerance test are decided on evo's float64 seconds (EvoStampSeconds),
///   so a stamp exactly half-way between two others, which is a tie in exact arithmetic, goes
///   where evo's rounding sends it (docs/evaluation.md, "Ties").
///
/// The result is not one-to-one: a pose of the longer list may be used by several pairs. Unsorted and
/// duplicated stamps give exactly the pairs of the brute force. Stamps are int64 nanoseconds; the
/// exact search finds the candidates within float rounding of the nearest, and evo's float64
/// differences choose among them (AssociationOptions::evo_float_seconds).

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "cheval/traj/trajectory.h"

namespace cheval::eval {

/// How evo turns the stamps of a file into the float64 seconds it compares (`file_interface`):
/// text seconds (TUM, KITTI times) are parsed as the nearest double to the decimal; integer
/// nanoseconds (EuRoC, pose CSV) are parsed as a double and divided by 1e9.
enum class EvoStampSeconds {
  kDecimal,            ///< double nearest to the decimal seconds (exact for <= 9 decimals)
  kNanosecondsOver1e9  ///< double(ns) / 1e9, both steps rounded as numpy does
};

/// Options of the association; the defaults are evo's (t_max_diff 0.01 s, t_offset 0).
struct AssociationOptions {
  /// Largest accepted |t_ref - (t_est + offset)|, nanoseconds (inclusive). Must be >= 0.
  int64_t max_diff_ns = 10'000'000;
  /// Added to every estimate stamp: est_time + offset ≈ ref_time (evo's t_offset), nanoseconds.
  int64_t offset_ns = 0;
  /// Decide as evo does in float64 seconds (true, the default: evo's pairs exactly, also when an
  /// estimate stamp is exactly half-way between two reference stamps or |dt| is within float
  /// rounding of max_diff), or in exact nanoseconds (false).
  bool evo_float_seconds = true;
  /// How evo would read the stamps of each side (used when evo_float_seconds).
  EvoStampSeconds ref_seconds = EvoStampSeconds::kDecimal;
  EvoStampSeconds est_seconds = EvoStampSeconds::kDecimal;

  /// The options from seconds as a user gives them, each rounded to the nearest nanosecond. Throws
  /// OptionError naming max_diff_ns or offset_ns when a value is not finite or does not fit in int64.
  static AssociationOptions FromSeconds(double max_diff_s, double offset_s);
  /// The fields in seconds (exactly the seconds given to FromSeconds when they have at most nine
  /// decimals: ns / 1e9 is the double nearest to that decimal).
  double max_diff_s() const { return static_cast<double>(max_diff_ns) / 1e9; }
  double offset_s() const { return static_cast<double>(offset_ns) / 1e9; }
  /// Throws OptionError for a negative max_diff_ns.
  void Validate() const;
};

/// Pairs of associated poses: pair k compares reference pose `ref[k]` with estimate pose `est[k]`.
struct Association {
  std::vector<Eigen::Index> ref;
  std::vector<Eigen::Index> est;
  /// True when poses were paired by index (KITTI files without stamps), not by time.
  bool by_index = false;

  /// Number of pairs.
  Eigen::Index size() const { return static_cast<Eigen::Index>(est.size()); }
  bool empty() const { return est.empty(); }
};

/// Associates two lists of stamps with evo's rule (see the file comment). Any order, duplicates
/// allowed. Returns the pairs in the order of the shorter list (possibly none). Throws OptionError
/// for a negative max_diff (options.Validate()).
Association AssociateStamps(std::span<const int64_t> ref_stamps_ns, std::span<const int64_t> est_stamps_ns,
                            const AssociationOptions& options = {});

/// Associates two trajectories. When either has no stamps (KITTI without a times file), pose i is
/// paired with pose i, as evo's `kitti` mode does, and the lengths must agree. Throws ComputeError
/// when the lengths differ in that case, and when no pair is found: the message gives both stamp
/// ranges and suggests an offset or checking the stamp units.
Association Associate(const traj::TrajectoryView& ref, const traj::TrajectoryView& est,
                      const AssociationOptions& options = {});

/// The stamps of the poses of `association` on one side, in pair order.
std::vector<int64_t> PairedStamps(std::span<const int64_t> stamps_ns, std::span<const Eigen::Index> indices);

/// The float64 seconds evo compares for a stamp of `ns` nanoseconds read as `kind`.
double EvoSeconds(int64_t ns, EvoStampSeconds kind);

/// Converts seconds (as a user gives them) to nanoseconds, rounding to the nearest; throws UsageError
/// naming `what` (an option as `STRUCT::FIELD`, common/option_names.h) if the value is not finite or
/// does not fit in int64.
int64_t SecondsToNanoseconds(double seconds, const std::string& what);

}  // namespace cheval::eval
