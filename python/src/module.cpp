// proxseg._proxseg: the extension under the Python package proxseg (python/proxseg/). The
// package's Python layer turns parameters, Open3D clouds and results into Python's habits; this
// layer converts numpy arrays, releases the GIL around the computation and maps errors.
#include <proxseg/core/errors.hpp>
#include <proxseg/core/version.hpp>
#include <proxseg/io/memory.hpp>
#include <proxseg/io/output.hpp>

#include <nlohmann/json.hpp>

#include <cstdlib>
#include <cstring>
#include <stdexcept>

#include "bindings.hpp"
#include "stop.hpp"

namespace proxseg::python {

std::vector<py::ssize_t> point_shape(const Frame& frame) {
  if (frame.organized()) return {frame.height, frame.width};
  return {static_cast<py::ssize_t>(frame.size())};
}

namespace {

py::object to_python(const nlohmann::json& j) {
  switch (j.type()) {
    case nlohmann::json::value_t::null:
      return py::none();
    case nlohmann::json::value_t::boolean:
      return py::bool_(j.get<bool>());
    case nlohmann::json::value_t::number_integer:
      return py::int_(j.get<std::int64_t>());
    case nlohmann::json::value_t::number_unsigned:
      return py::int_(j.get<std::uint64_t>());
    case nlohmann::json::value_t::number_float:
      return py::float_(j.get<double>());
    case nlohmann::json::value_t::string:
      return py::str(j.get_ref<const std::string&>());
    case nlohmann::json::value_t::array: {
      py::list out;
      for (const auto& v : j) out.append(to_python(v));
      return std::move(out);
    }
    case nlohmann::json::value_t::object: {
      py::dict out;
      for (const auto& [k, v] : j.items()) out[py::str(k)] = to_python(v);
      return std::move(out);
    }
    default:
      throw std::invalid_argument("cannot convert JSON value to Python");
  }
}

nlohmann::json from_python(const py::handle& v, const std::string& where) {
  if (v.is_none()) return nullptr;
  if (py::isinstance<py::bool_>(v)) return v.cast<bool>();
  if (py::isinstance<py::int_>(v)) {
    if (v.cast<py::int_>() < py::int_(0)) return v.cast<std::int64_t>();
    return v.cast<std::uint64_t>();
  }
  if (py::isinstance<py::float_>(v)) return v.cast<double>();
  if (py::isinstance<py::str>(v)) return v.cast<std::string>();
  if (py::isinstance<py::dict>(v)) {
    nlohmann::json out = nlohmann::json::object();
    for (const auto& [k, x] : v.cast<py::dict>()) {
      const std::string key = py::str(k);
      out[key] = from_python(x, where.empty() ? key : where + "." + key);
    }
    return out;
  }
  if (py::isinstance<py::list>(v) || py::isinstance<py::tuple>(v)) {
    nlohmann::json out = nlohmann::json::array();
    for (const auto& x : v) out.push_back(from_python(x, where));
    return out;
  }
  // numpy scalars and other numbers
  if (py::hasattr(v, "__float__") && py::hasattr(v, "dtype")) {
    const std::string kind = py::str(v.attr("dtype").attr("kind"));
    if (kind == "b") return v.cast<bool>();
    if (kind == "i" || kind == "u")
      return py::int_(py::reinterpret_borrow<py::object>(v)).cast<std::int64_t>();
    return py::float_(py::reinterpret_borrow<py::object>(v)).cast<double>();
  }
  throw InputError((where.empty() ? std::string("parameters") : where) + ": " +
                   std::string(py::str(py::type::of(v).attr("__name__"))) +
                   " is not a JSON value (expected a number, bool, string, list or dict)");
}

}  // namespace

py::object json_to_python(const nlohmann::json& j) {
  return to_python(j);
}
nlohmann::json python_to_json(const py::handle& value) {
  return from_python(value, "");
}

}  // namespace proxseg::python

PYBIND11_MODULE(_proxseg, m) {
  namespace py = pybind11;
  using namespace proxseg::python;
  m.doc() = "proxseg's compiled core; use the package `proxseg`, which wraps it.";
  m.attr("__version__") = PROXSEG_VERSION;
  m.def(
      "build_info", [] { return json_to_python(proxseg::build_info()); },
      "{'version': ..., 'commit': ...}: what built this module (echoed in every report).");

  // A file the system refuses -> OSError; any other bad input -> ValueError. FileError derives
  // from InputError, so it is registered last (pybind11 tries translators newest first).
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const proxseg::FileError& e) {
      // OSError(errno, message) is the subclass the errno names: FileNotFoundError,
      // PermissionError, IsADirectoryError, NotADirectoryError.
      if (e.error != 0) {
        PyObject* args = Py_BuildValue("(is)", e.error, e.what());
        PyErr_SetObject(PyExc_OSError, args);
        Py_XDECREF(args);
      } else {
        PyErr_SetString(PyExc_OSError, e.what());
      }
    } catch (const proxseg::InputError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const std::invalid_argument& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });

  // A process that segments frame after frame keeps the memory segment() frees for the next
  // frame, as the CLI does (io/memory.hpp): without it each call page-faults its buffers in
  // again, which made segment() from Python 1.6 times the C++ call's time (docs/results.md,
  // Python). Import is this module's start-up; PROXSEG_KEEP_FREED_MEMORY=0 leaves the
  // allocator as it is.
  const char* keep = std::getenv("PROXSEG_KEEP_FREED_MEMORY");
  const bool keeps = keep == nullptr || std::strcmp(keep, "0") != 0;
  if (keeps) proxseg::keep_freed_memory();
  m.attr("_keeps_freed_memory") = keeps;

  bind_frame(m);
  bind_segment(m);
  bind_database(m);
  bind_recognition(m);
  bind_batch(m);
  bind_stop(m);
}
