// What `proxseg recognize` leaves for a user: PREFIX.pcd's per-point `object` ids against the
// YCB-Video label images and against PREFIX.json's ids, the picture's legend, two copies of one
// object with two ids, and no partial set of outputs after a failure.
#include <proxseg/core/errors.hpp>
#include <proxseg/eval/ycb_frames.hpp>
#include <proxseg/io/cloud_io.hpp>

#include "support/cli_util.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <set>

namespace fs = std::filesystem;

namespace {
using namespace cli_test;
const fs::path kTmp = fs::path(PROXSEG_TEST_TMP) / "recognize_outputs";
const std::string kFrames = kData + "/ycbv/frames";

CliRun run(const std::string& args) {
  return run_in(kTmp, args);
}

std::string test_name() {
  return ::testing::UnitTest::GetInstance()->current_test_info()->name();
}

// The three objects of the YCB-Video frames, read with the library's YCB reader (ground truth:
// their pixels with a valid depth).
proxseg::YcbFrame ycb_frame(int k) {
  char stem[16];
  std::snprintf(stem, sizeof stem, "%06d", k);
  return proxseg::read_ycb_frame(kFrames, stem, proxseg::read_lines(kData + "/ycbv/classes.txt"));
}

// A database of the frames' three models, built as the Ycb fixture of test_recognition builds
// its one (a full model per object from points.xyz), here through `proxseg db add --xyz`.
// One per test: ctest runs the tests of this file in parallel processes.
fs::path ycb_database() {
  const fs::path db = kTmp / ("db-" + test_name());
  fs::remove_all(db);
  for (const char* name : {"009_gelatin_box", "025_mug", "061_foam_brick"}) {
    const CliRun r = run("db add " + db.string() + " --name " + name + " --xyz " + kData +
                         "/ycbv/models/" + name + "/points.xyz");
    EXPECT_EQ(r.code, 0) << r.err;
  }
  return db;
}

std::string rgbd_args(int k) {
  char base[64];
  std::snprintf(base, sizeof base, "/%06d", k);
  const std::string b = kFrames + base;
  return "--color " + b + "-color.png --depth " + b + "-depth.png --meta " + b + "-meta.json";
}

// Ascending indices of the points that carry `id`.
std::vector<int> points_with(const std::vector<std::uint32_t>& labels, std::uint32_t id) {
  std::vector<int> out;
  for (std::size_t i = 0; i < labels.size(); ++i)
    if (labels[i] == id) out.push_back(static_cast<int>(i));
  return out;
}

double iou(const std::vector<int>& a, const std::vector<int>& b) {
  std::vector<int> both;
  std::set_intersection(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(both));
  const std::size_t either = a.size() + b.size() - both.size();
  return either ? double(both.size()) / either : 0.0;
}

// Top row of a 10x10 block of exactly `rgb` in x >= x0 of the picture, or -1.
int find_swatch(const cv::Mat& bgr, int x0, const nlohmann::json& rgb) {
  const cv::Vec3b c(rgb[2].get<int>(), rgb[1].get<int>(), rgb[0].get<int>());
  for (int y = 0; y + 10 <= bgr.rows; ++y)
    for (int x = x0; x + 10 <= bgr.cols; ++x) {
      if (bgr.at<cv::Vec3b>(y, x) != c) continue;
      bool block = true;
      for (int dy = 0; dy < 10 && block; ++dy)
        for (int dx = 0; dx < 10 && block; ++dx) block = bgr.at<cv::Vec3b>(y + dy, x + dx) == c;
      if (block) return y;
    }
  return -1;
}

// Runs `recognize` on a scene and checks what the three outputs say about each other:
// PREFIX.pcd is the input frame with field `object`; its ids are exactly PREFIX.json's, each on
// the number of points the report gives; the picture is the scene plus a legend in which every
// candidate has a swatch of its colour, in report order, and its colour outlines its points.
// Returns the report and the PCD's `object` field.
struct Outputs {
  nlohmann::json report;
  std::vector<std::uint32_t> object;
};
Outputs recognize_and_check(const std::string& input_args, const proxseg::Frame& input,
                            const fs::path& db, const fs::path& prefix) {
  for (const char* ext : {".pcd", ".png", ".json"}) fs::remove(prefix.string() + ext);
  const CliRun r = run("recognize " + input_args + " --db " + db.string() + " -o " +
                       prefix.string() + " --json");
  EXPECT_EQ(r.code, 0) << r.err;
  if (r.code != 0) return {};
  Outputs out;
  out.report = nlohmann::json::parse(r.out);
  EXPECT_EQ(out.report, nlohmann::json::parse(slurp(prefix.string() + ".json")));
  const std::string stem = prefix.filename().string();
  EXPECT_EQ(out.report["labels"]["file"], stem + ".pcd");
  EXPECT_EQ(out.report["labels"]["field"], "object");
  EXPECT_EQ(out.report["labels"]["none"], 0);

  // The input frame, point for point, organized like it.
  const proxseg::Frame pcd = proxseg::read_pcd(prefix.string() + ".pcd", "object");
  EXPECT_EQ(pcd.width, input.width);
  EXPECT_EQ(pcd.height, input.height);
  EXPECT_EQ(pcd.size(), input.size());
  if (pcd.size() != input.size() || pcd.label.size() != pcd.size()) {
    ADD_FAILURE() << "PREFIX.pcd has no field `object` for every point";
    return out;
  }
  std::size_t differ = 0, labelled_invalid = 0;
  for (std::size_t i = 0; i < pcd.size(); ++i) {
    differ += pcd.valid(i) != input.valid(i) || pcd.rgb[i] != input.rgb[i] ||
              (input.valid(i) && pcd.xyz[i] != input.xyz[i]);
    labelled_invalid += pcd.label[i] != 0 && !input.valid(i);
  }
  EXPECT_EQ(differ, 0u) << "points of PREFIX.pcd that are not the input's";
  EXPECT_EQ(labelled_invalid, 0u) << "invalid points with an object id";
  out.object = pcd.label;

  // The ids of the PCD are the report's, each on as many points as the report says.
  std::map<std::uint32_t, std::size_t> in_pcd;
  for (std::uint32_t id : pcd.label)
    if (id) ++in_pcd[id];
  std::map<std::uint32_t, std::size_t> in_report;
  std::set<std::vector<int>> colours;
  for (const auto& c : out.report["candidates"]) {
    EXPECT_TRUE(in_report.emplace(c["id"].get<std::uint32_t>(), c["points"]).second)
        << "id " << c["id"] << " twice in the report";
    colours.insert(c["colour"].get<std::vector<int>>());
  }
  EXPECT_EQ(in_pcd, in_report);
  EXPECT_EQ(colours.size(), in_report.size()) << "two objects share a colour";

  // The picture: the scene and the legend to its right.
  const cv::Mat png = cv::imread(prefix.string() + ".png");
  const auto& pic = out.report["picture"];
  EXPECT_EQ(pic["file"], stem + ".png");
  EXPECT_EQ(png.cols, pic["width"].get<int>());
  EXPECT_EQ(png.rows, pic["height"].get<int>());
  const int scene_w = pic["scene"]["width"], scene_h = pic["scene"]["height"];
  if (input.height > 1) {
    EXPECT_EQ(scene_w, input.width);
    EXPECT_EQ(scene_h, input.height);
  }
  EXPECT_GE(png.cols, scene_w + 200) << "no legend area";
  EXPECT_GE(png.rows, scene_h);
  int last_row = -1;
  for (const auto& c : out.report["candidates"]) {
    const int row = find_swatch(png, scene_w, c["colour"]);
    EXPECT_GE(row, 0) << "no legend entry for id " << c["id"];
    // One column here: the entries go down in report (id) order.
    EXPECT_GT(row, last_row) << "legend entry of id " << c["id"] << " out of order";
    last_row = row;
    if (input.height <= 1) continue;
    // The object's outline is drawn in the legend's colour.
    const cv::Vec3b bgr(c["colour"][2].get<int>(), c["colour"][1].get<int>(),
                        c["colour"][0].get<int>());
    std::size_t outlined = 0;
    for (int i : points_with(pcd.label, c["id"].get<std::uint32_t>()))
      outlined += png.at<cv::Vec3b>(i / input.width, i % input.width) == bgr;
    EXPECT_GE(outlined, 10u) << "id " << c["id"] << " not drawn in its legend colour";
  }
  return out;
}

// The object the report names `name` with the best score: what a user would take as "the" X.
const nlohmann::json* best_named(const nlohmann::json& report, const std::string& name) {
  const nlohmann::json* best = nullptr;
  for (const auto& c : report["candidates"])
    if (c["name"] == name && (!best || c["score"].get<double>() > (*best)["score"].get<double>()))
      best = &c;
  return best;
}

// The YCB-Video frames: for each of the three objects, the points that PREFIX.pcd gives the id of
// the object the report names X cover the label image's pixels of class X (those with a depth)
// with IoU >= 0.5. Frames 1, 5 and 10: the first, middle and last of the video.
TEST(RecognizeOutputs, ObjectIdsCoverTheYcbLabelImage) {
  const fs::path db = ycb_database();
  for (int k : {1, 5, 10}) {
    SCOPED_TRACE("frame " + std::to_string(k));
    const proxseg::YcbFrame y = ycb_frame(k);
    ASSERT_EQ(y.objects.size(), 3u);
    const Outputs out =
        recognize_and_check(rgbd_args(k), y.frame, db, kTmp / ("ycb" + std::to_string(k)));
    ASSERT_FALSE(out.object.empty());
    for (const proxseg::ObjectTruth& truth : y.objects) {
      const nlohmann::json* named = best_named(out.report, truth.name);
      ASSERT_TRUE(named) << "no object named " << truth.name;
      const std::uint32_t id = (*named)["id"];
      const double overlap = iou(points_with(out.object, id), truth.points);
      std::printf("frame %d %-16s id %2u IoU %.3f\n", k, truth.name.c_str(), id, overlap);
      EXPECT_GE(overlap, 0.5) << truth.name << " (id " << id << ")";
    }
  }
}

// Frame 1 with a second gelatin box: the box's points moved along the desk to the empty space
// left of it (the desk plane fitted to its pixels there), splatted with a depth test. Returns the
// frame and, ascending, the pixels of the original box and those of the copy.
struct TwoBoxes {
  proxseg::Frame frame;
  std::vector<int> original, copy;
};
TwoBoxes with_a_second_gelatin_box(const proxseg::YcbFrame& y) {
  const proxseg::ObjectTruth* box = nullptr;
  for (const auto& o : y.objects)
    if (o.name == "009_gelatin_box") box = &o;
  if (!box) throw std::runtime_error("no gelatin box in the frame");
  const proxseg::Frame& f = y.frame;
  const proxseg::Intrinsics& k = y.intrinsics;
  const auto ray = [&](double u, double v) {
    return Eigen::Vector3d((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1).normalized();
  };
  // The desk's normal n from the valid background pixels of u 20..180, v 150..250.
  std::vector<Eigen::Vector3d> desk;
  for (int v = 150; v < 250; ++v)
    for (int u = 20; u < 180; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * f.width + u;
      if (f.valid(i)) desk.push_back(f.xyz[i].cast<double>());
    }
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : desk) mean += p;
  mean /= desk.size();
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& p : desk) cov += (p - mean) * (p - mean).transpose();
  Eigen::Vector3d n = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors().col(0);
  if (n.dot(mean) > 0) n = -n;  // towards the camera
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (int i : box->points) centre += f.xyz[i].cast<double>();
  centre /= box->points.size();
  // The copy's centre: on the ray of pixel (100, 205), as high above the desk as the box's.
  const Eigen::Vector3d r = ray(100, 205);
  const double lambda = n.dot(centre) / n.dot(r);  // n.(lambda r) = n.centre: the same height
  const Eigen::Vector3f shift = (lambda * r - centre).cast<float>();

