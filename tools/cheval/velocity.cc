// `cheval velocity IN [-o OUT]`: world-frame linear velocity from positions (C-ASE ground truth).
#include <algorithm>
#include <charconv>
#include <chrono>
#include <cstdio>

#include <fmt/format.h>

#include <vector>
#include <nlohmann/json.hpp>

#include "cheval/common/error.h"
#include "cheval/eval/velocity.h"
#include "cheval/traj/stamp.h"
#include "common.h"
#include "progress.h"

namespace cheval::cli {
namespace {

struct VelocityFlags {
  std::string input;
  std::string output;
  std::string method = "chebyshev";
  std::string degree = "auto";
  double window_s = 0.0;
  std::string at_path;
  std::string json_path;
  bool angular = false;
  InputFlags format;
};

eval::VelocityOptions ToOptions(const VelocityFlags& flags, const traj::TrajectoryView& trajectory) {
  eval::VelocityOptions options;
  options.method = *eval::VelocityMethodFromString(flags.method);
  options.angular = flags.angular;
  if (flags.degree == "auto" || flags.degree == "cv") {
    options.curve.degree_method = cheb::DegreeMethod::kCrossValidation;
  } else if (flags.degree == "chop") {
    options.curve.degree_method = cheb::DegreeMethod::kChop;
  } else {
    int degree = -1;
    const auto [end, ec] = std::from_chars(flags.degree.data(), flags.degree.data() + flags.degree.size(), degree);
    if (ec != std::errc() || end != flags.degree.data() + flags.degree.size() || degree < 0) {
      throw UsageError(
          fmt::format("--degree: expected auto, cv, chop or a non-negative integer, got '{}'", flags.degree));
    }
    options.curve.degree_method = cheb::DegreeMethod::kFixed;
    options.curve.fixed_degree = degree;
    if (flags.window_s == 0.0) options.curve.single_window = true;  // a fixed degree alone: one global fit
  }
  if (flags.window_s < 0.0) throw UsageError(fmt::format("--window must be positive, got {}", flags.window_s));
  if (flags.window_s > 0.0) {
    if (options.method == eval::VelocityMethod::kSavitzkyGolay) {
      // Seconds -> an odd number of samples at the median rate.
      const auto s = trajectory.stamps_ns();
      const double duration = static_cast<double>(s.back() - s.front()) * 1e-9;
      const double rate = duration > 0 ? static_cast<double>(s.size() - 1) / duration : 0.0;
      int samples = static_cast<int>(std::lround(flags.window_s * rate));
      if (samples % 2 == 0) ++samples;
      options.savgol_window = std::max(samples, 5);
    } else {
      options.curve.window_s = flags.window_s;
    }
  }
  options.curve.progress = Progress().Fn();  // on a terminal only (progress.h)
  return options;
}

// The output trajectory: positions and orientation as read at the input's own stamps, or the
// fitted ones at --at stamps; the velocities; the angular velocities with --angular.
traj::Trajectory MakeOutput(const traj::TrajectoryView& input, std::span<const int64_t> stamps, bool own_stamps,
                            const eval::VelocityEstimate& estimate) {
  traj::Trajectory out(traj::Channels{traj::OrientationKind::kQuaternion, true, estimate.angular_velocities.cols() > 0,
                                      true});
  out.Reserve(static_cast<Eigen::Index>(stamps.size()));
  for (size_t i = 0; i < stamps.size(); ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    Eigen::Vector3d position;
    Eigen::Vector4d q(0, 0, 0, 1);
    if (own_stamps) {
      position = input.positions().col(k);
      if (input.channels().orientation == traj::OrientationKind::kQuaternion) {
        q = input.quaternions().col(k);
      } else if (input.has_orientation()) {
        q = input.UnitQuaternion(k).coeffs();
      }
    } else {
      position = estimate.positions.col(k);
      if (!estimate.orientations.empty()) {
        q = estimate.orientations[i].coeffs();  // the fitted orientation curve
      } else if (input.has_orientation()) {
        // Slerp between the input's neighbouring orientations (stamps sorted by the caller's file).
        const auto s = input.stamps_ns();
        const auto upper = std::upper_bound(s.begin(), s.end(), stamps[i]) - s.begin();
        const Eigen::Index j1 = std::clamp<Eigen::Index>(upper, 1, input.size() - 1), j0 = j1 - 1;
        const double span = static_cast<double>(s[j1] - s[j0]);
        const double f = span > 0 ? std::clamp(static_cast<double>(stamps[i] - s[j0]) / span, 0.0, 1.0) : 0.0;
        q = input.UnitQuaternion(j0).slerp(f, input.UnitQuaternion(j1)).coeffs();
      }
    }
    const Eigen::Vector3d v = estimate.velocities.col(k);
    Eigen::Vector3d w = Eigen::Vector3d::Zero();
    if (estimate.angular_velocities.cols() > 0) w = estimate.angular_velocities.col(k);
    out.Append(stamps[i], position.data(), q.data(), v.data(), w.data());
  }
  return out;
}

}  // namespace

void RegisterVelocity(CLI::App& app, Action* action) {
  auto flags = std::make_shared<VelocityFlags>();
  CLI::App* command = app.add_subcommand(
      "velocity", "World-frame linear velocity from positions by Chebyshev fitting (or central differences, "
                  "Savitzky-Golay)");
  command->add_option("input", flags->input, "Trajectory file (positions are used)")->required();
  command->add_option("-o,--output", flags->output,
                      "Write TUM + velocity (t x y z qx qy qz qw vx vy vz [wx wy wz]), orientation as read");
  command->add_option("--method", flags->method, "Velocity method")
      ->check(CLI::IsMember({"chebyshev", "central", "savgol"}))
      ->capture_default_str();
  command->add_option("--degree", flags->degree,
                      "chebyshev: auto = cv (5-fold cross-validation per window), chop (standardChop at the "
                      "estimated noise level) or a fixed degree")
      ->capture_default_str();
  command->add_option("--window", flags->window_s,
                      "chebyshev: fixed window length in seconds (default: adaptive); savgol: window in seconds "
                      "(default 21 samples)");
  command->add_option("--at", flags->at_path,
                      "Evaluate at these stamps: a file of one stamp (s) per line, or a trajectory file");
  command->add_flag("--angular", flags->angular,
                    "Also body angular velocity from the orientations, appended as wx wy wz (rad/s)");
  command->add_option("--json", flags->json_path, "Write what was done as JSON");
  AddInputFlags(command, &flags->format);
  command->callback([flags, action] {
    *action = [flags] {
      const auto start = std::chrono::steady_clock::now();
      const traj::Trajectory trajectory = traj::ReadTrajectory(flags->input, flags->format.ToReadOptions());
      const traj::TrajectoryView view = trajectory.View();
      if (!view.has_stamps()) throw ComputeError("velocity needs stamps; give the KITTI times with --kitti-times");
      const eval::VelocityOptions options = ToOptions(*flags, view);
      std::vector<int64_t> at;
      if (!flags->at_path.empty()) at = ReadQueryStamps(flags->at_path);
      const bool own = flags->at_path.empty();
      const eval::VelocityEstimate estimate =
          eval::EstimateVelocity(view, options, own ? std::nullopt : std::optional<std::span<const int64_t>>(at));
      const std::span<const int64_t> stamps = own ? view.stamps_ns() : std::span<const int64_t>(at);
      const std::string text =
          flags->output.empty()
              ? ""
              : traj::FormatTrajectory(MakeOutput(view, stamps, own, estimate).View(), traj::Format::kTumV);
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

      nlohmann::json j;
      std::vector<int> all_degrees;
      j["command"] = "velocity";
      j["input"] = {{"path", flags->input}, {"poses", view.size()}};
      j["method"] = flags->method;
      j["evaluated_at"] = stamps.size();
      if (estimate.curve) {
        const cheb::Curve& curve = *estimate.curve;
        nlohmann::json windows = nlohmann::json::array();
        for (const cheb::CurveSegment& segment : curve.segments()) {
          for (const cheb::CurveWindow& w : segment.windows) {
            windows.push_back({{"begin_s", w.fit_begin}, {"end_s", w.fit_end}, {"samples", w.samples},
                               {"degrees", w.degrees}});
            all_degrees.insert(all_degrees.end(), w.degrees.begin(), w.degrees.end());
          }
        }
        j["degree_method"] = flags->degree;
        j["segments"] = curve.segments().size();
        j["windows"] = windows.size();
        j["degrees"] = all_degrees;
        j["window_list"] = windows;
        j["noise_sigma_m"] = std::vector<double>(curve.noise_sigma().data(), curve.noise_sigma().data() + 3);
        j["residual_rmse_m"] = std::vector<double>(curve.residual_rms().data(), curve.residual_rms().data() + 3);
        j["compression_ratio"] = static_cast<double>(3 * view.size()) / static_cast<double>(curve.stored_values());
      }
      if (estimate.rotation_curve) {
        j["angular"] = {{"charts", estimate.rotation_curve->charts().size()},
                        {"residual_rms_rad", estimate.rotation_curve->residual_rms_rad()}};
      }
      j["seconds"] = seconds;
      if (!view.has_orientation() && !flags->output.empty()) {
        fmt::print(stderr, "cheval: warning: {} has no orientation; {} gets identity quaternions\n", flags->input,
                   flags->output);
      }
      const std::string json_text = j.dump(2) + "\n";
      std::vector<traj::FileToWrite> files;
      if (!flags->output.empty()) files.push_back({flags->output, text});
      if (!flags->json_path.empty()) files.push_back({flags->json_path, json_text});
      traj::WriteFilesAtomically(files);
      if (estimate.curve) {
        fmt::print("{}: {} poses, {} windows in {} segments, degrees {}..{}, noise sigma {:.3g} m, residual RMSE "
                   "{:.3g} m, compression {:.1f}x, {:.3f} s\n",
                   flags->input, view.size(), j["windows"].get<size_t>(), j["segments"].get<size_t>(),
                   *std::min_element(all_degrees.begin(), all_degrees.end()),
                   *std::max_element(all_degrees.begin(), all_degrees.end()), estimate.curve->noise_sigma().mean(),
                   estimate.curve->residual_rms().mean(), j["compression_ratio"].get<double>(), seconds);
      } else {
        fmt::print("{}: {} poses, method {}, {:.3f} s\n", flags->input, view.size(), flags->method, seconds);
      }
    };
  });
}

}  // namespace cheval::cli
