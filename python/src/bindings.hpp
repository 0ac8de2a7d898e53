// Shared pieces of the Python bindings (python/src/*.cpp): numpy <-> std::vector without copies
// where the layout allows, and the bind_* functions that module.cpp calls in order.
#pragma once
#include <proxseg/core/frame.hpp>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <nlohmann/json.hpp>

#include <string>
#include <utility>
#include <vector>

namespace proxseg::python {

namespace py = pybind11;

// A numpy array that owns the vector's buffer (moved, not copied), shaped `shape`.
template <class T>
py::array_t<T> to_numpy(std::vector<T>&& values, std::vector<py::ssize_t> shape) {
  auto* owned = new std::vector<T>(std::move(values));
  py::capsule owner(owned, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<T>(std::move(shape), owned->data(), owner);
}

// The shape of per-point arrays for this frame: (height, width) when organized, else (n,).
std::vector<py::ssize_t> point_shape(const Frame& frame);

// JSON (reports, parameters) as Python dicts, lists and numbers, and back.
py::object json_to_python(const nlohmann::json& j);
nlohmann::json python_to_json(const py::handle& value);

void bind_frame(py::module_& m);
void bind_segment(py::module_& m);
void bind_database(py::module_& m);
void bind_recognition(py::module_& m);
void bind_batch(py::module_& m);

}  // namespace proxseg::python