  TwoBoxes out{f, box->points, {}};
  std::vector<char> is_copy(f.size(), 0);
  for (int i : box->points) {
    const Eigen::Vector3f q = f.xyz[i] + shift;
    const int u = static_cast<int>(std::lround(k.fx * q.x() / q.z() + k.cx));
    const int v = static_cast<int>(std::lround(k.fy * q.y() / q.z() + k.cy));
    // 2x2 splats: the copy has no holes of desk where its pixels spread a little.
    for (int dv = 0; dv < 2; ++dv)
      for (int du = 0; du < 2; ++du) {
        if (u + du < 0 || v + dv < 0 || u + du >= f.width || v + dv >= f.height) continue;
        const std::size_t j = static_cast<std::size_t>(v + dv) * f.width + u + du;
        if (out.frame.valid(j) && out.frame.xyz[j].z() <= q.z()) continue;
        out.frame.xyz[j] = q;
        out.frame.rgb[j] = f.rgb[i];
        is_copy[j] = 1;
      }
  }
  for (std::size_t j = 0; j < f.size(); ++j)
    if (is_copy[j]) out.copy.push_back(static_cast<int>(j));
  return out;
}

// Two copies of one model in a scene: two objects named after it, each with its own id in the
// report and in PREFIX.pcd, each on its own copy.
TEST(RecognizeOutputs, TwoCopiesOfOneObjectHaveTwoIds) {
  const fs::path db = ycb_database();
  const TwoBoxes scene = with_a_second_gelatin_box(ycb_frame(1));
  ASSERT_GT(scene.copy.size(), scene.original.size() / 2);
  ASSERT_EQ(iou(scene.copy, scene.original), 0.0) << "the copy landed on the box";
  const fs::path input = kTmp / "two_boxes_scene.pcd";
  fs::create_directories(kTmp);
  proxseg::write_pcd(input.string(), scene.frame, {});
  const Outputs out = recognize_and_check(input.string(), scene.frame, db, kTmp / "two_boxes");
  ASSERT_FALSE(out.object.empty());
  std::set<std::uint32_t> ids;
  using Box = std::pair<const char*, const std::vector<int>*>;
  for (const auto& [what, truth] : {Box{"original", &scene.original}, Box{"copy", &scene.copy}}) {
    // The object of the report that overlaps this box most.
    const nlohmann::json* best = nullptr;
    double best_iou = 0;
    for (const auto& c : out.report["candidates"]) {
      const double overlap = iou(points_with(out.object, c["id"].get<std::uint32_t>()), *truth);
      if (overlap > best_iou) best_iou = overlap, best = &c;
    }
    ASSERT_TRUE(best) << what;
    std::printf("two boxes: %-8s -> id %d %s IoU %.3f\n", what, (*best)["id"].get<int>(),
                (*best)["name"].get<std::string>().c_str(), best_iou);
    EXPECT_GE(best_iou, 0.5) << what;
    EXPECT_EQ((*best)["name"], "009_gelatin_box") << what;
    ids.insert((*best)["id"].get<std::uint32_t>());
  }
  EXPECT_EQ(ids.size(), 2u) << "both boxes under one id";
}

