#include "option_names.h"

#include <array>
#include <stdexcept>

#include "cheval/common/option_names.h"

namespace cheval::cli {
namespace {

// Field -> flag. A flag whose value selects an enum value names it ("--association continuous").
constexpr std::array kFlags = std::to_array<OptionName>({
    // traj::ReadOptions
    {"ReadOptions::format", "--format"},
    {"ReadOptions::columns", "--columns"},
    {"ReadOptions::kitti_times_path", "--kitti-times"},
    {"ReadOptions::topic", "--topic"},
    {"ReadOptions::record_time", "--bag-time"},
    // eval::AssociationOptions, AlignmentOptions, RpeOptions, EvaluationOptions
    {"AssociationOptions::max_diff_ns", "--t-max-diff"},
    {"AssociationOptions::offset_ns", "--t-offset"},
    {"AlignmentOptions::method", "--align"},
    {"AlignmentOptions::n_align", "--n-align"},
    {"RpeOptions::delta", "--delta"},
    {"RpeOptions::delta_unit", "--delta-unit"},
    {"RpeOptions::all_pairs", "--all-pairs"},
    {"EvaluationOptions::relation", "--relation"},
    {"EvaluationOptions::continuous_reference", "--association continuous"},
    {"EvaluationOptions::kitti_drift", "--kitti-drift"},
    {"EvaluationOptions::reference_velocity", "--gt-velocity"},
    {"EvaluationOptions::estimate_velocity_body_frame", "--velocity-frame"},
    {"EvaluationOptions::pose_only", "--pose-only"},
    // eval::VelocityOptions and the curve fit (cheb::CurveOptions)
    {"VelocityOptions::method", "--method"},
    {"VelocityOptions::angular", "--angular"},
    {"VelocityOptions::savgol_window_s", "--window"},
    {"CurveOptions::degree_method", "--degree"},
    {"CurveOptions::fixed_degree", "--degree"},
    {"CurveOptions::window_s", "--window"},
    // cheb::CompressOptions
    {"CompressOptions::tolerance", "--tolerance"},
    // cheb::ModelGridStamps (`cheval sample --rate`)
    {"ModelGridStamps::rate_hz", "--rate"},
    // report::ReportOptions
    {"ReportOptions::max_points", "--max-points"},
    // sim::MotionOptions, MeasurementOptions, EstimatorSimOptions
    {"MotionOptions::kind", "--kind"},
    {"MotionOptions::seed", "--seed"},
    {"MotionOptions::duration_s", "--duration"},
    {"MotionOptions::rate_hz", "--rate"},
    {"MeasurementOptions::noise_m", "--noise"},
    {"MeasurementOptions::rotation_noise_rad", "--rotation-noise"},
    {"MeasurementOptions::jitter_s", "--jitter"},
    {"MeasurementOptions::dropout_probability", "--dropout"},
    {"MeasurementOptions::gap_count", "--gap-count"},
    {"MeasurementOptions::gap_s", "--gap-seconds"},
    {"EstimatorSimOptions::rate_hz", "--estimate-rate"},
    {"EstimatorSimOptions::velocity_random_walk", "--estimate-drift"},
    {"EstimatorSimOptions::rotation_random_walk_rad", "--estimate-rotation-drift"},
    // sim::QuadrotorSimOptions
    {"QuadrotorSimOptions::scenario", "--scenario"},
    {"QuadrotorSimOptions::seed", "--seed"},
    {"QuadrotorSimOptions::duration_s", "--duration"},
    // estim::QuadrotorEstimateOptions
    {"QuadrotorEstimateOptions::degree", "--degree"},
    {"QuadrotorEstimateOptions::segment_s", "--segment"},
    // estim::ThrustEstimateOptions
    {"ThrustEstimateOptions::degree", "--degree"},
    {"ThrustEstimateOptions::segment_s", "--segment"},
    {"ThrustEstimateOptions::use_imu", "--imu"},
    {"ThrustEstimateOptions::position_rate_hz", "--position-rate"},
    {"ThrustEstimateOptions::position_sigma_m", "--position-sigma"},
    {"ThrustEstimateOptions::position_noise_m", "--position-noise"},
    {"ThrustEstimateOptions::seed", "--seed"},
    {"ThrustEstimateOptions::imu_sigma_mps2", "--imu-sigma"},
    {"ThrustEstimateOptions::sigma_acceleration", "--sigma-acceleration"},
    {"ThrustEstimateOptions::sigma_rotor_rate", "--sigma-rotor-rate"},
    {"ThrustEstimateOptions::rotor_delay_s", "--rotor-delay"},
});

}  // namespace

std::string Flag(std::string_view field, std::string_view prefix) {
  for (const OptionName& entry : kFlags) {
    if (entry.field == field) {
      const std::string_view flag = entry.name.substr(0, entry.name.find(' '));
      return "--" + std::string(prefix) + std::string(flag.substr(2));
    }
  }
  throw std::logic_error("no flag for the option " + std::string(field));
}

std::string Spell(std::string_view message) { return SpellOptions(message, kFlags); }

std::span<const OptionName> FlagNames() { return kFlags; }

}  // namespace cheval::cli
