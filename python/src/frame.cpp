// proxseg.Frame from numpy arrays and files; its points and colours as numpy views (no copy).
#include <proxseg/core/errors.hpp>
#include <proxseg/core/rgbd.hpp>
#include <proxseg/io/cloud_io.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>

#include "bindings.hpp"
#include "stop.hpp"

namespace proxseg::python {
namespace {

std::string shape_str(const std::vector<py::ssize_t>& shape) {
  std::string s = "(";
  for (std::size_t i = 0; i < shape.size(); ++i) s += (i ? ", " : "") + std::to_string(shape[i]);
  return s + (shape.size() == 1 ? ",)" : ")");
}
std::vector<py::ssize_t> shape_of(const py::array& a) {
  return {a.shape(), a.shape() + a.ndim()};
}
std::string shape_str(const py::array& a) {
  return shape_str(shape_of(a));
}

std::string dtype_str(const py::array& a) {
  return py::str(a.dtype());
}

// An array-like (numpy array, list, anything numpy.asarray takes) as a numpy array; TypeError
// naming the argument and the type, never the value (which may be millions of numbers).
py::array as_array(const py::handle& value, const char* name) {
  if (py::isinstance<py::array>(value)) return py::reinterpret_borrow<py::array>(value);
  const auto not_array_like = [&] {
    return py::type_error(std::string(name) + ": " +
                          std::string(py::str(py::type::of(value).attr("__name__"))) +
                          " is not array-like (expected a numpy array or nested lists of numbers)");
  };
  py::array a;
  try {
    a = py::module_::import("numpy").attr("asarray")(value);
  } catch (const py::error_already_set&) {
    throw not_array_like();
  }
  if (a.dtype().kind() == 'O' || a.dtype().kind() == 'U' || a.dtype().kind() == 'S')
    throw not_array_like();
  return a;
}

// None -> no colour; else of exactly the points' shape ((N, 3) or (H, W, 3)): uint8 0-255, or
// floats in [0, 1] (Open3D's colours) rounded to the nearest of 0-255.
std::vector<Rgb> colours_from_numpy(const py::object& rgb, const std::vector<py::ssize_t>& shape) {
  if (rgb.is_none()) return {};
  py::array colours = as_array(rgb, "rgb");
  if (shape_of(colours) != shape)
    throw InputError("rgb: shape " + shape_str(colours) + " (expected " + shape_str(shape) + ")");
  if (colours.dtype().kind() == 'f') {
    const auto f = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(colours);
    std::vector<Rgb> out(static_cast<std::size_t>(f.size() / 3));
    const double* v = f.data();
    for (std::size_t i = 0; i < out.size() * 3; ++i) {
      if (!(v[i] >= 0 && v[i] <= 1))
        throw InputError("rgb: float colours must lie in [0, 1] (Open3D's), got " +
                         std::to_string(v[i]) + " (or give uint8 0-255)");
      out[i / 3][i % 3] = static_cast<std::uint8_t>(std::lround(v[i] * 255.0));
    }
    return out;
  }
  if (colours.dtype().kind() != 'u' || colours.itemsize() != 1)
    throw InputError("rgb: dtype " + dtype_str(colours) +
                     " (expected uint8 0-255, or floats in [0, 1])");
  const auto c = py::array_t<std::uint8_t, py::array::c_style>::ensure(colours);
  std::vector<Rgb> out(static_cast<std::size_t>(c.size() / 3));
  if (!out.empty()) std::memcpy(out.data()->data(), c.data(), out.size() * 3);
  return out;
}

// xyz (N, 3) or (H, W, 3) floats, metres; rgb None or uint8 of the same leading shape. One copy
// into the frame's own storage (memcpy for C-contiguous float32).
Frame frame_from_numpy(const py::object& xyz_like, const py::object& rgb) {
  py::array xyz = as_array(xyz_like, "xyz");
  if (xyz.dtype().kind() == 'i' || xyz.dtype().kind() == 'u')  // integers from a list
    xyz = py::array_t<float, py::array::forcecast>::ensure(xyz);
  if (xyz.dtype().kind() != 'f')
    throw InputError("xyz: dtype " + dtype_str(xyz) + " (expected float32 or float64 metres)");
  if (!((xyz.ndim() == 2 || xyz.ndim() == 3) && xyz.shape(xyz.ndim() - 1) == 3))
    throw InputError("xyz: shape " + shape_str(xyz) + " (expected (N, 3) or (H, W, 3))");
  const auto points = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(xyz);
  if (!points) throw InputError("xyz: cannot be read as float32");
  Frame frame;
  if (xyz.ndim() == 3) {
    frame.height = static_cast<int>(xyz.shape(0));
    frame.width = static_cast<int>(xyz.shape(1));
  } else {
    frame.height = 1;
    frame.width = static_cast<int>(xyz.shape(0));
  }
  const std::size_t n = static_cast<std::size_t>(points.size() / 3);
  frame.xyz.resize(n);
  if (n) std::memcpy(frame.xyz.data()->data(), points.data(), n * 3 * sizeof(float));
  frame.rgb = colours_from_numpy(rgb, shape_of(xyz));
  return frame;
}

// A writable view of the frame's storage, kept alive by the Python Frame (base).
template <class T, class Element>
py::array view(std::vector<Element>& values, const Frame& frame, const py::object& base) {
  std::vector<py::ssize_t> shape = point_shape(frame);
  shape.push_back(3);
  if (values.empty()) return py::array_t<T>(shape);
  return py::array_t<T>(shape, reinterpret_cast<T*>(values.data()), base);
}

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

template <class Depth>
std::vector<Eigen::Vector3f> depth_points(const py::array& depth, const Intrinsics& k) {
  const auto d = py::array_t<Depth, py::array::c_style>::ensure(depth);
  const int h = static_cast<int>(depth.shape(0)), w = static_cast<int>(depth.shape(1));
  return without_gil([&] { return back_project(d.data(), w, h, k); });
}

// color (H, W, 3) uint8 RGB or None, depth (H, W) uint16 (depth units) or float32 (units).
Frame frame_from_rgbd(const py::object& colour, const py::array& depth,
                      const py::array_t<double, py::array::forcecast>& K, double depth_scale) {
  if (depth.ndim() != 2)
    throw InputError("depth: shape " + shape_str(depth) + " (expected (H, W))");
  if (K.ndim() != 2 || K.shape(0) != 3 || K.shape(1) != 3)
    throw InputError("K: shape " + shape_str(K) + " (expected the 3x3 camera matrix)");
  const auto k3 = K.unchecked<2>();
  const Intrinsics k{k3(0, 0), k3(1, 1), k3(0, 2), k3(1, 2), depth_scale};
  Frame frame;
  frame.height = static_cast<int>(depth.shape(0));
  frame.width = static_cast<int>(depth.shape(1));
  if (depth.dtype().is(py::dtype::of<std::uint16_t>()))
    frame.xyz = depth_points<std::uint16_t>(depth, k);
  else if (depth.dtype().kind() == 'f')
    frame.xyz = depth_points<float>(
        py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(depth), k);
  else
    throw InputError("depth: dtype " + dtype_str(depth) +
                     " (expected uint16 depth units or float32; 0 = no return)");
  frame.rgb = colours_from_numpy(colour, {depth.shape(0), depth.shape(1), 3});
  return frame;
}

// A frame as picklable state: (xyz, rgb, label, width, height), plain arrays and numbers.
py::tuple frame_state(const Frame& f) {
  py::object label = py::none();
  if (!f.label.empty())
    label =
        to_numpy(std::vector<std::uint32_t>(f.label), {static_cast<py::ssize_t>(f.label.size())});
  py::bytes xyz(reinterpret_cast<const char*>(f.xyz.data()), f.xyz.size() * 12);
  py::bytes rgb(reinterpret_cast<const char*>(f.rgb.data()), f.rgb.size() * 3);
  return py::make_tuple(xyz, rgb, label, f.width, f.height);
}

// The frame of frame_state()'s tuple.
Frame frame_from_state(const py::tuple& t) {
  if (t.size() != 5) throw InputError("Frame: not a pickled proxseg.Frame");
  Frame f;
  const std::string xyz = t[0].cast<std::string>(), rgb = t[1].cast<std::string>();
  f.width = t[3].cast<int>();
  f.height = t[4].cast<int>();
  if (xyz.size() % 12 != 0 || rgb.size() % 3 != 0 ||
      (!rgb.empty() && rgb.size() / 3 != xyz.size() / 12) ||
      static_cast<std::size_t>(f.width) * f.height != xyz.size() / 12)
    throw InputError("Frame: not a pickled proxseg.Frame (sizes do not agree)");
  f.xyz.resize(xyz.size() / 12);
  if (!xyz.empty()) std::memcpy(f.xyz.data()->data(), xyz.data(), xyz.size());
  f.rgb.resize(rgb.size() / 3);
  if (!rgb.empty()) std::memcpy(f.rgb.data()->data(), rgb.data(), rgb.size());
  if (!t[2].is_none()) f.label = t[2].cast<std::vector<std::uint32_t>>();
  return f;
}

// The class, its constructor and pickling.
py::class_<Frame> frame_class(py::module_& m) {
  return py::class_<Frame>(m, "Frame", R"doc(
One RGB-D capture as a point cloud: organized (an image grid, H x W) or not (N points).

Frame(xyz, rgb=None)
  xyz: (N, 3) or (H, W, 3) float array, metres in the sensor frame (sensor at the origin,
       z forward); NaN for pixels with no return. float64 is converted to float32.
  rgb: None (a colourless cloud: segmentation then runs without its colour and texture blocks)
       or uint8 0-255 of the same leading shape as xyz.
The arrays are copied once into the frame (a memcpy for C-contiguous float32 / uint8);
frame.xyz and frame.rgb are views of the frame's own storage, without a copy.
)doc")
      .def(py::init(&frame_from_numpy), py::arg("xyz"), py::arg("rgb") = py::none())
      .def(py::pickle(&frame_state, &frame_from_state));
}

// The views of the points and colours, and the labels.
void add_frame_arrays(py::class_<Frame>& c) {
  c.def_property_readonly(
       "xyz",
       [](py::object self) {
         Frame& f = self.cast<Frame&>();
         return view<float>(f.xyz, f, self);
       },
       "The points, (H, W, 3) or (N, 3) float32 metres, NaN = no return (a view, no copy).")
      .def_property_readonly(
          "rgb",
          [](py::object self) -> py::object {
            Frame& f = self.cast<Frame&>();
            if (f.rgb.empty()) return py::none();
            return view<std::uint8_t>(f.rgb, f, self);
          },
          "The colours, (H, W, 3) or (N, 3) uint8 RGB (a view, no copy); None without colour.")
      .def_property_readonly(
          "label",
          [](const Frame& f) -> py::object {
            if (f.label.empty()) return py::none();
            return to_numpy(std::vector<std::uint32_t>(f.label), point_shape(f));
          },
          "The file's per-point label field (read_point_cloud's label_field), or None.");
}

// The grid's shape and the counts.
void add_frame_shape(py::class_<Frame>& c) {
  c.def_property_readonly(
       "width", [](const Frame& f) { return f.width; },
       "Image columns; the number of points when unorganized.")
      .def_property_readonly(
          "height", [](const Frame& f) { return f.height; }, "Image rows; 1 when unorganized.")
      .def_property_readonly("organized", &Frame::organized, "Whether the points form an image.")
      .def_property_readonly(
          "coloured", [](const Frame& f) { return !f.rgb.empty(); },
          "Whether the frame has colours.")
      .def_property_readonly(
          "colored", [](const Frame& f) { return !f.rgb.empty(); }, "The same as coloured.")
      .def_property_readonly(
          "shape", [](const Frame& f) { return py::tuple(py::cast(point_shape(f))); },
          "(H, W) when organized, else (N,): the shape of per-point results.")
      .def_property_readonly("valid_count", &Frame::valid_count, "Points with finite coordinates.")
      .def("__len__", &Frame::size)
      .def("__repr__", [](const Frame& f) {
        return "<proxseg.Frame " + std::to_string(f.width) + "x" + std::to_string(f.height) +
               (f.organized() ? " organized" : " unorganized") + ", " +
               std::to_string(f.valid_count()) + " valid points" +
               (f.rgb.empty() ? ", no colour" : "") + ">";
      });
}

void bind_frame_io(py::module_& m) {
  m.def(
      "read_point_cloud",
      [](const std::string& path, const std::string& label_field) {
        return without_gil([&] {
          if (lower_extension(path) == ".pcd") return read_pcd(path, label_field);
          if (lower_extension(path) == ".ply") return read_ply(path, label_field);
          return read_point_cloud(path);
        });
      },
      py::arg("path"), py::arg("label_field") = "label",
      "Reads a .pcd (ascii, binary, binary_compressed; organized or not) or .ply point cloud.\n"
      "label_field: the integer PCD field or PLY vertex property kept as Frame.label (e.g. "
      "'instance').");
  m.def(
      "read_rgbd",
      [](const std::string& colour, const std::string& depth, const std::string& meta,
         const std::string& intrinsics) {
        return without_gil([&] {
          if (meta.empty() == intrinsics.empty())
            throw InputError("read_rgbd: give exactly one of meta= or intrinsics=");
          const Intrinsics k = meta.empty() ? read_intrinsics(intrinsics) : read_ycb_meta(meta);
          return read_rgbd(colour, depth, k);
        });
      },
      py::arg("color"), py::arg("depth"), py::kw_only(), py::arg("meta") = "",
      py::arg("intrinsics") = "");
  m.def(
      "_write_point_cloud",
      [](const std::string& path, const Frame& frame, const py::dict& fields, bool compressed,
         bool keep_invalid) {
        std::vector<PointField> extra;
        for (const auto& [name, values] : fields) {
          const auto a =
              py::array_t<std::uint32_t, py::array::c_style | py::array::forcecast>::ensure(
                  as_array(values, "fields"));
          if (!a || static_cast<std::size_t>(a.size()) != frame.size())
            throw InputError("fields[" + std::string(py::str(name)) +
                             "]: expected one value per point (" + std::to_string(frame.size()) +
                             ")");
          extra.push_back({py::str(name), {a.data(), a.data() + a.size()}});
        }
        without_gil([&] {
          if (lower_extension(path) == ".ply")
            write_ply(path, frame, extra, keep_invalid ? PlyPoints::kAll : PlyPoints::kValid);
          else
            write_pcd(path, frame, extra,
                      compressed ? PcdData::kBinaryCompressed : PcdData::kBinary);
        });
      },
      py::arg("path"), py::arg("frame"), py::arg("fields"), py::arg("compressed"),
      py::arg("keep_invalid"));
  m.def("_from_rgbd", &frame_from_rgbd, py::arg("color"), py::arg("depth"), py::arg("K"),
        py::arg("depth_scale"));
}

}  // namespace

void bind_frame(py::module_& m) {
  py::class_<Frame> c = frame_class(m);
  add_frame_arrays(c);
  add_frame_shape(c);
  bind_frame_io(m);
}

}  // namespace proxseg::python
