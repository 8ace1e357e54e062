// The extension module `cheval._cheval`: the library's typed errors as Python exceptions, the numpy
// hand-over helpers, and the registration of every binding. python/cheval/__init__.py is the public
// face over it (docs/python.md).
#include <charconv>
#include <exception>
#include <string>

#include "bindings.h"
#include <fmt/format.h>

#include "cheval/common/error.h"
#include "cheval/traj/stamp.h"
#include "cheval/traj/validate.h"

namespace cheval::python {
namespace {

// The exception classes, created once when the module is imported (they live as long as Python).
PyObject* g_error = nullptr;
PyObject* g_input_error = nullptr;
PyObject* g_usage_error = nullptr;
PyObject* g_compute_error = nullptr;
PyObject* g_output_error = nullptr;

PyObject* NewException(py::module_& m, const char* name, const char* doc, py::tuple bases) {
  const std::string qualified = std::string("cheval.") + name;
  PyObject* type = PyErr_NewExceptionWithDoc(qualified.c_str(), doc, bases.ptr(), nullptr);
  if (type == nullptr) throw py::error_already_set();
  m.add_object(name, py::handle(type));  // the module keeps a reference; so does `type` (never released)
  return type;
}

// Raises `type` with the library's message (what()) as its only argument, the options it names
// spelled as keyword arguments (option_names.cc).
void Raise(PyObject* type, const std::exception& e) { PyErr_SetString(type, Spell(e.what()).c_str()); }

}  // namespace

void BindErrors(py::module_& m) {
  const py::handle exception(PyExc_Exception), value_error(PyExc_ValueError), runtime_error(PyExc_RuntimeError),
      os_error(PyExc_OSError);
  g_error = NewException(m, "Error", "Base of every error cheval raises; str(e) is the complete message.",
                         py::make_tuple(exception));
  const py::handle error(g_error);
  // The typed errors: name, description, the standard exception each also is.
  const struct {
    PyObject** type;
    const char* name;
    const char* doc;
    py::handle standard;
  } kErrors[] = {
      {&g_input_error, "InputError",
       "Bad input data (a file or arrays): the message is 'PATH:LINE:COLUMN: error: WHAT' (the CLI's exit code 2). "
       "Attributes: path, line, column (1-based; 0 = the file as a whole) and detail (WHAT alone).",
       value_error},
      {&g_usage_error, "UsageError",
       "A bad option value or combination, found before any work (the CLI's exit code 1); the message names the "
       "keyword argument.",
       value_error},
      {&g_compute_error, "ComputeError",
       "Well-formed input on which the computation is impossible, e.g. no associated pair or too few samples "
       "(the CLI's exit code 3). The message says what to change.",
       runtime_error},
      {&g_output_error, "OutputError", "An output file could not be written; nothing partial is left (exit code 4).",
       os_error},
  };
  for (const auto& e : kErrors) *e.type = NewException(m, e.name, e.doc, py::make_tuple(error, e.standard));

  py::register_exception_translator([](std::exception_ptr thrown) {
    try {
      if (thrown) std::rethrow_exception(thrown);
    } catch (const InputError& e) {
      py::object exc = py::handle(g_input_error)(Spell(e.what()));
      exc.attr("path") = e.path();
      exc.attr("line") = e.line();
      exc.attr("column") = e.column();
      exc.attr("detail") = Spell(e.detail());
      PyErr_SetObject(g_input_error, exc.ptr());
    } catch (const UsageError& e) {
      Raise(g_usage_error, e);
    } catch (const ComputeError& e) {
      Raise(g_compute_error, e);
    } catch (const OutputError& e) {
      Raise(g_output_error, e);
    }
  });
}

py::array AdoptColumns(Eigen::Matrix3Xd&& columns) {
  const auto n = static_cast<py::ssize_t>(columns.cols());
  constexpr auto kDouble = static_cast<py::ssize_t>(sizeof(double));
  return AdoptArray<double>(std::move(columns), [](const Eigen::Matrix3Xd& m) { return m.data(); }, {n, 3},
                            {3 * kDouble, kDouble});
}

py::array AdoptMatrix(Eigen::MatrixXd&& matrix) {
  const auto rows = static_cast<py::ssize_t>(matrix.rows()), cols = static_cast<py::ssize_t>(matrix.cols());
  constexpr auto kDouble = static_cast<py::ssize_t>(sizeof(double));
  return AdoptArray<double>(std::move(matrix), [](const Eigen::MatrixXd& m) { return m.data(); }, {rows, cols},
                            {kDouble, rows * kDouble});
}

bool QuatOrderIsWxyz(const std::string& quat_order) {
  if (quat_order != "xyzw" && quat_order != "wxyz") {
    throw UsageError(fmt::format("quat_order: expected 'xyzw' or 'wxyz', got '{}'", quat_order));
  }
  return quat_order == "wxyz";
}

namespace {

// Float seconds as the readers take decimal text: each value's shortest round-trip decimal
// (std::to_chars, the digits Python's repr shows) parsed exactly (traj::ParseDecimalStamp, halves to
// even at the nanosecond), so 1403715529.1121435 gives the stamp a TUM file with that text gives.
py::array_t<int64_t> StampsFromSeconds(const py::array& array) {
  const auto seconds = py::array_t<double, py::array::forcecast>::ensure(array);
  const auto view = seconds.unchecked<1>();
  py::array_t<int64_t> out(view.shape(0));
  auto stamps = out.mutable_unchecked<1>();
  for (py::ssize_t i = 0; i < view.shape(0); ++i) {
    char text[64];
    const auto [end, error] = std::to_chars(text, text + sizeof text, view(i));
    const std::string_view decimal(text, error == std::errc() ? static_cast<size_t>(end - text) : 0);
    const traj::StampParseResult r = traj::ParseDecimalStamp(decimal, 9);
    if (r.error) {
      throw InputError("<array>", 0, 0,
                       fmt::format("row {}: stamps[{}] = {}: {}", i, i, decimal,
                                   *r.error == traj::StampParseError::kOutOfRange
                                       ? "beyond int64 nanoseconds (about +-292 years)"
                                       : "not a finite number of seconds"));
    }
    stamps(i) = r.value;
  }
  return StampsArray(out);  // the span check of integer stamps
}

}  // namespace

py::array_t<int64_t> StampsArray(const py::handle& stamps) {
  const py::array array = py::array::ensure(stamps);
  if (!array) throw py::type_error("stamps: expected an array of integer nanoseconds");
  const char kind = array.dtype().kind();
  if (array.ndim() != 1) throw py::value_error("stamps: expected a 1-D array, got " + std::to_string(array.ndim()) + "-D");
  if (kind == 'f') return StampsFromSeconds(array);
  if (kind != 'i' && kind != 'u') {
    throw py::type_error("stamps must be integer nanoseconds (int64) or float seconds, got dtype " +
                         py::str(array.dtype()).cast<std::string>());
  }
  if (kind == 'u' && array.itemsize() == sizeof(uint64_t)) {
    // A cast to int64 would wrap 2^63 and beyond to negative stamps.
    const auto unsigned_stamps = py::array_t<uint64_t, py::array::forcecast>::ensure(array);
    const auto view = unsigned_stamps.unchecked<1>();
    for (py::ssize_t i = 0; i < view.shape(0); ++i) {
      if (view(i) > static_cast<uint64_t>(INT64_MAX)) {
        throw InputError("<array>", 0, 0,
                         fmt::format("row {}: {}", i, traj::StampOutOfRangeMessage(std::to_string(view(i)),
                                                                                    fmt::format("stamps[{}]", i))));
      }
    }
  }
  auto converted = py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(array);
  // Every difference of two stamps must fit int64, as in a file (traj::StampSpan).
  traj::StampSpan span;
  const int64_t* data = converted.data();
  for (py::ssize_t i = 0; i < converted.size(); ++i) {
    if (auto problem = span.Add(data[i], i, "row")) {
      throw InputError("<array>", 0, 0, fmt::format("row {}: {}", i, *problem));
    }
  }
  return converted;
}

DoubleArray RealArray(const py::handle& values, const char* name) {
  const py::array array = py::array::ensure(values);
  if (!array) throw py::type_error(fmt::format("{}: expected an array of numbers", name));
  CheckReal(array, name);
  DoubleArray converted = DoubleArray::ensure(array);
  if (!converted) throw py::type_error(fmt::format("{}: expected an array of real numbers", name));
  return converted;
}

void CheckReal(const py::array& array, const char* name) {
  const char kind = array.dtype().kind();
  if (kind == 'c') {
    throw InputError("<array>", 0, 0,
                     fmt::format("{}: complex values (dtype {}) are not accepted; expected real numbers (a conversion "
                                 "would drop the imaginary part)",
                                 name, py::str(array.dtype()).cast<std::string>()));
  }
  if (kind != 'f' && kind != 'i' && kind != 'u' && kind != 'b' && kind != 'O') {
    throw InputError("<array>", 0, 0,
                     fmt::format("{}: expected real numbers, got dtype {}", name, py::str(array.dtype()).cast<std::string>()));
  }
}

}  // namespace cheval::python

PYBIND11_MODULE(_cheval, m) {
  m.doc() = "The compiled core of the Python module cheval; import cheval instead (docs/python.md).";
  cheval::python::BindErrors(m);
  cheval::python::BindTrajectory(m);
  cheval::python::BindChebyshev(m);
  cheval::python::BindEvaluation(m);
  cheval::python::BindEstimator(m);
}
