// libFuzzer harness: the JSON configs: `segment --config`, `recognize --config`, and
// the camera files (intrinsics JSON, YCB-Video meta).
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/params.hpp>

#include "fuzz_util.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = fuzz::write("config.json", {reinterpret_cast<const char*>(data), size});
  fuzz::answers("read_params", [&] {
    const proxseg::SegmentParams p = proxseg::read_params(path, proxseg::preset("default"));
    proxseg::validate(p);
    // What was read must echo back and read again to the same parameters.
    if (proxseg::to_json(proxseg::params_from_json(proxseg::to_json(p))) != proxseg::to_json(p))
      std::abort();
  });
  fuzz::answers("read_recognize_params", [&] {
    const auto [seg, rec] = proxseg::read_recognize_params(path, proxseg::preset("paper"), {});
    proxseg::validate(seg);
    proxseg::validate(rec);
  });
  fuzz::answers("read_intrinsics", [&] { proxseg::read_intrinsics(path); });
  fuzz::answers("read_ycb_meta", [&] { proxseg::read_ycb_meta(path); });
  return 0;
}
