// Chebyshev curves in Python: cheval.fit (a Curve evaluable at any stamps), cheval.compress (a
// pseudo-spectral Model), cheval.sample, and model files.
#include <optional>

#include <fmt/format.h>
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "cheval/eval/velocity.h"
#include "cheval/cheb/compress.h"
#include "cheval/cheb/model.h"
#include "cheval/common/error.h"
#include "cheval/common/output.h"

namespace cheval::python {
namespace {

// The samples of a trajectory as FitCurve takes them: its stamps and its positions (n x 3,
// column-major: a transposed copy of the stored 3 x n).
struct Samples {
  std::span<const int64_t> stamps;  // the trajectory's own (it outlives the call)
  Eigen::MatrixXd values;
};

Samples SamplesOf(const PyTrajectory& t) {
  const traj::TrajectoryView view = t.trajectory.View();
  if (!view.has_stamps()) throw ComputeError("fitting needs stamps; give the KITTI times with kitti_times=");
  return {view.stamps_ns(), view.positions().transpose()};
}

py::list WindowsOf(const cheb::Curve& curve) {
  py::list windows;
  for (const cheb::CurveSegment& segment : curve.segments()) {
    for (const cheb::CurveWindow& w : segment.windows) {
      py::dict d;
      d["core"] = py::make_tuple(w.core_begin, w.core_end);
      d["fit"] = py::make_tuple(w.fit_begin, w.fit_end);
      d["samples"] = w.samples;
      d["degrees"] = w.degrees;
      d["coefficient_magnitudes"] = w.coefficient_magnitudes;  // (K x d), copied
      windows.append(d);
    }
  }
  return windows;
}

// Curve.evaluate: values, and the derivatives up to `order`, each (n, d) without a copy.
py::object EvaluateCurve(const cheb::Curve& curve, const py::handle& stamps_in, int order, double tolerance_s) {
  if (order < 0 || order > 2) throw UsageError(fmt::format("order must be 0, 1 or 2, got {}", order));
  const py::array_t<int64_t> stamps = StampsArray(stamps_in);
  Eigen::MatrixXd values, first, second;
  {
    py::gil_scoped_release release;
    curve.EvaluateMany(SpanOf(stamps), order, &values, order >= 1 ? &first : nullptr, order >= 2 ? &second : nullptr,
                       tolerance_s);
  }
  if (order == 0) return AdoptMatrix(std::move(values));
  if (order == 1) return py::make_tuple(AdoptMatrix(std::move(values)), AdoptMatrix(std::move(first)));
  return py::make_tuple(AdoptMatrix(std::move(values)), AdoptMatrix(std::move(first)), AdoptMatrix(std::move(second)));
}

cheb::Compression CompressSamples(std::span<const int64_t> stamps, const Eigen::Ref<const Eigen::MatrixXd>& values,
                                  std::optional<double> tolerance) {
  cheb::CompressOptions options;
  options.tolerance = tolerance;
  options.Validate();
  py::gil_scoped_release release;
  return cheb::Compress(stamps, values, options);
}

}  // namespace

cheb::CurveOptions CurveOptionsOf(const py::object& degree, std::optional<double> window, std::optional<double> noise,
                                  int threads) {
  std::string name;
  if (py::isinstance<py::str>(degree)) {
    name = degree.cast<std::string>();
  } else if (py::isinstance<py::int_>(degree) && !py::isinstance<py::bool_>(degree)) {
    name = std::to_string(degree.cast<long long>());
  } else {
    throw UsageError("degree: expected 'auto', 'cv', 'chop' or an int");
  }
  cheb::CurveOptions options = eval::CurveOptionsFromNames(name, window);
  options.noise_sigma = noise;
  options.threads = threads;
  return options;
}

void BindChebyshev(py::module_& m) {
  py::class_<cheb::Curve>(m, "Curve", R"(A continuous-time curve fitted to stamped samples (cheval.fit): overlapping
windowed Chebyshev least-squares fits with automatically chosen degrees, blended smoothly and
split at gaps. Evaluate it at any stamps inside the data.)")
      .def("evaluate", &EvaluateCurve, py::arg("stamps"), py::arg("order") = 0, py::arg("tolerance") = 0.0,
           R"(Values at int64 stamps (ns), shape (n, d); with order=1 (values, first derivative per
second), order=2 also the second derivative. Arrays are returned without a copy (Fortran order).
Raises ComputeError for a stamp outside the data by more than `tolerance` seconds or in a gap.)")
      .def_property_readonly("origin", &cheb::Curve::origin_ns, "Stamp (ns) of t = 0 of the windows' times.")
      .def_property_readonly("dimension", &cheb::Curve::dimension, "Coordinates per sample.")
      .def_property_readonly("noise_sigma", &cheb::Curve::noise_sigma,
                             "Noise sigma per coordinate the degrees were chosen for (estimated or given): the "
                             "recording's level.")
      .def_property_readonly("noise_sigma_max", &cheb::Curve::noise_sigma_max,
                             "The largest noise sigma per coordinate of the noise profile (noise_sigma where no "
                             "stretch is clearly noisier; docs/velocity.md, \"Noise profile\").")
      .def_property_readonly("noisier_samples", &cheb::Curve::noisier_samples,
                             "Samples tested against a noise sigma above the recording's (the noise profile).")
      .def_property_readonly("stamp_noise_s", &cheb::Curve::stamp_noise_s,
                             "RMS error (s) of the stamps where the samples scatter in proportion to their rate, "
                             "as stamps off by white errors make them; 0 where they do not (docs/velocity.md, "
                             "\"Stamp noise\").")
      .def_property_readonly("resolution", &cheb::Curve::resolution,
                             "Per coordinate, the step the values were rounded to (0 where they were not); an "
                             "estimated noise sigma is at least step/sqrt(12), more with noise before the rounding, "
                             "except on a staircase (docs/velocity.md, "
                             "\"Rounded positions\").")
      .def_property_readonly("staircase", &cheb::Curve::staircase,
                             "Per coordinate, whether the values were rounded to a step they moved less than a "
                             "sample at a time, and were fitted placed between their steps (docs/velocity.md, "
                             "\"Rounded positions\").")
      .def_property_readonly("residual_rms", &cheb::Curve::residual_rms, "RMS of the fit residuals per coordinate.")
      .def_property_readonly("stored_values", &cheb::Curve::stored_values,
                             "Sum over windows of (degree + 1) per coordinate.")
      .def_property_readonly(
          "segments",
          [](const cheb::Curve& c) {
            std::vector<std::pair<double, double>> spans;
            for (const cheb::CurveSegment& s : c.segments()) spans.emplace_back(s.begin, s.end);
            return spans;
          },
          "Gap-free stretches as (first, last) sample times in seconds from origin.")
      .def_property_readonly("windows", &WindowsOf,
                             "One dict per window: core and fit intervals (s from origin), samples, degrees (per "
                             "coordinate) and coefficient_magnitudes (|c_k| of the high-degree fit, K x d).");

