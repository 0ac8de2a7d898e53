// libFuzzer harness: the version-1 folder database as `proxseg db upgrade` reads it. One input
// packs (fuzz_util.hpp kPart) the index.json, one view's PCD and its feature cache, written where
// the seed's index names them (views/obj-000.pcd, views/obj-000.fpfh); a mutated index may name
// other files.
#include <proxseg/core/database.hpp>
#include <proxseg/recognition/database_io.hpp>

#include "fuzz_util.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto part = fuzz::split(data, size, 3);
  std::error_code ec;
  std::filesystem::remove_all(fuzz::scratch() / "db", ec);
  fuzz::write("db/index.json", part[0]);
  fuzz::write("db/views/obj-000.pcd", part[1]);
  fuzz::write("db/views/obj-000.fpfh", part[2]);
  const std::string dir = (fuzz::scratch() / "db").string();
  if (!fuzz::answers("upgrade_database", [&] { proxseg::upgrade_database(dir); })) return 0;
  fuzz::answers("load_database", [&] {
    const proxseg::Database db = proxseg::load_database(dir);
    for (const auto& v : db.views) {
      const auto& c = v.cloud();
      if (c.normals.size() != c.size() || static_cast<std::size_t>(c.features.cols()) != c.size())
        std::abort();
    }
  });
  return 0;
}
