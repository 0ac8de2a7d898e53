// The names of evaluation scenes: category, number and fold from a file name, and a folder's
// scene files in natural order (scene_names.hpp).
#include <proxseg/core/errors.hpp>
#include <proxseg/eval/scene_names.hpp>

#include <proxseg/core/frame.hpp>

#include <algorithm>
#include <cctype>
#include <system_error>
#include <utility>

namespace proxseg {

namespace {

// The number of an mOSD learn scene's file name, "learn<digits>" with an optional ".<extension>"
// (letters, digits, _); -1 for any other name.
int learn_number(const std::string& name) {
  auto word = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
  auto digit = [](char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; };
  if (name.rfind("learn", 0) != 0) return -1;
  std::size_t end = 5;
  while (end < name.size() && digit(name[end])) ++end;
  if (end == 5) return -1;
  if (end < name.size()) {
    if (name[end] != '.' || end + 1 == name.size()) return -1;
    for (std::size_t k = end + 1; k < name.size(); ++k)
      if (!word(name[k])) return -1;
  }
  return std::stoi(name.substr(5, end - 5));
}

}  // namespace

std::string scene_category(const std::string& scene_name) {
  const std::string name = std::filesystem::path(scene_name).filename().string();
  for (const char* kind : {"clutter", "piles", "occlusion"})  // generated: clutter_kind()
    if (name.rfind(kind, 0) == 0) return kind;
  const int i = learn_number(name);
  if (i < 0) return "other";
  return i <= 16   ? "boxes"
         : i <= 24 ? "stacked"
         : i <= 32 ? "occluded"
         : i <= 44 ? "cylindric"
                   : "other";
}

long scene_number(const std::string& scene_name) {
  const std::string stem = std::filesystem::path(scene_name).stem().string();
  std::size_t i = stem.size();
  while (i > 0 && std::isdigit(static_cast<unsigned char>(stem[i - 1]))) --i;
  if (i == stem.size()) return -1;
  return std::stol(stem.substr(i, 18));  // at most 18 digits: no overflow
}

std::string scene_fold(const std::string& scene_name) {
  const std::string category = scene_category(scene_name);
  if (category != "clutter" && category != "piles" && category != "occlusion") return category;
  const long n = scene_number(scene_name);
  return category + (n >= 0 && n % 2 == 1 ? "-odd" : "-even");
}

std::vector<std::filesystem::path> scene_files(const std::string& dir,
                                               const std::vector<std::string>& extensions) {
  std::string wanted;
  for (const auto& e : extensions) wanted += (wanted.empty() ? "" : " or ") + e;
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec))
    throw InputError(dir + ": not a directory (expected a folder of " + wanted + " scenes)");
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    std::string ext = e.path().extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (e.is_regular_file() &&
        std::find(extensions.begin(), extensions.end(), ext) != extensions.end())
      files.push_back(e.path());
  }
  // Natural order: the trailing number of the stem compares as a number.
  auto key = [](const std::filesystem::path& p) {
    const std::string stem = p.stem().string();
    std::size_t i = stem.size();
    while (i > 0 && std::isdigit(static_cast<unsigned char>(stem[i - 1]))) --i;
    const long n = i < stem.size() ? std::stol(stem.substr(i, 9)) : -1;
    return std::make_pair(stem.substr(0, i), n);
  };
  std::sort(files.begin(), files.end(), [&](const auto& a, const auto& b) {
    return std::make_pair(key(a), a.string()) < std::make_pair(key(b), b.string());
  });
  if (files.empty()) throw InputError(dir + ": no " + wanted + " files (expected scenes)");
  return files;
}

}  // namespace proxseg
