// libFuzzer harness: the model database file. The input is DB/database.sqlite; opening it, and
// reading every view's parts and body, must answer or throw InputError, whatever the bytes (SQLite
// reports a damaged structure; the records' checksums and sizes catch the rest).
#include <proxseg/core/database.hpp>
#include <proxseg/recognition/database_io.hpp>

#include "fuzz_util.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::error_code ec;
  std::filesystem::remove_all(fuzz::scratch() / "db", ec);
  fuzz::write("db/database.sqlite", std::string(reinterpret_cast<const char*>(data), size));
  const std::string dir = (fuzz::scratch() / "db").string();
  fuzz::answers("load_database", [&] {
    const proxseg::Database db = proxseg::load_database(dir);
    for (const auto& v : db.views) {
      fuzz::answers("part_signatures", [&] { v.part_signatures(); });
      fuzz::answers("cloud", [&] {
        const auto& c = v.cloud();
        if (c.size() != v.points || c.normals.size() != c.size() ||
            static_cast<std::size_t>(c.features.cols()) != c.size())
          std::abort();
      });
    }
    proxseg::database_info(db);
  });
  fuzz::answers("check_database", [&] { proxseg::check_database(dir); });
  return 0;
}
