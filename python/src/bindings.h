#pragma once
// Shared pieces of the Python face (module `cheval._cheval`, wrapped by python/cheval/__init__.py):
// the trajectory object Python holds, and the numpy hand-over in both directions. The bindings hold
// no logic of their own: they convert arguments, call the library and convert the results.

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "cheval/cheb/curve.h"
#include "cheval/traj/io.h"
#include "cheval/traj/trajectory.h"

namespace cheval::python {

namespace py = pybind11;

/// A trajectory as Python holds it: the library's Trajectory (never modified once built, so numpy
/// views of its channels stay valid while the object lives), the name it was read from and the
/// format used ("<array>" and auto for one built from arrays).
struct PyTrajectory {
  traj::Trajectory trajectory;
  std::string path = "<array>";
  traj::Format format = traj::Format::kAuto;
  /// The order of the quaternion arrays this object takes and gives (quat_order 'wxyz'); the library's
  /// storage is always x y z w.
  bool quat_wxyz = false;
};

/// quat_order's value: true for 'wxyz', false for 'xyzw'; UsageError naming the keyword otherwise.
bool QuatOrderIsWxyz(const std::string& quat_order);

/// A read-only numpy view of `data` (no copy) whose lifetime is tied to `owner` (the Python object
/// that owns the memory). `shape` and `strides` (bytes) as numpy takes them.
template <typename Scalar>
py::array ViewOf(const Scalar* data, std::vector<py::ssize_t> shape, std::vector<py::ssize_t> strides,
                 py::handle owner) {
  py::array array(py::dtype::of<Scalar>(), std::move(shape), std::move(strides), data, owner);
  py::detail::array_proxy(array.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return array;
}

/// Moves `owner` (a std::vector or an Eigen matrix: moving keeps its buffer) to the heap and returns
/// a numpy array over its memory (no copy) that frees it when the array dies. `data` gives the first
/// element of the moved object.
template <typename Scalar, typename Owner, typename DataOf>
py::array AdoptArray(Owner&& owner, DataOf data, std::vector<py::ssize_t> shape, std::vector<py::ssize_t> strides) {
  auto* heap = new std::decay_t<Owner>(std::forward<Owner>(owner));
  py::capsule free_when_done(heap, [](void* p) { delete static_cast<std::decay_t<Owner>*>(p); });
  return py::array(py::dtype::of<Scalar>(), std::move(shape), std::move(strides), data(*heap), free_when_done);
}

/// A std::vector<T> as a 1-D numpy array, without a copy.
template <typename T>
py::array AdoptVector(std::vector<T>&& values) {
  const auto n = static_cast<py::ssize_t>(values.size());
  return AdoptArray<T>(std::move(values), [](const std::vector<T>& v) { return v.data(); }, {n},
                       {static_cast<py::ssize_t>(sizeof(T))});
}

/// A 3 x n column-major matrix (column i = sample i) as an (n, 3) C-ordered numpy array, no copy.
py::array AdoptColumns(Eigen::Matrix3Xd&& columns);

/// An n x d column-major matrix as an (n, d) Fortran-ordered numpy array, no copy.
py::array AdoptMatrix(Eigen::MatrixXd&& matrix);

/// Integer stamps (nanoseconds) from a numpy array or sequence: a view when it is already a
/// contiguous int64 array, else a converted copy. Floating-point input is refused with a TypeError
/// (seconds would be silently truncated); an unsigned stamp beyond int64 (>= 2^63, which a cast would
/// wrap to a negative one) and stamps spanning more than int64 nanoseconds (traj::StampSpan) with
/// InputError, the readers' messages. The returned array keeps the memory alive.
py::array_t<int64_t> StampsArray(const py::handle& stamps);
/// A C-ordered float64 array of real numbers from `values` (a numpy array or a sequence): a view when
/// it already is one, else a converted copy. A complex array (whose imaginary part a conversion would
/// drop), or one of text, bytes or objects, is refused with InputError naming the argument `name`.
using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;
DoubleArray RealArray(const py::handle& values, const char* name);
/// The check of RealArray alone, without a conversion: InputError for a complex or text `array`.
void CheckReal(const py::array& array, const char* name);

inline std::span<const int64_t> SpanOf(const py::array_t<int64_t>& stamps) {
  return {stamps.data(), static_cast<size_t>(stamps.size())};
}

/// Curve options from the Python arguments of fit and velocity: degree 'auto' (= 'cv'), 'chop' or
/// an int (eval::CurveOptionsFromNames), window (s) and noise sigma (None: adaptive /
/// estimated). The library validates the values (OptionError).
cheb::CurveOptions CurveOptionsOf(const py::object& degree, std::optional<double> window, std::optional<double> noise,
                                  int threads);

/// The keyword argument of a library options field ("AlignmentOptions::n_align" -> "n_align"), from
/// the one table of python/src/option_names.cc; std::logic_error for a field not in it.
const char* Keyword(std::string_view field);

/// `message` with every options field of that table spelled as its keyword (the exception
/// translator applies it to every library error).
std::string Spell(std::string_view message);

void BindErrors(py::module_& m);
void BindTrajectory(py::module_& m);
void BindChebyshev(py::module_& m);
void BindEvaluation(py::module_& m);
void BindEstimator(py::module_& m);

}  // namespace cheval::python
