// libFuzzer harness: the RGB-D readers. One input packs four files (fuzz_util.hpp kPart):
// a JSON (intrinsics or YCB-Video meta), a colour image, a 16-bit depth image and an 8-bit
// label image. They go through read_intrinsics / read_ycb_meta + read_rgbd, and through
// read_ycb_frame (meta, colour, depth, label of one YCB-Video frame).
#include <proxseg/eval/ycb_frames.hpp>
#include <proxseg/io/cloud_io.hpp>

#include "fuzz_util.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto part = fuzz::split(data, size, 4);
  const std::string json = fuzz::write("f-meta.json", part[0]);
  const std::string colour = fuzz::write("f-color.png", part[1]);
  const std::string depth = fuzz::write("f-depth.png", part[2]);
  fuzz::write("f-label.png", part[3]);
  for (const bool meta : {false, true}) {
    proxseg::Intrinsics k;
    if (!fuzz::answers("intrinsics", [&] {
          k = meta ? proxseg::read_ycb_meta(json) : proxseg::read_intrinsics(json);
        }))
      continue;
    fuzz::answers("read_rgbd", [&] {
      const proxseg::Frame f = proxseg::read_rgbd(colour, depth, k);
      fuzz::check_frame(f);
      if (!f.organized() && f.height != 1) std::abort();
    });
  }
  const std::vector<std::string> classes = {"a", "b", "c", "d", "e", "f", "g", "h", "i", "j", "k",
                                            "l", "m", "n", "o", "p", "q", "r", "s", "t", "u"};
  fuzz::answers("read_ycb_frame", [&] {
    const proxseg::YcbFrame y = proxseg::read_ycb_frame(fuzz::scratch().string(), "f", classes);
    fuzz::check_frame(y.frame);
    for (const auto& o : y.objects)
      for (const int i : o.points)
        if (i < 0 || static_cast<std::size_t>(i) >= y.frame.size()) std::abort();
  });
  return 0;
}
