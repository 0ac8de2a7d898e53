// libFuzzer harness: the model readers: PLY point cloud (with and without a label property) and
// mesh (our PLY reader, ply_io.hpp) and the YCB-Video points.xyz text format.
#include <proxseg/io/cloud_io.hpp>

#include <cmath>

#include "fuzz_util.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const std::string ply = fuzz::write("input.ply", bytes);
  fuzz::answers("read_ply", [&] { fuzz::check_frame(proxseg::read_ply(ply)); });
  fuzz::answers("read_ply label",  // check_frame: one label per point or none
                [&] { fuzz::check_frame(proxseg::read_ply(ply, "label")); });
  fuzz::answers("read_mesh", [&] {
    const proxseg::Mesh m = proxseg::read_mesh(ply, 0.001);
    for (const auto& t : m.triangles)
      for (int k = 0; k < 3; ++k)
        if (t[k] < 0 || t[k] >= static_cast<int>(m.vertices.size())) std::abort();
    if (m.colours.size() != m.vertices.size()) std::abort();
  });
  const std::string xyz = fuzz::write("input.xyz", bytes);
  fuzz::answers("read_xyz", [&] {
    for (const auto& p : proxseg::read_xyz(xyz))
      if (!p.allFinite()) std::abort();
  });
  return 0;
}