// Outputs that cannot be written: the command fails with the file named, and the set of
// PREFIX.pcd, .png and .json is never left half new (no file of the failed run, no temporary
// file, the files of an earlier run untouched).
TEST(RecognizeOutputs, FailedWritesLeaveNoPartialOutputs) {
  const fs::path db = ycb_database();
  const fs::path dir = kTmp / "bad-outputs";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const auto listing = [&] {
    std::set<std::string> names;
    for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
    return names;
  };
  const std::string scene = rgbd_args(1) + " --db " + db.string();

  // A prefix under a regular file: refused before the work, nothing written.
  std::ofstream(dir / "a-file") << "x";
  expect_input_error(run("recognize " + scene + " -o " + (dir / "a-file" / "out").string()),
                     "a-file", dir / "a-file" / "out");

  // PREFIX.png in the way (a directory) while an earlier run's PREFIX.pcd and PREFIX.json are
  // there: exit 1 naming it; the earlier files are as they were, nothing else appears.
  const fs::path prefix = dir / "out";
  fs::create_directories(prefix.string() + ".png");
  std::ofstream(prefix.string() + ".pcd") << "earlier pcd";
  std::ofstream(prefix.string() + ".json") << "earlier json";
  const auto before = listing();
  CliRun r = run("recognize " + scene + " -o " + prefix.string());
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("out.png"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(prefix.string() + ".pcd"), "earlier pcd");
  EXPECT_EQ(slurp(prefix.string() + ".json"), "earlier json");
  EXPECT_EQ(listing(), before);

  // The same with no earlier files: none of the three appears.
  fs::remove(prefix.string() + ".pcd");
  fs::remove(prefix.string() + ".json");
  r = run("recognize " + scene + " -o " + prefix.string());
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_FALSE(fs::exists(prefix.string() + ".pcd"));
  EXPECT_FALSE(fs::exists(prefix.string() + ".json"));
  EXPECT_TRUE(fs::is_empty(prefix.string() + ".png"));

  // An output that would overwrite the input (PREFIX.pcd is the scene): a usage error, the scene
  // unchanged, no other output.
  const fs::path input = dir / "scene.pcd";
  const proxseg::YcbFrame y = ycb_frame(1);
  proxseg::write_pcd(input.string(), y.frame, {});
  const std::string bytes = slurp(input);
  r = run("recognize " + input.string() + " --db " + db.string() + " -o " +
          (dir / "scene").string());
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("scene.pcd"), std::string::npos) << r.err;
  EXPECT_TRUE(slurp(input) == bytes);
  EXPECT_FALSE(fs::exists(dir / "scene.json"));
  EXPECT_FALSE(fs::exists(dir / "scene.png"));
}