  m.def(
      "fit",
      [](const py::handle& stamps_in, const Eigen::Ref<const Eigen::MatrixXd>& values, const py::object& degree,
         std::optional<double> window, std::optional<double> noise, int threads) {
        const cheb::CurveOptions options = CurveOptionsOf(degree, window, noise, threads);
        const py::array_t<int64_t> stamps = StampsArray(stamps_in);
        py::gil_scoped_release release;
        return cheb::FitCurve(SpanOf(stamps), values, options);
      },
      py::arg("stamps"), py::arg("values"), py::kw_only(), py::arg("degree") = "auto", py::arg("window") = py::none(),
      py::arg("noise") = py::none(), py::arg("threads") = 0,
      R"(Fits samples `values` (n x d, d <= 4) taken at int64 `stamps` (ns, any order) with a Curve.
degree: 'auto' (= 'cv', cross-validation per window), 'chop' or an int (a fixed
degree: one global fit unless `window` is given); window: fixed window length in seconds
(default adaptive); noise: the samples' noise sigma (default estimated); threads: for the fit (0:
every core; the curve is the same for any number). values is used without a copy when it is a
Fortran-ordered float64 array, copied otherwise.)");
  m.def(
      "fit",
      [](const PyTrajectory& t, const py::object& degree, std::optional<double> window, std::optional<double> noise,
         int threads) {
        const cheb::CurveOptions options = CurveOptionsOf(degree, window, noise, threads);
        const Samples samples = SamplesOf(t);
        py::gil_scoped_release release;
        return cheb::FitCurve(samples.stamps, samples.values, options);
      },
      py::arg("trajectory"), py::kw_only(), py::arg("degree") = "auto", py::arg("window") = py::none(),
      py::arg("noise") = py::none(), py::arg("threads") = 0, "The Curve of a Trajectory's positions (same options).");

  py::class_<cheb::TrajectoryModel>(m, "Model", R"(A trajectory's pseudo-spectral model (docs/compress.md): windowed
Chebyshev polynomials held by their values at Chebyshev points. From cheval.compress or
cheval.read_model; evaluate it with cheval.sample or model.curve().)")
      .def_readonly("origin", &cheb::TrajectoryModel::origin_ns, "Stamp (ns) of t = 0.")
      .def_readonly("dimension", &cheb::TrajectoryModel::dimension, "Coordinates per sample (3 for positions).")
      .def_property_readonly("segments",
                             [](const cheb::TrajectoryModel& model) {
                               std::vector<std::pair<int64_t, int64_t>> spans;
                               for (const cheb::ModelSegment& s : model.segments) spans.emplace_back(s.first_ns, s.last_ns);
                               return spans;
                             },
                             "Gap-free stretches as (first, last) stamps in ns.")
      .def_property_readonly("value_count", &cheb::ModelValueCount, "Numbers in the model's value arrays.")
      .def_property_readonly("number_count", &cheb::ModelNumberCount,
                             "Every number the model needs (values, window intervals, segment stamps, origin).")
      .def("to_json", &cheb::WriteModelJson, "The model file's JSON text (doubles round-trip exactly).")
      .def("curve", &cheb::CurveFromModel, "The model as a Curve (bit-identical evaluations).")
      .def_static(
          "from_json",
          [](const std::string& text, const std::string& path) { return cheb::ParseModelJson(text, path); },
          py::arg("text"), py::arg("path") = "<string>",
          "Parses and validates a model; InputError naming the element on anything invalid.");

  m.def("read_model", &cheb::ReadModel, py::arg("path"), "Reads a model file written by cheval.write_model or `cheval compress`.");
  m.def(
      "write_model",
      [](const cheb::TrajectoryModel& model, const std::string& path) {
        WriteOutput(path, cheb::WriteModelJson(model));
      },
      py::arg("model"), py::arg("path"), "Writes a model file atomically (OutputError when it cannot).");

  py::class_<cheb::Compression>(m, "Compression", "The result of cheval.compress: the model and what it costs and achieves.")
      .def_readonly("model", &cheb::Compression::model)
      .def_readonly("input_numbers", &cheb::Compression::input_numbers, "dimension x samples of the input.")
      .def_readonly("model_numbers", &cheb::Compression::model_numbers, "Model.number_count.")
      .def_readonly("ratio", &cheb::Compression::ratio, "input_numbers / model_numbers.")
      .def_readonly("automatic", &cheb::Compression::automatic, "Whether the model is the automatic fit.")
      .def_property_readonly("max_error", [](const cheb::Compression& c) { return c.error.max; },
                             "Largest Euclidean error of the stored model at the input samples.")
      .def_property_readonly("rms_error", [](const cheb::Compression& c) { return c.error.rms; },
                             "RMS of that error.")
      .def_property_readonly("worst_stamp", [](const cheb::Compression& c) { return c.error.worst_stamp_ns; },
                             "Stamp (ns) of the sample with the largest error.");

  m.def(
      "compress",
      [](const py::handle& stamps_in, const Eigen::Ref<const Eigen::MatrixXd>& values, std::optional<double> tolerance) {
        const py::array_t<int64_t> stamps = StampsArray(stamps_in);
        return CompressSamples(SpanOf(stamps), values, tolerance);
      },
      py::arg("stamps"), py::arg("values"), py::kw_only(), py::arg("tolerance") = py::none(),
      R"(Compresses samples (n x d at int64 stamps) into a Model, as `cheval compress`. tolerance (units
of the samples): the smallest model found whose error at every sample is at most it, or
ComputeError saying what can be reached; None: the automatic fit.)");
  m.def(
      "compress",
      [](const PyTrajectory& t, std::optional<double> tolerance) {
        const Samples samples = SamplesOf(t);
        return CompressSamples(samples.stamps, samples.values, tolerance);
      },
      py::arg("trajectory"), py::kw_only(), py::arg("tolerance") = py::none(),
      "Compresses a Trajectory's positions (orientation is not stored).");

  m.def(
      "sample",
      [](const cheb::TrajectoryModel& model, std::optional<double> rate, const py::object& at) {
        if (!rate && at.is_none()) throw UsageError("sample needs rate= or at=");
        if (rate && !at.is_none()) throw UsageError("sample takes rate= or at=, not both");
        py::array_t<int64_t> stamps;
        if (rate) {
          stamps = py::array_t<int64_t>::ensure(AdoptVector(cheb::ModelGridStamps(model, *rate)));
        } else {
          stamps = StampsArray(at);
          cheb::CheckModelCovers(model, SpanOf(stamps));
        }
        Eigen::MatrixXd values;
        {
          py::gil_scoped_release release;
          cheb::CurveFromModel(model).EvaluateMany(SpanOf(stamps), 0, &values);
        }
        py::dict out;
        out["stamps"] = stamps;
        out["values"] = AdoptMatrix(std::move(values));
        return out;
      },
      py::arg("model"), py::kw_only(), py::arg("rate") = py::none(), py::arg("at") = py::none(),
      R"(Values of a model, as `cheval sample`: every 1/rate s from its first stamp to its last (gaps
skipped), or at the int64 stamps `at` (ComputeError naming the first one outside the model).
Returns {'stamps': (n,) int64, 'values': (n, d)} (no copies).)");
}

}  // namespace cheval::python
