// YCB-Video frames: colour, depth, labels and the objects' poses from meta.json
// (ycb_frames.hpp).
#include <proxseg/core/errors.hpp>
#include <proxseg/eval/ycb_frames.hpp>

#include <proxseg/io/cloud_io.hpp>

#include <cctype>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

namespace proxseg {

std::vector<std::string> read_lines(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open (expected a text file)");
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) {
    while (!line.empty() && std::isspace(static_cast<unsigned char>(line.back()))) line.pop_back();
    if (!line.empty()) lines.push_back(line);
  }
  return lines;
}

YcbFrame read_ycb_frame(const std::string& dir, const std::string& stem,
                        const std::vector<std::string>& classes) {
  const std::string base = (std::filesystem::path(dir) / stem).string();
  const std::string meta_path = base + "-meta.json", label_path = base + "-label.png";
  YcbFrame y;
  y.intrinsics = read_ycb_meta(meta_path);
  y.frame = read_rgbd(base + "-color.png", base + "-depth.png", y.intrinsics);
  const std::vector<std::uint8_t> label =
      read_label_image(label_path, y.frame.width, y.frame.height);
  nlohmann::json meta;
  {
    std::ifstream in(meta_path);
    meta = nlohmann::json::parse(in, nullptr, false);  // read_ycb_meta has parsed it already
  }
  // cls_indexes: N ids (or [id] each); poses: 3 x 4 x N numbers.
  const auto bad = [&](const std::string& what) {
    throw InputError(meta_path + ": " + what + " (expected cls_indexes of N class ids and poses " +
                     "of 3 x 4 x N numbers)");
  };
  if (!meta.is_object() || !meta.contains("cls_indexes") || !meta.contains("poses"))
    bad("missing cls_indexes or poses");
  const auto& ids = meta.at("cls_indexes");
  const auto& poses = meta.at("poses");
  if (!ids.is_array()) bad("cls_indexes is not an array");
  const std::size_t n_objects = ids.size();
  if (!poses.is_array() || poses.size() != 3) bad("poses is not 3 rows");
  for (const auto& row : poses) {
    if (!row.is_array() || row.size() != 4) bad("a row of poses has not 4 columns");
    for (const auto& cell : row) {
      if (!cell.is_array() || cell.size() != n_objects) bad("poses has not one value per object");
      for (const auto& v : cell)
        if (!v.is_number() || !std::isfinite(v.get<double>())) bad("poses has a non-number");
    }
  }
  for (std::size_t n = 0; n < n_objects; ++n) {
    ObjectTruth o;
    const auto& id = ids[n].is_array() && ids[n].size() == 1 ? ids[n][0] : ids[n];
    if (!id.is_number_integer()) bad("cls_indexes[" + std::to_string(n) + "] is not an integer");
    const auto index = id.get<std::int64_t>();
    if (index < 1 || index > static_cast<std::int64_t>(classes.size()))
      throw InputError(meta_path + ": cls_indexes[" + std::to_string(n) +
                       "] = " + std::to_string(index) + " is not a class of classes.txt");
    o.class_index = static_cast<int>(index);
    o.name = classes[o.class_index - 1];
    o.pose.setIdentity();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) o.pose(r, c) = poses[r][c][n].get<double>();
    for (std::size_t i = 0; i < label.size(); ++i)
      if (label[i] == o.class_index && y.frame.valid(i)) o.points.push_back(static_cast<int>(i));
    y.objects.push_back(std::move(o));
  }
  y.labels = label;
  return y;
}

}  // namespace proxseg
