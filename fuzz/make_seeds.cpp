// Builds the fuzzers' seed corpora from the real files in ../shared/data (never committed):
// small crops of real frames in every encoding the readers take, heads of the real files
// (truncated inputs) and a few hand-mutated headers. Usage: make_seeds DATA_DIR OUT_DIR
#include <proxseg/core/database.hpp>
#include <proxseg/core/pipeline.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/output.hpp>
#include <proxseg/recognition/database_io.hpp>

#include <proxseg/io/params.hpp>
#include "support/folder_database_v1.hpp"
#include "support/frame_window.hpp"

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "fuzz_util.hpp"

namespace fs = std::filesystem;

namespace {

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) throw std::runtime_error(p.string() + ": cannot read");
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void put(const fs::path& dir, const std::string& name, const std::string& bytes) {
  fs::create_directories(dir);
  std::ofstream(dir / name, std::ios::binary).write(bytes.data(), bytes.size());
}

std::string pack(const std::vector<std::string>& parts) {
  std::string out;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (i) out += fuzz::kPart;
    out += parts[i];
  }
  return out;
}

// The frame as a PCD in mOSD's layout (label x y z rgba), in the given encoding. binary_compressed
// uses LZF literal runs only (valid LZF); the real files seed the back-references.
std::string pcd(const proxseg::Frame& f, const std::string& encoding, bool rgb_float = false) {
  const bool lab = !f.label.empty();
  std::ostringstream h;
  h << "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS " << (lab ? "label " : "")
    << "x y z " << (rgb_float ? "rgb" : "rgba") << "\nSIZE " << (lab ? "4 " : "")
    << "4 4 4 4\nTYPE " << (lab ? "U " : "") << "F F F " << (rgb_float ? "F" : "U") << "\nCOUNT "
    << (lab ? "1 " : "") << "1 1 1 1\nWIDTH " << f.width << "\nHEIGHT " << f.height
    << "\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " << f.size() << "\nDATA " << encoding << "\n";
  const std::size_t n = f.size();
  auto colour = [&](std::size_t i) {
    return (std::uint32_t{255} << 24) | (std::uint32_t{f.rgb[i][0]} << 16) |
           (std::uint32_t{f.rgb[i][1]} << 8) | f.rgb[i][2];
  };
  if (encoding == "ascii") {
    for (std::size_t i = 0; i < n; ++i) {
      if (lab) h << f.label[i] << " ";
      h << f.xyz[i].x() << " " << f.xyz[i].y() << " " << f.xyz[i].z() << " ";
      if (rgb_float) {
        float v;
        const std::uint32_t c = colour(i) & 0xffffff;
        std::memcpy(&v, &c, 4);
        h << v << "\n";
      } else {
        h << colour(i) << "\n";
      }
    }
    return h.str();
  }
  // Field-major (binary_compressed) or point-major (binary) 4-byte values.
  std::vector<std::vector<std::uint32_t>> fields;
  if (lab) fields.push_back(f.label);
  for (int k = 0; k < 3; ++k) {
    std::vector<std::uint32_t> v(n);
    for (std::size_t i = 0; i < n; ++i) std::memcpy(&v[i], &f.xyz[i][k], 4);
    fields.push_back(v);
  }
  std::vector<std::uint32_t> c(n);
  for (std::size_t i = 0; i < n; ++i) c[i] = rgb_float ? colour(i) & 0xffffff : colour(i);
  fields.push_back(c);
  std::string raw;
  if (encoding == "binary") {
    for (std::size_t i = 0; i < n; ++i)
      for (const auto& fv : fields) raw.append(reinterpret_cast<const char*>(&fv[i]), 4);
    return h.str() + raw;
  }
  for (const auto& fv : fields) raw.append(reinterpret_cast<const char*>(fv.data()), 4 * n);
  std::string lzf;
  for (std::size_t at = 0; at < raw.size(); at += 32) {
    const std::size_t len = std::min<std::size_t>(32, raw.size() - at);
    lzf += static_cast<char>(len - 1);
    lzf += raw.substr(at, len);
  }
  const std::uint32_t sizes[2] = {static_cast<std::uint32_t>(lzf.size()),
                                  static_cast<std::uint32_t>(raw.size())};
  return h.str() + std::string(reinterpret_cast<const char*>(sizes), 8) + lzf;
}

