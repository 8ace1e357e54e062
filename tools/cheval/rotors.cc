// `cheval estimate rotors` and `cheval identify rotors`: all four rotor speeds of a real quadrotor
// from motion capture, attitude, body rates and the rigid-body dynamics, and the identification of the
// vehicle's parameters from flights with measured rotor speeds (docs/estimator_real_data.md).
#include <fmt/format.h>

#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include "cheval/common/error.h"
#include "cheval/estim/rotor_estimator.h"
#include "cheval/report/rotor_page.h"
#include "common.h"

namespace cheval::cli {
namespace {

struct RotorFlags {
  std::vector<std::string> data;
  std::string vehicle, json, output;
  std::string report;  // estimate rotors --report
  estim::RotorEstimateOptions options;
};

void AddModelOptions(CLI::App* command, estim::RotorEstimateOptions& o) {
  command->add_option("--degree", o.degree, "Polynomial degree per segment")->capture_default_str();
  command->add_option("--segment", o.segment_s, "Segment length (s)")->capture_default_str();
  command->add_option("--position-sigma", o.position_sigma_m, "Sigma of a motion-capture position (m)")
      ->capture_default_str();
  command->add_option("--attitude-sigma", o.attitude_sigma_rad, "Sigma of the onboard attitude (rad)")
      ->capture_default_str();
  command->add_option("--rate-sigma", o.rate_sigma_radps, "Sigma of a body-rate sample (rad/s)")->capture_default_str();
  command->add_option("--sigma-acceleration", o.sigma_acceleration, "Collocation sigma of v' (m/s^2)")
      ->capture_default_str();
  command->add_option("--sigma-angular-acceleration", o.sigma_angular_acceleration,
                      "Collocation sigma of the body rate's derivative (rad/s^2)")
      ->capture_default_str();
  command->add_option("--threads", o.threads, "Solver threads (default: the machine's cores)")->capture_default_str();
  command->add_flag("!--no-clock-offset", o.estimate_clock_offset,
                    "Take the onboard samples and the motion capture as stamped by one clock (default: estimate "
                    "their offset)");
  command->add_option("--max-iterations", o.max_iterations, "Levenberg-Marquardt iterations at most")
      ->capture_default_str();
  command->add_option("--baseline-window", o.baseline_window_s, "Window of the flatness baseline's fits (s)")
      ->capture_default_str();
}

std::string Row(const Eigen::Vector4d& v, const char* format) {
  return fmt::format(fmt::runtime(format), v[0], v[1], v[2], v[3]);
}

}  // namespace

void RegisterEstimateRotors(CLI::App& app, Action* action) {
  CLI::App* estimate = app.get_subcommand("estimate");
  auto flags = std::make_shared<RotorFlags>();
  CLI::App* rotors = estimate->add_subcommand(
      "rotors", "All four rotor speeds of a real quadrotor (Crazyflie CSV layout) from motion capture, attitude, "
                "body rates and the rigid-body dynamics");
  rotors->add_option("--data", flags->data, "Flight CSV (../shared/data/crazyflie_brushless_idsia/NAME.csv)")
      ->required()
      ->expected(1);
  rotors->add_option("--vehicle", flags->vehicle, "Rotor vehicle file (data/vehicles/crazyflie21_brushless.json or "
                                                  "one written by `identify rotors`)")
      ->required();
  AddModelOptions(rotors, flags->options);
  rotors->add_option("--sigma-rotor-rate", flags->options.sigma_rotor_rate,
                     "Smoothness prior of the rotor speeds (rad/s^2 per s^0.5)")
      ->capture_default_str();
  rotors->add_flag("!--no-accelerometer", flags->options.use_accelerometer,
                   "Do not use the accelerometer (ax,ay,az: world-frame specific force) as a measurement");
  rotors->add_option("--accelerometer-sigma", flags->options.accelerometer_sigma_mps2,
                     "Sigma of an accelerometer sample per axis (m/s^2)")
      ->capture_default_str();
  rotors->add_option("--json", flags->json, "Write the result as JSON");
  rotors->add_option("-o,--output", flags->output, "Write states and rotor speeds (estimated, measured, baseline) as CSV");
  rotors->add_option("--report", flags->report,
                     "Write an HTML page: estimated, measured and baseline speed per motor over time, error table");
  rotors->callback([flags, action] {
    *action = [flags] {
      flags->options.Validate();
      if (!flags->report.empty()) report::RequireReportPage();
      RefuseSharedPaths({flags->data[0], flags->vehicle},
                        {{"--json", flags->json}, {"-o", flags->output}, {"--report", flags->report}});
      const estim::RotorVehicle vehicle = estim::ReadRotorVehicle(flags->vehicle);
      const estim::RotorFlight flight = estim::ReadRotorFlight(flags->data[0]);
      if (!flight.dropped_lines.empty()) {
        fmt::print(stderr, "cheval: {}: dropped {} row(s) with missing values (first at line {})\n", flight.path,
                   flight.dropped_lines.size(), flight.dropped_lines.front());
      }
      const estim::RotorEstimate e = estim::EstimateRotors(flight, vehicle, flags->options);
      fmt::print("duration            {:.2f} s ({} scored samples)\n", e.duration_s, e.scored_samples);
      fmt::print("states              {}\nsegments            {}\nsolver iterations   {}{}\nseconds             {:.3f}\n",
                 e.states, e.segments, e.iterations, e.converged ? "" : "  (did not converge)", e.seconds);
      if (flags->options.estimate_clock_offset) {
        std::string offsets;
        for (double d : e.clock_offsets_s) offsets += fmt::format("{}{:.1f}", offsets.empty() ? "" : " ", 1e3 * d);
        fmt::print("clock offset ms     {}  (onboard minus motion capture, per span)\n", offsets);
      }
      fmt::print("rotor error rpm     {}\n", Row(e.error.rpm, "{:.1f} {:.1f} {:.1f} {:.1f}"));
      fmt::print("rotor error %       {}\n", Row(e.error.percent, "{:.3f} {:.3f} {:.3f} {:.3f}"));
      fmt::print("flatness rpm        {}\n", Row(e.baseline.rpm, "{:.1f} {:.1f} {:.1f} {:.1f}"));
      fmt::print("flatness %          {}\n", Row(e.baseline.percent, "{:.3f} {:.3f} {:.3f} {:.3f}"));
      // OutputFile holds a view: the texts live here until written.
      const std::string json = flags->json.empty() ? "" : estim::RotorEstimateJson(e, flight);
      const std::string csv = flags->output.empty() ? "" : estim::RotorStatesCsv(e);
      std::vector<OutputFile> files;
      if (!flags->json.empty()) files.push_back({flags->json, json});
      if (!flags->output.empty()) files.push_back({flags->output, csv});
      const std::string page =
          flags->report.empty() ? "" : report::RotorPageHtml(e, {.flight_path = flags->data[0],
                                                                 .vehicle_path = flags->vehicle,
                                                                 .generator = fmt::format("cheval {}", CHEVAL_VERSION)});
      if (!flags->report.empty()) files.push_back({flags->report, page});
      if (!files.empty()) WriteOutputs(files);
    };
  });
}

void RegisterIdentifyRotors(CLI::App& app, Action* action) {
  CLI::App* identify = app.add_subcommand("identify", "Identify a vehicle's parameters from data");
  identify->require_subcommand(1);
  auto flags = std::make_shared<RotorFlags>();
  CLI::App* rotors = identify->add_subcommand(
      "rotors", "Thrust and moment coefficients, inertia, torque offset and rotor drag of a quadrotor, jointly with "
                "the trajectories of flights with measured rotor speeds");
  rotors->add_option("--data", flags->data, "Flight CSV with measured rotor speeds (repeat for several)")->required();
  rotors->add_option("--vehicle", flags->vehicle, "Base vehicle file (the published parameters)")->required();
  rotors->add_option("-o,--output", flags->output, "The identified vehicle file (JSON)")->required();
  AddModelOptions(rotors, flags->options);
  rotors->add_option("--rotor-sigma", flags->options.rotor_sigma_radps, "Sigma of a measured rotor speed (rad/s)")
      ->capture_default_str();
  rotors->add_option("--piece", flags->options.identification_piece_s,
                     "Length of the pieces identified one by one (s, >= 1); their spread widens sigma")
      ->capture_default_str();
  rotors->callback([flags, action] {
    *action = [flags] {
      std::vector<std::string> inputs = flags->data;
      inputs.push_back(flags->vehicle);
      flags->options.Validate();
      RefuseSharedPaths(inputs, {{"-o", flags->output}});
      const estim::RotorVehicle base = estim::ReadRotorVehicle(flags->vehicle);
      std::vector<estim::RotorFlight> flights;
      for (const std::string& path : flags->data) flights.push_back(estim::ReadRotorFlight(path));
      std::vector<estim::RotorIdentification> per_flight;
      const estim::RotorVehicle out = estim::IdentifyRotors(flights, base, flags->options, &per_flight);
      for (size_t f = 0; f < flights.size(); ++f) {
        fmt::print("{}: {} piece(s), {:.2f} s, reduced chi2 <= {:.3g}, clock offset {:.1f} ms{}\n", flights[f].path,
                   per_flight[f].pieces, per_flight[f].seconds, per_flight[f].reduced_chi2,
                   1e3 * per_flight[f].clock_offset_s, per_flight[f].converged ? "" : "  (a piece did not converge)");
      }
      const char* names[] = {"k_m1/k_F", "k_m2/k_F", "k_m3/k_F", "k_m4/k_F", "Jx/Jx_pub", "Jy/Jy_pub",
                             "Jz/Jz_pub", "k_M/Kc", "tau0_x [1e-5 N m]", "tau0_y [1e-5 N m]",
                             "tau0_z [1e-5 N m]", "drag_xy [1e-5]", "drag_z [1e-5]", "moment_x [1e-8]",
                             "moment_y [1e-8]", "rotor_inertia [1e-9 kg m^2]"};
      static_assert(std::size(names) == estim::kRotorThetaSize);
      for (int i = 0; i < estim::kRotorThetaSize; ++i) {
        if (out.theta_sigma[i] == 0) {
          fmt::print("{:<20}{:>10.4f}   (held at the base vehicle's value)\n", names[i], out.theta[i]);
          continue;
        }
        fmt::print("{:<20}{:>10.4f} +- {:.4f}   (published {})\n", names[i], out.theta[i], out.theta_sigma[i],
                   estim::RotorNominal::PublishedTheta()[i]);
      }
      WriteOutput(flags->output, estim::RotorVehicleToJson(out));
    };
  });
}

}  // namespace cheval::cli
