#include "option_names.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <stdexcept>

#include <fmt/format.h>

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
    {"EvaluationOptions::identity_reference_is_position_only", "--ref-has-orientation"},
    // eval::VelocityOptions and the curve fit (cheb::CurveOptions)
    {"VelocityOptions::method", "--method"},
    {"VelocityOptions::angular", "--angular"},
    {"VelocityOptions::savgol_window_s", "--window"},
    {"CurveOptions::degree_method", "--degree"},
    {"CurveOptions::fixed_degree", "--degree"},
    {"CurveOptions::window_s", "--window"},
    {"CurveOptions::threads", "--threads"},
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
    // estim::RotorEstimateOptions
    {"RotorEstimateOptions::degree", "--degree"},
    {"RotorEstimateOptions::segment_s", "--segment"},
    {"RotorEstimateOptions::position_sigma_m", "--position-sigma"},
    {"RotorEstimateOptions::attitude_sigma_rad", "--attitude-sigma"},
    {"RotorEstimateOptions::rate_sigma_radps", "--rate-sigma"},
    {"RotorEstimateOptions::rotor_sigma_radps", "--rotor-sigma"},
    {"RotorEstimateOptions::sigma_acceleration", "--sigma-acceleration"},
    {"RotorEstimateOptions::sigma_angular_acceleration", "--sigma-angular-acceleration"},
    {"RotorEstimateOptions::sigma_rotor_rate", "--sigma-rotor-rate"},
    {"RotorEstimateOptions::baseline_window_s", "--baseline-window"},
    {"RotorEstimateOptions::identification_piece_s", "--piece"},
    {"RotorEstimateOptions::max_iterations", "--max-iterations"},
    {"RotorEstimateOptions::threads", "--threads"},
    {"RotorEstimateOptions::estimate_clock_offset", "--no-clock-offset"},
    {"RotorEstimateOptions::use_accelerometer", "--no-accelerometer"},
    {"RotorEstimateOptions::accelerometer_sigma_mps2", "--accelerometer-sigma"},
});

// evo's spellings (evo_ape / evo_rpe / evo_traj 1.36.5 argparse names), one table for the CLI's
// names, the "did you mean" of unknown flags and docs/cli.md. Aliases are second names of the same
// option; the others are flags of their own (eval_command.cc) or only named in messages.
constexpr std::array kEvo = std::to_array<EvoSpelling>({
    {"-a", "--align se3 (with -s: --align sim3)", false},
    {"--align", "--align se3 (cheval's --align takes a method; alone it means se3, as evo's)", false},
    {"-s", "--align scale (with -a: --align sim3)", false},
    {"--correct_scale", "--align scale (with -a: --align sim3)", false},
    {"--align_origin", "--align origin", false},
    {"--n_to_align", "--n-align", true},
    {"--t_max_diff", "--t-max-diff", true},
    {"--t_offset", "--t-offset", true},
    {"--pose_relation", "--relation", true},
    {"-d", "--delta", true},
    {"--delta_unit", "--delta-unit", true},
    {"--all_pairs", "--all-pairs", true},
    {"--save_results", "--save-results", true},
    {"--transform_left", "--transform-left", true},
    {"--transform_right", "--transform-right", true},
    {"-v", "accepted: cheval always prints what evo prints with -v", false},
    {"--verbose", "accepted: cheval always prints what evo prints with -v", false},
    {"--full_check", "--full-check", true},
    {"-p", "no plot window: cheval report REF EST -o FILE.html", false},
    {"--plot", "no plot window: cheval report REF EST -o FILE.html", false},
    {"--save_table", "--save-table", true},
    {"--use_filenames", "--use-filenames", true},
    {"--ignore_title", "--ignore-title", true},
});

std::string Normalized(std::string_view flag) {
  std::string out;
  for (char c : flag) {
    if (c == '-' || c == '_') continue;
    out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  return out;
}

size_t EditDistance(std::string_view a, std::string_view b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

}  // namespace

std::span<const EvoSpelling> EvoSpellings() { return kEvo; }

std::string Names(std::string_view field, std::string_view prefix, std::string_view short_name) {
  return FlagNames(Flag(field, prefix), prefix.empty(), short_name);
}

std::string FlagNames(const std::string& flag, bool with_evo, std::string_view short_name) {
  std::string names(short_name);
  if (!names.empty()) names += ',';
  names += flag;
  if (!with_evo) return names;
  for (const EvoSpelling& e : kEvo) {
    if (e.alias && e.cheval == flag && e.evo != short_name) names.append(",").append(e.evo);
  }
  return names;
}

std::string UnknownFlagsMessage(const std::vector<std::string>& flags, const std::vector<std::string>& known,
                                std::string_view command) {
  std::string message;
  for (const std::string& given : flags) {
    const std::string flag = given.substr(0, given.find('='));
    std::string hint;
    for (const EvoSpelling& e : kEvo) {
      if (e.evo == flag && !e.alias) hint = fmt::format("{} is evo's spelling; cheval: {}", flag, e.cheval);
    }
    if (hint.empty() && flag.size() > 1 && flag[0] == '-') {
      const std::string wanted = Normalized(flag);
      size_t best = std::string::npos;
      std::string best_name;
      for (const std::string& name : known) {
        const size_t d = EditDistance(wanted, Normalized(name));
        if (d < best) best = d, best_name = name;
      }
      if (!best_name.empty() && best <= std::max<size_t>(2, wanted.size() / 3)) {
        hint = fmt::format("{} is not a flag of this command; did you mean {}?", flag, best_name);
      }
    }
    if (hint.empty()) hint = fmt::format("the argument {} was not expected", given);
    message += (message.empty() ? "" : "\n") + std::string("cheval: error: ") + hint;
  }
  return message + fmt::format("\nRun 'cheval {}--help' for the flags.", command.empty() ? "" : std::string(command) + " ");
}

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