std::string replace(std::string s, const std::string& from, const std::string& to) {
  const auto at = s.find(from);
  if (at != std::string::npos) s.replace(at, from.size(), to);
  return s;
}

void pcd_seeds(const fs::path& data, const fs::path& out) {
  for (const char* f : {"pcl/milk.pcd"}) put(out, "milk.pcd", slurp(data / f));
  int n = 0;
  for (const char* f :
       {"pcl/milk_cartoon_all_small_clorox.pcd", "pcl/region_growing_rgb_tutorial.pcd",
        "pcl/table_scene_mug_stereo_textured.pcd", "mosd/learn/learn0.pcd"}) {
    const std::string bytes = slurp(data / f);
    for (std::size_t len : {512, 4096, 65536})
      put(out, "head" + std::to_string(n++) + ".pcd", bytes.substr(0, len));
  }
  const proxseg::Frame scene = proxseg::read_pcd((data / "mosd/learn/learn0.pcd").string());
  const proxseg::Frame small = proxseg::test::frame_window(scene, 200, 300, 12, 16);
  for (const char* enc : {"ascii", "binary", "binary_compressed"}) {
    const std::string e = enc;
    put(out, "crop-" + e + ".pcd", pcd(small, e));
    put(out, "crop-rgb-" + e + ".pcd", pcd(small, e, true));
    proxseg::Frame unorganized = small;
    unorganized.width = static_cast<int>(small.size());
    unorganized.height = 1;
    unorganized.label.clear();
    put(out, "crop-unorganized-" + e + ".pcd", pcd(unorganized, e));
  }
  const std::string a = pcd(small, "ascii");
  put(out, "mut-points.pcd", replace(a, "POINTS 192", "POINTS 191"));
  put(out, "mut-width.pcd", replace(a, "WIDTH 16", "WIDTH 17"));
  put(out, "mut-type.pcd", replace(a, "TYPE U F F F U", "TYPE I F F F F"));
  put(out, "mut-size.pcd", replace(a, "SIZE 4 4 4 4 4", "SIZE 2 4 4 4 8"));
  put(out, "mut-count.pcd", replace(a, "COUNT 1 1 1 1 1", "COUNT 2 1 1 1 1"));
  put(out, "mut-instance.pcd", replace(a, "FIELDS label", "FIELDS instance"));
  put(out, "header-only.pcd", a.substr(0, a.find("DATA ascii\n") + 11));
  put(out, "empty.pcd", "");
}

void ply_seeds(const fs::path& data, const fs::path& out) {
  const std::string ape = slurp(data / "lmo/models/obj_000001.ply");
  for (std::size_t len : {256, 2048, 16384})
    put(out, "ape-head" + std::to_string(len), ape.substr(0, len));
  // A small mesh cut from the real model: its header with 12 vertices and 4 faces.
  std::istringstream in(ape);
  std::string line, header;
  while (std::getline(in, line) && line != "end_header") header += line + "\n";
  header = replace(replace(header, "element vertex 5841", "element vertex 12"),
                   "element face 11678", "element face 4");
  std::string body;
  for (int i = 0; i < 12 && std::getline(in, line); ++i) body += line + "\n";
  body += "3 0 1 2\n3 3 4 5\n3 6 7 8\n3 9 10 11\n";
  put(out, "small-ascii.ply", header + "end_header\n" + body);
  // The same as binary_little_endian, and as a point cloud without faces.
  std::string bin =
      replace(header, "format ascii 1.0", "format binary_little_endian 1.0") + "end_header\n";
  std::istringstream vb(body);
  for (int i = 0; i < 12 && std::getline(vb, line); ++i) {
    std::istringstream v(line);
    float x[6];
    int c[4];
    for (float& f : x) v >> f;
    for (int& k : c) v >> k;
    bin.append(reinterpret_cast<const char*>(x), sizeof x);
    for (int k : c) bin += static_cast<char>(k);
  }
  for (int t = 0; t < 4; ++t) {
    bin += static_cast<char>(3);
    for (int k = 0; k < 3; ++k) {
      const std::int32_t idx = 3 * t + k;
      bin.append(reinterpret_cast<const char*>(&idx), 4);
    }
  }
  put(out, "small-binary.ply", bin);
  put(out, "cloud-ascii.ply",
      replace(header, "element face 4\nproperty list uchar int vertex_indices\n", "") +
          "end_header\n" + body.substr(0, body.find("3 0 1 2")));
  // A cloud as write_ply writes it, with a label property and a NaN point (read_ply's label).
  proxseg::Frame cloud;
  cloud.width = 4;
  cloud.height = 1;
  for (int i = 0; i < 4; ++i) {
    cloud.xyz.emplace_back(0.1f * i, 0.0f, i == 2 ? std::nanf("") : 1.0f);
    cloud.rgb.push_back({static_cast<std::uint8_t>(60 * i), 10, 200});
  }
  put(out, "labelled.ply",
      proxseg::ply_bytes(cloud, {{"label", {0, 1, 2, 3}}}, proxseg::PlyPoints::kAll));
  const std::string xyz = slurp(data / "ycbv/models/003_cracker_box/points.xyz");
  put(out, "points.xyz", xyz.substr(0, xyz.find('\n', 2000) + 1));
}

