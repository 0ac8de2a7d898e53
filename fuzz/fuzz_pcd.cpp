// libFuzzer harness: the PCD reader (ascii, binary, binary_compressed; label fields).
#include <proxseg/io/cloud_io.hpp>

#include "fuzz_util.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = fuzz::write("input.pcd", {reinterpret_cast<const char*>(data), size});
  fuzz::answers("read_pcd", [&] { fuzz::check_frame(proxseg::read_pcd(path)); });
  fuzz::answers("read_pcd(instance)",
                [&] { fuzz::check_frame(proxseg::read_pcd(path, "instance")); });
  return 0;
}
