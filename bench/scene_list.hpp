// The labelled scenes a segmentation benchmark runs on (seg_bench, seg_cv): a folder's scene
// files, or N of them spread evenly.
#pragma once
#include <proxseg/eval/scene_names.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace proxseg::bench {

// One set of scenes: "mOSD learn" or "generated", its files.
struct SceneSet {
  std::string name;
  std::vector<std::filesystem::path> files;
};

// Every scene of the folder, or N of them spread evenly so every category is represented.
inline std::vector<std::filesystem::path> scenes_of(const std::string& dir, int limit) {
  std::vector<std::filesystem::path> files = scene_files(dir);
  if (limit > 0 && static_cast<int>(files.size()) > limit) {
    std::vector<std::filesystem::path> spread;
    for (int i = 0; i < limit; ++i) spread.push_back(files[i * files.size() / limit]);
    files = spread;
  }
  return files;
}

}  // namespace proxseg::bench