std::string png(const cv::Mat& m, const char* ext = ".png") {
  std::vector<unsigned char> buf;
  cv::imencode(ext, m, buf);
  return {buf.begin(), buf.end()};
}

void rgbd_seeds(const fs::path& data, const fs::path& out) {
  const fs::path f = data / "ycbv/frames";
  const std::string meta = slurp(f / "000001-meta.json");
  const cv::Rect roi(300, 220, 24, 18);
  const cv::Mat colour = cv::imread((f / "000001-color.png").string(), cv::IMREAD_UNCHANGED)(roi);
  const cv::Mat depth = cv::imread((f / "000001-depth.png").string(), cv::IMREAD_UNCHANGED)(roi);
  const cv::Mat label = cv::imread((f / "000001-label.png").string(), cv::IMREAD_UNCHANGED)(roi);
  // The crop's principal point moves with it, so that the points are where the frame has them.
  const std::string intr =
      R"({"fx": 1066.778, "fy": 1067.487, "cx": 12.9869, "cy": 21.3109, "depth_scale": 10000})";
  put(out, "ycb-meta", pack({meta, png(colour), png(depth), png(label)}));
  put(out, "ycb-intrinsics", pack({intr, png(colour), png(depth), png(label)}));
  put(out, "ycb-jpeg", pack({intr, png(colour, ".jpg"), png(depth), png(label)}));
  put(out, "ycb-8bit-depth", pack({intr, png(colour), png(label), png(label)}));
  put(out, "ycb-size-mismatch",
      pack({intr, png(colour(cv::Rect(0, 0, 12, 9))), png(depth), png(label)}));
  put(out, "ycb-zero-depth",
      pack({intr, png(colour), png(cv::Mat::zeros(depth.size(), CV_16U)), png(label)}));
}

void config_seeds(const fs::path& data, const fs::path& out) {
  put(out, "default.json", proxseg::to_json(proxseg::preset("default")).dump(2));
  put(out, "paper.json", proxseg::to_json(proxseg::preset("paper")).dump());
  put(out, "recognize.json",
      nlohmann::json{{"segmentation", proxseg::to_json(proxseg::preset("default"))},
                     {"recognition", proxseg::to_json(proxseg::RecognitionParams{})}}
          .dump(1));
  put(out, "partial.json", R"({"mrf": {"pairwise_weight": 0.3}, "voxels": {"voxel_size": 0.01}})");
  put(out, "meta.json", slurp(data / "ycbv/frames/000001-meta.json"));
  put(out, "intrinsics.json",
      R"({"fx": 525, "fy": 525, "cx": 319.5, "cy": 239.5, "depth_scale": 1000})");
}

