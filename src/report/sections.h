#pragma once
// Internal to src/report: the report's relative pose error section (RPE at distances of the
// reference's length, over time and as box plots per distance, as rpg_trajectory_evaluation draws
// them) and the ASE rotation part in degrees.

#include <cstddef>
#include <string>
#include <vector>

#include "series.h"

namespace cheval::report::detail {

// The RPE distances: 10, 20, 30, 40 and 50 % of the reference's path length, floored to whole
// metres from 10 m on and to two significant digits below; empty for a path shorter than 1 mm.
std::vector<double> RpeDistances(const traj::TrajectoryView& ref);

// The RPE of one estimate at each distance over the APE's pairs and alignment (eval::RpeIndexPairs
// with δ in metres, all pairs; eval::RpeErrors): per distance {"delta", "pairs", "trans" (box),
// "rot" (box, degrees, with orientation on both sides), "series" (t, trans, rot)}; "relation" is
// the translation relation ("trans_part", or "point_distance" without orientation). A distance
// without a pair is left out with a note.
Json RpeJson(const traj::TrajectoryView& ref, const traj::TrajectoryView& est, const eval::EvaluationResult& ape,
             const std::vector<double>& distances, const Clock& clock, std::size_t max_points, const std::string& name,
             std::vector<std::string>* notes);

// The ASE rotation part ‖R_qᵀR_p − I‖_F = 2√2·sin(θ/2) as the angle θ in degrees.
std::vector<double> RotationPartDegrees(const std::vector<double>& rotation_part);

}  // namespace cheval::report::detail
