// Writes a version-1 folder model database (index.json, a PCD and a feature cache per view), as
// proxseg 0.x did: the input of `proxseg db upgrade`, for its tests and fuzz seeds. The format is
// in docs/database.md, "Version 1".
#pragma once
#include <proxseg/core/database.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/params.hpp>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace proxseg::test {

template <class T>
inline void put(std::string& out, const T& v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof v);
}

// Writes views as proxseg 0.x did (docs/database.md, "Version 1").
inline void write_folder_database(const std::string& dir, const std::vector<ModelView>& views,
                                  const DescriptorParams& d) {
  std::filesystem::create_directories(dir + "/views");
  nlohmann::json objects = nlohmann::json::array();
  std::map<std::string, int> at;
  for (const ModelView& v : views) {
    const Cloud& c = v.cloud();
    const std::string stem = "views/" + v.name;
    Frame f;
    for (const auto& p : c.points) f.xyz.push_back(p.cast<float>());
    f.rgb = c.colours.empty() ? std::vector<Rgb>(c.size(), Rgb{128, 128, 128}) : c.colours;
    f.width = static_cast<int>(c.size());
    f.height = 1;
    write_pcd(dir + "/" + stem + ".pcd", f, {});
    std::string cache("PXSGFPF1", 8);
    put(cache, static_cast<std::uint32_t>(c.size()));
    put(cache, static_cast<std::uint32_t>(c.features.rows()));
    for (int k = 0; k < 3; ++k) put(cache, c.viewpoint[k]);
    std::uint64_t h = 1469598103934665603ull;  // FNV-1a over the float coordinates
    for (const auto& p : c.points)
      for (int k = 0; k < 3; ++k) {
        const float x = static_cast<float>(p[k]);
        unsigned char b[4];
        std::memcpy(b, &x, 4);
        for (unsigned char ch : b) h = (h ^ ch) * 1099511628211ull;
      }
    put(cache, h);
    for (const auto& n : c.normals)
      for (int k = 0; k < 3; ++k) put(cache, static_cast<float>(n[k]));
    for (Eigen::Index j = 0; j < c.features.cols(); ++j)
      for (Eigen::Index i = 0; i < c.features.rows(); ++i)
        put(cache, static_cast<float>(c.features(i, j)));
    std::ofstream(dir + "/" + stem + ".fpfh", std::ios::binary) << cache;
    if (!at.count(v.object)) {
      at[v.object] = static_cast<int>(objects.size());
      objects.push_back({{"name", v.object}, {"views", nlohmann::json::array()}});
    }
    const auto& vp = c.viewpoint;
    objects[at[v.object]]["views"].push_back(
        {{"file", stem + ".pcd"},
         {"features", stem + ".fpfh"},
         {"points", c.size()},
         {"viewpoint",
          vp.allFinite() ? nlohmann::json{vp.x(), vp.y(), vp.z()} : nlohmann::json(nullptr)},
         {"colour", !c.colours.empty()},
         {"source", v.source}});
  }
  std::ofstream(dir + "/index.json") << nlohmann::json{
      {"format", "proxseg-model-database"},
      {"version", 1},
      {"units", "metres"},
      {"descriptor", to_json(d)},
      {"objects", objects}}.dump(2);
}

}  // namespace proxseg::test
