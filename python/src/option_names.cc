// Python's spelling of the library's options: one table from each options field (`STRUCT::FIELD`,
// as the library names it in OptionError and in its messages) to its keyword argument. The bindings
// take their keywords from it (Keyword) and the exception translator (module.cc) passes every
// library message through Spell: "n_align needs align (...)" where the library says
// "AlignmentOptions::n_align needs AlignmentOptions::method (...)". A field missing from the table
// stays STRUCT::FIELD.
#include <array>
#include <stdexcept>
#include <string>

#include "bindings.h"
#include "cheval/common/option_names.h"

namespace cheval::python {
namespace {

// Field -> keyword. A keyword whose value selects an enum value names it ("association='continuous'").
constexpr std::array kKeywords = std::to_array<OptionName>({
    // traj::ReadOptions
    {"ReadOptions::format", "format"},
    {"ReadOptions::columns", "columns"},
    {"ReadOptions::kitti_times_path", "kitti_times"},
    {"ReadOptions::topic", "topic"},
    {"ReadOptions::record_time", "bag_time"},
    // eval::AssociationOptions, AlignmentOptions, RpeOptions, EvaluationOptions
    {"AssociationOptions::max_diff_ns", "t_max_diff"},
    {"AssociationOptions::offset_ns", "t_offset"},
    {"AlignmentOptions::method", "align"},
    {"AlignmentOptions::n_align", "n_align"},
    {"RpeOptions::delta", "delta"},
    {"RpeOptions::delta_unit", "delta_unit"},
    {"RpeOptions::all_pairs", "all_pairs"},
    {"EvaluationOptions::relation", "relation"},
    {"EvaluationOptions::continuous_reference", "association='continuous'"},
    {"EvaluationOptions::kitti_drift", "kitti_drift"},
    {"EvaluationOptions::reference_velocity", "gt_velocity"},
    {"EvaluationOptions::estimate_velocity_body_frame", "velocity_frame"},
    {"EvaluationOptions::pose_only", "pose_only"},
    // eval::VelocityOptions and the curve fit (cheb::CurveOptions)
    {"VelocityOptions::method", "method"},
    {"VelocityOptions::angular", "angular"},
    {"VelocityOptions::savgol_window", "savgol_window"},
    {"CurveOptions::degree_method", "degree"},
    {"CurveOptions::fixed_degree", "degree"},
    {"CurveOptions::window_s", "window"},
    {"CurveOptions::noise_sigma", "noise"},
    {"CurveOptions::threads", "threads"},
    // cheb::CompressOptions
    {"CompressOptions::tolerance", "tolerance"},
    // sim::MotionOptions, MeasurementOptions (cheval.simulate)
    {"MotionOptions::kind", "kind"},
    {"MotionOptions::seed", "seed"},
    {"MotionOptions::duration_s", "duration"},
    {"MotionOptions::rate_hz", "rate"},
    {"MeasurementOptions::noise_m", "noise"},
    {"MeasurementOptions::rotation_noise_rad", "rotation_noise"},
    {"MeasurementOptions::jitter_s", "jitter"},
    {"MeasurementOptions::dropout_probability", "dropout"},
    {"MeasurementOptions::gap_count", "gap_count"},
    {"MeasurementOptions::gap_s", "gap_seconds"},
    // sim::QuadrotorSimOptions, estim::QuadrotorEstimateOptions (cheval.estimate_quadrotor)
    {"QuadrotorSimOptions::scenario", "scenario"},
    {"QuadrotorSimOptions::seed", "seed"},
    {"QuadrotorSimOptions::duration_s", "duration"},
    {"QuadrotorEstimateOptions::degree", "degree"},
    {"QuadrotorEstimateOptions::segment_s", "segment"},
});

}  // namespace

const char* Keyword(std::string_view field) {
  for (const OptionName& entry : kKeywords) {
    if (entry.field == field) return entry.name.data();  // the literals of the table: NUL-terminated
  }
  throw std::logic_error("no keyword for the option " + std::string(field));
}

std::string Spell(std::string_view message) { return SpellOptions(message, kKeywords); }

}  // namespace cheval::python