// The library's all-or-none writer on its own: a directory in the way of the last file stops
// the set before any file is touched.
TEST(RecognizeOutputs, WriteFilesAtomicIsAllOrNone) {
  const fs::path dir = kTmp / "atomic-set";
  fs::remove_all(dir);
  fs::create_directories(dir / "c.txt");
  std::ofstream(dir / "a.txt") << "old a";
  try {
    proxseg::write_files_atomic({{(dir / "a.txt").string(), "new a"},
                                 {(dir / "b.txt").string(), "new b"},
                                 {(dir / "c.txt").string(), "new c"}});
    ADD_FAILURE() << "expected an InputError";
  } catch (const proxseg::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("c.txt"), std::string::npos) << e.what();
  }
  EXPECT_EQ(slurp(dir / "a.txt"), "old a");
  EXPECT_FALSE(fs::exists(dir / "b.txt"));
  std::size_t entries = std::distance(fs::directory_iterator(dir), {});
  EXPECT_EQ(entries, 2u);  // a.txt and the directory c.txt: no temporary file
  // Without the obstacle every file is written.
  fs::remove(dir / "c.txt");
  proxseg::write_files_atomic({{(dir / "a.txt").string(), "new a"},
                               {(dir / "b.txt").string(), "new b"},
                               {(dir / "c.txt").string(), "new c"}});
  EXPECT_EQ(slurp(dir / "a.txt"), "new a");
  EXPECT_EQ(slurp(dir / "c.txt"), "new c");
  entries = std::distance(fs::directory_iterator(dir), {});
  EXPECT_EQ(entries, 3u);
}

}  // namespace
