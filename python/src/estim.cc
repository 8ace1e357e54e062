// The estimator in Python: `cheval sim quadrotor` and `cheval estimate quadrotor` as functions, with
// the same library calls, the same JSON (estim::QuadrotorEstimateJson) and the estimated states as
// numpy arrays.
#include <optional>
#include <string>

#include <fmt/format.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "cheval/common/error.h"
#include "cheval/estim/quadrotor_data.h"
#include "cheval/estim/quadrotor_estimator.h"
#include "cheval/estim/quadrotor_scoring.h"
#include "cheval/sim/quadrotor.h"

namespace cheval::python {
namespace {

sim::QuadrotorSimOptions SimOptionsOf(const std::string& scenario, uint64_t seed, double duration) {
  const auto parsed = sim::QuadrotorScenarioFromString(scenario);
  if (!parsed) {
    throw UsageError(fmt::format("scenario: unknown scenario '{}' (expected hover, line, circle, figure8, lissajous or "
                                 "aggressive)",
                                 scenario));
  }
  sim::QuadrotorSimOptions options;
  options.scenario = *parsed;
  options.seed = seed;
  options.duration_s = duration;
  return options;
}

void SimulateQuadrotor(const std::string& scenario, const std::string& output, uint64_t seed, double duration,
                       const std::string& vehicle) {
  py::gil_scoped_release release;
  const estim::QuadrotorData data = sim::SimulateQuadrotor(estim::ReadVehicle(vehicle), SimOptionsOf(scenario, seed, duration));
  estim::WriteQuadrotorData(data, output);
}

// (the JSON text of `cheval estimate quadrotor --json`, the states as arrays)
py::tuple EstimateQuadrotor(const std::optional<std::string>& scenario, const std::optional<std::string>& data_folder,
                            uint64_t seed, double duration, const std::optional<std::string>& vehicle,
                            std::optional<int> degree, std::optional<double> segment) {
  if (scenario.has_value() == data_folder.has_value()) throw UsageError("give exactly one of scenario= or data=");
  if (scenario && !vehicle) throw UsageError("a simulated scenario needs vehicle= (e.g. cheval.DEFAULT_VEHICLE)");
  estim::QuadrotorEstimateOptions options;
  if (degree) options.degree = *degree;  // else the library's defaults
  if (segment) options.segment_s = *segment;
  std::string json;
  std::vector<estim::QuadrotorTruth> states;
  {
    py::gil_scoped_release release;
    estim::QuadrotorData data;
    if (data_folder) {
      data = estim::ReadQuadrotorData(*data_folder);
      if (vehicle) data.vehicle = estim::ReadVehicle(*vehicle);  // replaces the folder's, as --vehicle does
    } else {
      data = sim::SimulateQuadrotor(estim::ReadVehicle(*vehicle), SimOptionsOf(*scenario, seed, duration));
    }
    const estim::QuadrotorEstimate e = estim::EstimateQuadrotor(data.vehicle, data.landmarks, data.pixels, data.initial,
                                                                options, estim::ReportTimes(data));
    std::optional<estim::QuadrotorErrors> errors;
    if (!data.truth.empty()) errors = estim::CompareWithTruth(e, data.truth);
    json = estim::QuadrotorEstimateJson(e, errors ? &*errors : nullptr);
    states = estim::EstimatedStates(e);
  }
  const auto n = static_cast<Eigen::Index>(states.size());
  std::vector<double> t(states.size());
  Eigen::MatrixXd p(n, 3), q(n, 4), v(n, 3), w(n, 3), rotor(n, 4);
  for (Eigen::Index i = 0; i < n; ++i) {
    const estim::QuadrotorTruth& s = states[static_cast<size_t>(i)];
    t[static_cast<size_t>(i)] = s.t;
    p.row(i) = s.p.transpose();
    q.row(i) << s.q.x(), s.q.y(), s.q.z(), s.q.w();
    v.row(i) = s.v.transpose();
    w.row(i) = s.w.transpose();
    rotor.row(i) = s.rotor.transpose();
  }
  py::dict arrays;
  arrays["times"] = AdoptVector(std::move(t));
  arrays["positions"] = AdoptMatrix(std::move(p));
  arrays["quaternions"] = AdoptMatrix(std::move(q));
  arrays["velocities"] = AdoptMatrix(std::move(v));
  arrays["angular_velocities"] = AdoptMatrix(std::move(w));
  arrays["rotor_speeds"] = AdoptMatrix(std::move(rotor));
  return py::make_tuple(json, arrays);
}

}  // namespace

void BindEstimator(py::module_& m) {
  m.def("simulate_quadrotor", &SimulateQuadrotor, py::arg("scenario"), py::arg("output"), py::arg("seed"),
        py::arg("duration"), py::arg("vehicle"));
  m.def("estimate_quadrotor", &EstimateQuadrotor, py::arg("scenario"), py::arg("data"), py::arg("seed"),
        py::arg("duration"), py::arg("vehicle"), py::arg("degree"), py::arg("segment"));
}

}  // namespace cheval::python
