// libFuzzer harness: the result `proxseg view` reads (PREFIX.json, the report, and PREFIX.pcd,
// the cloud with the fields the report names), packed as report | cloud. The report's reader
// bounds its nesting and checks every field's shape before the page indexes it (issue 54).
#include <proxseg/io/view_page.hpp>

#include "fuzz_util.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::vector<std::string_view> parts = fuzz::split(data, size, 2);
  fuzz::write("result.json", parts[0]);
  const std::string prefix = fuzz::write("result.pcd", parts[1]);
  proxseg::ViewOptions options;
  options.max_points = 5000;  // a fuzzed cloud may be large; thinning is part of the reader too
  fuzz::answers("view_page_of", [&] {
    const std::string page = proxseg::view_page_of(prefix.substr(0, prefix.size() - 4), options);
    if (page.find("</html>") == std::string::npos) std::abort();  // a page, whole
  });
  return 0;
}