// A one-view database (the ape at 12 mm voxels): the database file, and the same view as a
// version-1 folder (the upgrade's input).
void database_seeds(const fs::path& data, const fs::path& out) {
  const fs::path dir =
      fs::temp_directory_path() / ("proxseg-seed-db-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  proxseg::DescriptorParams d;
  d.voxel_size = 0.012;
  d.fpfh_radii = {0.03};
  const proxseg::Mesh ape =
      proxseg::read_mesh((data / "lmo/models/obj_000001.ply").string(), 0.001);
  proxseg::Frame points;
  for (std::size_t i = 0; i < ape.vertices.size(); ++i) {
    points.xyz.push_back(ape.vertices[i]);
    points.rgb.push_back(ape.colours[i]);
  }
  points.width = static_cast<int>(points.xyz.size());
  points.height = 1;
  std::vector<proxseg::ModelView> views;
  {
    proxseg::Database db = proxseg::open_database((dir / "file").string(), d);
    proxseg::add_view(db, "obj", points, Eigen::Vector3d(0, 0, 0.5), "seed");
    views = db.views;
  }
  const std::string file = slurp(dir / "file" / proxseg::kDatabaseFile);
  put(out / "database", "db.sqlite", file);
  put(out / "database", "db-truncated.sqlite", file.substr(0, file.size() / 2));
  std::string flipped = file;
  flipped[flipped.size() - 100] ^= 0x20;
  put(out / "database", "db-flipped.sqlite", flipped);
  proxseg::test::write_folder_database((dir / "v1").string(), views, d);
  const std::string index = slurp(dir / "v1/index.json");
  const std::string view = slurp(dir / "v1/views/obj-000.pcd"),
                    cache = slurp(dir / "v1/views/obj-000.fpfh");
  put(out / "folder_database", "db", pack({index, view, cache}));
  put(out / "folder_database", "db-truncated-cache",
      pack({index, view, cache.substr(0, cache.size() / 2)}));
  put(out / "folder_database", "db-no-view", pack({index, "", cache}));
  fs::remove_all(dir);
}

// Results as `proxseg view` reads them, packed as report | cloud: a segmentation of a crop of a
// real frame, the same as a recognition (object field, a named object with a pose), a report
// without its cloud and one cut short.
void view_seeds(const fs::path& data, const fs::path& out) {
  const proxseg::Frame scene = proxseg::read_pcd((data / "mosd/learn/learn0.pcd").string());
  const proxseg::Frame crop = proxseg::test::frame_window(scene, 160, 220, 100, 140);
  const fs::path dir =
      fs::temp_directory_path() / ("proxseg-seed-view-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string prefix = (dir / "r").string();
  proxseg::OutputSet outputs;
  outputs.png = false;
  const proxseg::SegmentParams params = proxseg::preset("default");
  nlohmann::json report =
      proxseg::write_segmentation(prefix, crop, params, proxseg::segment(crop, params), outputs);
  const std::string cloud = slurp(prefix + ".pcd");
  fs::remove_all(dir);
  put(out, "segmentation", pack({report.dump(), cloud}));
  put(out, "report-only", pack({report.dump(1), ""}));
  put(out, "report-cut", pack({report.dump().substr(0, 300), cloud}));
  nlohmann::json recognition = report;
  recognition["database"] = "models.db";
  const std::uint32_t id =
      report["candidates"].empty() ? 1u : report["candidates"][0]["id"].get<std::uint32_t>();
  recognition["candidates"] = nlohmann::json::array(
      {{{"id", id},
        {"name", "tin"},
        {"colour", {1, 2, 3}},
        {"score", 0.5},
        {"pose", {{1, 0, 0, 0.1}, {0, 1, 0, 0}, {0, 0, 1, 0.5}, {0, 0, 0, 1}}}}});
  put(out, "recognition", pack({recognition.dump(), replace(cloud, "instance\n", "object\n")}));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: make_seeds DATA_DIR OUT_DIR\n";
    return 2;
  }
  try {
    const fs::path data = argv[1], out = argv[2];
    pcd_seeds(data, out / "pcd");
    ply_seeds(data, out / "ply");
    rgbd_seeds(data, out / "rgbd");
    config_seeds(data, out / "config");
    database_seeds(data, out);
    view_seeds(data, out / "view");
  } catch (const std::exception& e) {
    std::cerr << "make_seeds: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
