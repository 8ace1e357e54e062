// Trajectories in Python: cheval.Trajectory (numpy views of the library's storage), read, write,
// and the motion simulator.
#include <optional>

#include <fmt/format.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "cheval/common/error.h"
#include "cheval/sim/motion.h"
#include "cheval/traj/validate.h"

namespace cheval::python {
namespace {

constexpr auto kDouble = static_cast<py::ssize_t>(sizeof(double));

// Checks that `array` is (n, columns); UsageError naming the argument otherwise.
void CheckShape(const DoubleArray& array, py::ssize_t n, py::ssize_t columns, const char* name) {
  if (array.ndim() != 2 || array.shape(0) != n || array.shape(1) != columns) {
    std::string shape;
    for (py::ssize_t d = 0; d < array.ndim(); ++d) shape += (d ? ", " : "") + std::to_string(array.shape(d));
    throw UsageError(fmt::format("{}: expected shape ({}, {}) (one row per stamp), got ({})", name, n, columns, shape));
  }
}

// An optional array argument as doubles (RealArray), or nullopt for None.
std::optional<DoubleArray> OptionalRealArray(const py::handle& values, const char* name) {
  if (values.is_none()) return std::nullopt;
  return RealArray(values, name);
}

// Builds a trajectory from arrays and checks its values as the readers check a file's
// (traj::ValidatePoses: finite values, rotations, stamp span; InputError, a ValueError, naming the row).
PyTrajectory FromArrays(const py::handle& stamps_in, const py::handle& positions_in, const py::handle& quaternions_in,
                        const py::handle& velocities_in, const py::handle& angular_velocities_in,
                        const std::string& quat_order) {
  const bool wxyz = QuatOrderIsWxyz(quat_order);
  const py::array_t<int64_t> stamps = StampsArray(stamps_in);
  const DoubleArray positions = RealArray(positions_in, "positions");
  const std::optional<DoubleArray> quaternions = OptionalRealArray(quaternions_in, "quaternions");
  const std::optional<DoubleArray> velocities = OptionalRealArray(velocities_in, "velocities");
  const std::optional<DoubleArray> angular_velocities = OptionalRealArray(angular_velocities_in, "angular_velocities");
  const py::ssize_t n = stamps.size();
  CheckShape(positions, n, 3, "positions");
  if (quaternions) CheckShape(*quaternions, n, 4, "quaternions");
  if (velocities) CheckShape(*velocities, n, 3, "velocities");
  if (angular_velocities) CheckShape(*angular_velocities, n, 3, "angular_velocities");
  traj::Channels channels;
  channels.orientation = quaternions ? traj::OrientationKind::kQuaternion : traj::OrientationKind::kNone;
  channels.velocity = velocities.has_value();
  channels.angular_velocity = angular_velocities.has_value();
  PyTrajectory out{traj::Trajectory(channels)};
  out.quat_wxyz = wxyz;
  out.trajectory.Reserve(n);
  auto row = [](const std::optional<DoubleArray>& a, py::ssize_t i) { return a ? a->data(i, 0) : nullptr; };
  for (py::ssize_t i = 0; i < n; ++i) {
    const double* q = row(quaternions, i);
    const double xyzw[4] = {q && wxyz ? q[1] : 0, q && wxyz ? q[2] : 0, q && wxyz ? q[3] : 0, q && wxyz ? q[0] : 0};
    out.trajectory.Append(stamps.at(i), positions.data(i, 0), wxyz && q ? xyzw : q, row(velocities, i),
                          row(angular_velocities, i));
  }
  traj::ValidatePoses(out.trajectory.View(), out.path);
  return out;
}

// Orientations in the layout that is not stored, computed pose by pose (a copy).
py::array QuaternionsOf(const traj::TrajectoryView& view) {
  Eigen::Matrix4Xd q(4, view.size());
  for (Eigen::Index i = 0; i < view.size(); ++i) q.col(i) = view.UnitQuaternion(i).coeffs();
  const auto n = static_cast<py::ssize_t>(view.size());
  return AdoptArray<double>(std::move(q), [](const Eigen::Matrix4Xd& m) { return m.data(); }, {n, 4},
                            {4 * kDouble, kDouble});
}

py::array RotationsOf(const traj::TrajectoryView& view) {
  std::vector<double> r(static_cast<size_t>(9 * view.size()));
  for (Eigen::Index i = 0; i < view.size(); ++i) {
    Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(r.data() + 9 * i) = view.Rotation(i);
  }
  const auto n = static_cast<py::ssize_t>(view.size());
  return AdoptArray<double>(std::move(r), [](const std::vector<double>& v) { return v.data(); }, {n, 3, 3},
                            {9 * kDouble, 3 * kDouble, kDouble});
}

// The getter of a 3-vector channel: a read-only (n, 3) view of its storage (no copy), or None when
// `present` says the trajectory lacks it.
template <typename Present>
auto ChannelView(const std::vector<double>& (traj::Trajectory::*raw)() const, Present present) {
  return [raw, present](const py::object& self) -> py::object {
    const traj::Trajectory& t = self.cast<const PyTrajectory&>().trajectory;
    if (!present(t.channels())) return py::none();
    return ViewOf((t.*raw)().data(), {t.size(), 3}, {3 * kDouble, kDouble}, self);
  };
}

std::string_view OrientationName(traj::OrientationKind kind) {
  switch (kind) {
    case traj::OrientationKind::kQuaternion: return "quaternion";
    case traj::OrientationKind::kMatrix: return "matrix";
    case traj::OrientationKind::kNone: break;
  }
  return "none";
}

traj::Format FormatOf(const std::string& name) {
  const auto format = traj::FormatFromString(name);
  if (!format) throw UsageError(fmt::format("format: unknown format '{}' (auto, tum, tumv, euroc, kitti, vins, csv)", name));
  return *format;
}

}  // namespace

void BindTrajectory(py::module_& m) {
  py::class_<PyTrajectory>(m, "Trajectory", R"(A stamped trajectory: stamps (int64 ns), positions, optional orientations,
world-frame velocities and body-frame angular velocities.

Trajectory(stamps, positions, quaternions=None, velocities=None, angular_velocities=None) copies
the arrays in (n int64 stamps; (n, 3) positions in m; (n, 4) quaternions x y z w; (n, 3) m/s;
(n, 3) rad/s). Stamps must be integers (nanoseconds): floats raise TypeError. Trajectories
are immutable; the array properties are read-only views of the stored data (no copy).)")
      .def(py::init(&FromArrays), py::arg("stamps"), py::arg("positions"), py::arg("quaternions") = py::none(),
           py::arg("velocities") = py::none(), py::arg("angular_velocities") = py::none(),
           py::arg("quat_order") = "xyzw")
      .def("__len__", [](const PyTrajectory& t) { return t.trajectory.size(); })
      .def("__repr__",
           [](const PyTrajectory& t) {
             const traj::Channels& c = t.trajectory.channels();
             return fmt::format("<cheval.Trajectory '{}' ({}): {} poses, orientation {}{}{}>", t.path,
                                traj::ToString(t.format), t.trajectory.size(), OrientationName(c.orientation),
                                c.velocity ? ", velocity" : "", c.angular_velocity ? ", angular velocity" : "");
           })
      .def_readonly("path", &PyTrajectory::path, "The file it was read from, or '<array>'.")
      .def_property_readonly(
          "format", [](const PyTrajectory& t) { return std::string(traj::ToString(t.format)); },
          "The format it was read in (the detected one for format='auto'); 'auto' when built from arrays.")
      .def_property_readonly(
          "stamps",
          [](const py::object& self) {
            const auto& t = self.cast<const PyTrajectory&>().trajectory;
            return ViewOf(t.stamps_ns().data(), {t.size()}, {static_cast<py::ssize_t>(sizeof(int64_t))}, self);
          },
          "int64 stamps in nanoseconds, shape (n,), in file order (a view, no copy). For a KITTI file without "
          "times these are the pose indices in seconds and has_stamps is False.")
      .def_property_readonly(
          "positions", ChannelView(&traj::Trajectory::raw_positions, [](const traj::Channels&) { return true; }),
          "Positions p_world_body in metres, shape (n, 3) (a view, no copy).")
      .def_property_readonly(
          "quaternions",
          [](const py::object& self) -> py::object {
            const PyTrajectory& p = self.cast<const PyTrajectory&>();
            const auto& t = p.trajectory;
            py::object xyzw = py::none();
            switch (t.channels().orientation) {
              case traj::OrientationKind::kQuaternion:
                xyzw = ViewOf(t.raw_orientations().data(), {t.size(), 4}, {4 * kDouble, kDouble}, self);
                break;
              case traj::OrientationKind::kMatrix: xyzw = QuaternionsOf(t.View()); break;
              case traj::OrientationKind::kNone: break;
            }
            if (xyzw.is_none() || !p.quat_wxyz) return xyzw;
            return py::module_::import("numpy").attr("roll")(xyzw, 1, py::arg("axis") = 1);  // w first (a copy)
          },
          "Orientations as quaternions, shape (n, 4), in the trajectory's quat_order (x, y, z, w unless "
          "'wxyz' was asked): exactly as read (not normalised; a view, no copy, in x y z w) when the file "
          "stores quaternions; unit quaternions of the matrices (a copy) for KITTI; a copy in w x y z; None "
          "for a position-only trajectory.")
      .def_property_readonly(
          "quat_order", [](const PyTrajectory& t) { return std::string(t.quat_wxyz ? "wxyz" : "xyzw"); },
          "The order of the quaternion arrays this trajectory takes and gives: 'xyzw' (cheval's, TUM's) or "
          "'wxyz' (evo's orientations_quat_wxyz, EuRoC's).")
      .def_property_readonly(
          "rotations",
          [](const py::object& self) -> py::object {
            const auto& t = self.cast<const PyTrajectory&>().trajectory;
            if (t.channels().orientation == traj::OrientationKind::kMatrix) {
              return ViewOf(t.raw_orientations().data(), {t.size(), 3, 3}, {9 * kDouble, 3 * kDouble, kDouble}, self);
            }
            if (t.channels().orientation == traj::OrientationKind::kQuaternion) return RotationsOf(t.View());
            return py::none();
          },
          "Rotation matrices R_world_body, shape (n, 3, 3): the KITTI matrices as read (a view, no copy), or "
          "the quaternions' matrices with evo's normalisation (a copy); None without orientation.")
      .def_property_readonly(
          "velocities", ChannelView(&traj::Trajectory::raw_velocities, [](const traj::Channels& c) { return c.velocity; }),
          "World-frame linear velocities in m/s, shape (n, 3) (a view, no copy), or None.")
      .def_property_readonly("angular_velocities",
                             ChannelView(&traj::Trajectory::raw_angular_velocities,
                                         [](const traj::Channels& c) { return c.angular_velocity; }),
          "Body-frame angular velocities in rad/s, shape (n, 3) (a view, no copy), or None.")
      .def_property_readonly(
          "orientation", [](const PyTrajectory& t) { return OrientationName(t.trajectory.channels().orientation); },
          "How orientations are stored: 'quaternion', 'matrix' (KITTI) or 'none'.")
      .def_property_readonly("has_stamps", [](const PyTrajectory& t) { return t.trajectory.channels().has_stamps; },
                             "False for KITTI poses read without a times file.")
      .def(
          "to_text",
          [](const PyTrajectory& t, const std::string& format) {
            return traj::FormatTrajectory(t.trajectory.View(), FormatOf(format));
          },
          py::arg("format") = "tum",
          "The trajectory as the text of a file in `format` (tum, tumv, euroc, kitti), as cheval.write writes it.");

  m.def(
      "check_real",
      [](const py::handle& values, const std::string& name) {
        const py::array array = py::array::ensure(values);
        if (array) CheckReal(array, name.c_str());
      },
      "Raises InputError for a complex (or text) array `values`, named `name`, as Trajectory() does.");

  m.def(
      "read",
      [](const std::string& path, const std::string& format, const std::string& columns,
         const std::string& kitti_times, const std::string& topic, bool bag_time, const std::string& quat_order) {
        traj::ReadOptions options = traj::ReadOptions::FromNames(format, columns, kitti_times);
        options.topic = topic;
        options.record_time = bag_time;
        PyTrajectory out;
        {
          py::gil_scoped_release release;
          out.trajectory = traj::ReadTrajectory(path, options, &out.format);
        }
        out.path = path;
        out.quat_wxyz = QuatOrderIsWxyz(quat_order);
        return out;
      },
      py::arg("path"), py::arg("format") = "auto", py::arg("columns") = "", py::arg("kitti_times") = "",
      py::arg("topic") = "", py::arg("bag_time") = false, py::arg("quat_order") = "xyzw",
      R"(Reads a trajectory file exactly as the CLI does (docs/formats.md).

format: auto, tum, tumv, euroc, kitti, vins or csv; columns: a column map such as
't_ns,px,py,pz,qw,qx,qy,qz' (implies csv; '_' skips a column); kitti_times: a file of one stamp
(seconds) per KITTI pose. topic: for a recording (ROS 1 bag, ROS 2 bag folder, MCAP; docs/bags.md),
the topic or '/tf:PARENT.CHILD'; bag_time: stamps from the record time. Raises InputError ('PATH:LINE:COLUMN: error: ...') on bad input and
UsageError on bad arguments.)");

  m.def(
      "write",
      [](const PyTrajectory& t, const std::string& path, const std::string& format) {
        const traj::Format f = FormatOf(format);
        py::gil_scoped_release release;
        traj::WriteTrajectory(path, t.trajectory.View(), f);
      },
      py::arg("trajectory"), py::arg("path"), py::arg("format") = "tum",
      R"(Writes a trajectory atomically (a temporary file renamed into place) in tum, tumv, euroc or
kitti. Raises ComputeError when the trajectory lacks what the format needs (orientation;
velocity for tumv) and OutputError when the file cannot be written.)");

  m.def(
      "simulate",
      [](const std::string& kind, uint64_t seed, std::optional<double> duration, std::optional<double> rate,
         double noise, double rotation_noise, double jitter, double dropout, int gap_count, double gap_seconds) {
        sim::MotionOptions options;
        const auto parsed = sim::MotionKindFromString(kind);
        if (!parsed) throw UsageError(fmt::format("kind: expected car, legged, drone or handheld, got '{}'", kind));
        options.kind = *parsed;
        options.seed = seed;
        options.duration_s = duration;
        options.rate_hz = rate;
        sim::MeasurementOptions measurement;
        measurement.noise_m = noise;
        measurement.rotation_noise_rad = rotation_noise;
        measurement.jitter_s = jitter;
        measurement.dropout_probability = dropout;
        measurement.gap_count = gap_count;
        measurement.gap_s = gap_seconds;
        py::gil_scoped_release release;
        const sim::MotionModel model(options);
        PyTrajectory measured{sim::Measure(model, measurement), "<simulated>"};
        PyTrajectory truth{sim::GenerateMotion(model), "<simulated truth>"};
        return std::make_pair(std::move(measured), std::move(truth));
      },
      py::arg(Keyword("MotionOptions::kind")) = std::string(sim::ToString(sim::MotionOptions{}.kind)), py::arg(Keyword("MotionOptions::seed")) = sim::MotionOptions{}.seed,
      py::arg(Keyword("MotionOptions::duration_s")) = py::none(), py::arg(Keyword("MotionOptions::rate_hz")) = py::none(),
      py::arg(Keyword("MeasurementOptions::noise_m")) = sim::MeasurementOptions{}.noise_m,
      py::arg(Keyword("MeasurementOptions::rotation_noise_rad")) = sim::MeasurementOptions{}.rotation_noise_rad,
      py::arg(Keyword("MeasurementOptions::jitter_s")) = sim::MeasurementOptions{}.jitter_s,
      py::arg(Keyword("MeasurementOptions::dropout_probability")) = sim::MeasurementOptions{}.dropout_probability,
      py::arg(Keyword("MeasurementOptions::gap_count")) = sim::MeasurementOptions{}.gap_count,
      py::arg(Keyword("MeasurementOptions::gap_s")) = sim::MeasurementOptions{}.gap_s,
      R"(Synthetic motion with exact derivatives, as `cheval sim motion` (docs/sim.md): returns
(measured, truth). truth: the exact poses, world-frame velocities and body rates on the nominal
grid; measured: poses at jittered stamps with dropouts and gaps, positions + N(0, noise²) per
axis, orientations perturbed by rotation_noise (rad). kind: car, legged, drone or handheld;
duration (s) and rate (Hz) default per kind. Raises UsageError naming the keyword for bad values.)");
}

}  // namespace cheval::python
