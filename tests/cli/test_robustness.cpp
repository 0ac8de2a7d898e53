// The bad inputs of docs/robustness.md, one test per row, through the CLI as a user meets them:
// a result or a one-line error naming the file or field (exit 1), never a crash, a hang or a
// partial output. Also determinism (same outputs at 1 and 2 threads, run after run) and an
// interrupted batch.
#include <proxseg/io/batch.hpp>
#include <proxseg/io/cloud_io.hpp>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <limits>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <thread>

#include "support/cli_util.hpp"

namespace {
using namespace cli_test;
const fs::path kTmp = fs::path(PROXSEG_TEST_TMP) / "robustness";
CliRun run(const std::string& args) {
  return run_in(kTmp, args);
}

const std::string kHeader =
    "VERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\n"
    "VIEWPOINT 0 0 0 1 0 0 0\n";

// A PCD file under kTmp from header lines after kHeader (WIDTH, HEIGHT, POINTS, DATA) and data.
std::string pcd_file(const std::string& name, const std::string& text) {
  fs::create_directories(kTmp);
  std::ofstream(kTmp / name, std::ios::binary) << text;
  return (kTmp / name).string();
}

CliRun segment(const std::string& input, const fs::path& prefix) {
  fs::remove(prefix.string() + ".pcd");
  fs::remove(prefix.string() + ".png");
  fs::remove(prefix.string() + ".json");
  return run("segment " + input + " -o " + prefix.string());
}

// A 64x48 crop of a real YCB-Video frame, with the intrinsics moved with the crop.
struct RgbdCrop {
  cv::Mat colour, depth;
  std::string intrinsics;
};
RgbdCrop ycb_crop() {
  const std::string base = kData + "/ycbv/frames/000001";
  const cv::Rect roi(280, 200, 64, 48);
  RgbdCrop c;
  c.colour = cv::imread(base + "-color.png", cv::IMREAD_UNCHANGED);
  c.depth = cv::imread(base + "-depth.png", cv::IMREAD_UNCHANGED);
  if (c.colour.empty() || c.depth.empty()) ADD_FAILURE() << "missing real data: " << base;
  c.colour = c.colour(roi).clone();
  c.depth = c.depth(roi).clone();
  c.intrinsics = (kTmp / "crop-intrinsics.json").string();
  fs::create_directories(kTmp);
  std::ofstream(c.intrinsics)
      << R"({"fx": 1066.778, "fy": 1067.487, "cx": 32.9869, "cy": 41.3109, "depth_scale": 10000})";
  return c;
}

CliRun segment_rgbd(const RgbdCrop& c, const cv::Mat& colour, const cv::Mat& depth,
                    const std::string& tag, const fs::path& prefix) {
  const std::string cp = (kTmp / (tag + "-color.png")).string(),
                    dp = (kTmp / (tag + "-depth.png")).string();
  cv::imwrite(cp, colour);
  cv::imwrite(dp, depth);
  return run("segment --color " + cp + " --depth " + dp + " --intrinsics " + c.intrinsics + " -o " +
             prefix.string());
}

// A one-view database of the milk carton (the PCL tutorial model).
fs::path milk_database(const std::string& name) {
  const fs::path db = kTmp / name;
  fs::remove_all(db);
  const CliRun r = run("db add " + db.string() + " --name milk " + kData + "/pcl/milk.pcd");
  EXPECT_EQ(r.code, 0) << r.err;
  return db;
}

// The report without what may differ between runs: measured times and the echoed thread count.
nlohmann::json without_times(nlohmann::json j) {
  if (j.is_object()) {
    nlohmann::json out = nlohmann::json::object();
    for (auto& [key, value] : j.items()) {
      const bool timing = key == "ms" || key == "threads" ||
                          (key.size() > 3 && key.compare(key.size() - 3, 3, "_ms") == 0);
      if (!timing) out[key] = without_times(value);
    }
    return out;
  }
  if (j.is_array())
    for (auto& v : j) v = without_times(v);
  return j;
}
}  // namespace

TEST(Robustness, EmptyFile) {
  const fs::path o = kTmp / "empty-out";
  for (const std::string name : {"empty.pcd", "empty.ply"})
    expect_input_error(segment(pcd_file(name, ""), o), name, o);
  const RgbdCrop c = ycb_crop();
  std::ofstream(kTmp / "empty-color.png");
  cv::imwrite((kTmp / "ok-depth.png").string(), c.depth);
  expect_input_error(
      run("segment --color " + (kTmp / "empty-color.png").string() + " --depth " +
          (kTmp / "ok-depth.png").string() + " --intrinsics " + c.intrinsics + " -o " + o.string()),
      "empty-color.png", o);
}

TEST(Robustness, HeaderOnly) {
  const fs::path o = kTmp / "header-out";
  for (const std::string data : {"ascii", "binary", "binary_compressed"}) {
    const std::string name = "header-" + data + ".pcd";
    const CliRun r =
        segment(pcd_file(name, kHeader + "WIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA " + data + "\n"), o);
    expect_input_error(r, name, o);
  }
}

TEST(Robustness, AllNanCloud) {
  const fs::path o = kTmp / "nan-out";
  const CliRun r = segment(pcd_file("nan.pcd", kHeader + "WIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n"
                                                         "nan nan nan 0\nnan nan nan 0\n"),
                           o);
  expect_input_error(r, "nan.pcd", o);
  EXPECT_NE(r.err.find("no valid points"), std::string::npos) << r.err;
}

TEST(Robustness, SinglePoint) {
  const fs::path o = kTmp / "single-out";
  const CliRun r = segment(
      pcd_file("single.pcd", kHeader + "WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n0.1 0.2 1 255\n"),
      o);
  ASSERT_EQ(r.code, 0) << r.err;  // a result: one voxel, one region, no candidate object
  const auto report = nlohmann::json::parse(slurp(o.string() + ".json"));
  EXPECT_EQ(report["voxels"]["count"], 1);
  EXPECT_EQ(report["selection"]["candidates"], 0);
  EXPECT_EQ(proxseg::read_pcd(o.string() + ".pcd").size(), 1u);
}

TEST(Robustness, HugeOrInfiniteCoordinates) {
  // A real scene with a few points pushed to infinity or beyond any voxel index.
  proxseg::Frame f = proxseg::read_pcd(learn0());
  const float inf = std::numeric_limits<float>::infinity();
  const std::vector<std::pair<std::size_t, Eigen::Vector3f>> far = {{1000, {inf, 0, 1}},
                                                                    {2000, {0, -inf, 1}},
                                                                    {150000, {1e30f, 1e30f, 1e30f}},
                                                                    {160000, {-3e38f, 0, 1}},
                                                                    {170000, {0, 0, 3e38f}}};
  for (const auto& [i, p] : far) f.xyz[i] = p;
  f.label.clear();
  proxseg::write_pcd((kTmp / "far.pcd").string(), f, {});
  const fs::path o = kTmp / "far-out";
  const CliRun r = segment((kTmp / "far.pcd").string(), o);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("3 points too far out to voxelise"), std::string::npos) << r.err;
  const auto report = nlohmann::json::parse(slurp(o.string() + ".json"));
  EXPECT_EQ(report["input"]["out_of_range_points"], 3);
  EXPECT_GE(report["selection"]["candidates"].get<int>(), 1);
  const proxseg::Frame out = proxseg::read_pcd(o.string() + ".pcd");
  for (const auto& [i, p] : far) EXPECT_EQ(out.label[i], 0u) << i;  // unlabelled, not garbage
}

TEST(Robustness, WidthTimesHeightIsNotPoints) {
  const fs::path o = kTmp / "wh-out";
  const CliRun r = segment(pcd_file("wh.pcd", kHeader + "WIDTH 2\nHEIGHT 2\nPOINTS 3\nDATA ascii\n"
                                                        "0 0 1 0\n0 0 1 0\n0 0 1 0\n"),
                           o);
  expect_input_error(r, "wh.pcd", o);
  EXPECT_NE(r.err.find("WIDTH*HEIGHT"), std::string::npos) << r.err;
}

TEST(Robustness, MissingOrWrongTypedFields) {
  const fs::path o = kTmp / "fields-out";
  const std::string tail = "WIDTH 1\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 1\nDATA ascii\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"no-z.pcd", "FIELDS x y rgb\nSIZE 4 4 4\nTYPE F F U\nCOUNT 1 1 1\n" + tail + "0 0 1\n"},
      {"integer-x.pcd",
       "FIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE U F F U\nCOUNT 1 1 1 1\n" + tail + "0 0 1 0\n"},
      {"short-rgb.pcd",
       "FIELDS x y z rgb\nSIZE 4 4 4 2\nTYPE F F F U\nCOUNT 1 1 1 1\n" + tail + "0 0 1 0\n"},
      {"text-value.pcd",
       "FIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\n" + tail + "0 zero 1 0\n"},
      {"float-label.pcd",
       "FIELDS x y z rgb label\nSIZE 4 4 4 4 4\nTYPE F F F U F\nCOUNT 1 1 1 1 1\n" + tail +
           "0 0 1 0 1.5\n"}};
  for (const auto& [name, text] : cases)
    expect_input_error(segment(pcd_file(name, text), o), name, o);
}

// No colour field is no error: an XYZ-only cloud, segmented without the colour and texture blocks.
TEST(Robustness, XyzOnlyCloud) {
  const fs::path o = kTmp / "xyz-out";
  const std::string input =
      pcd_file("no-colour.pcd",
               "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 1\n"
               "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA ascii\n0 0 1\n0.01 0 1\n");
  const CliRun r = segment(input, o);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("no-colour.pcd has no colour: the colour block is off"), std::string::npos)
      << r.err;
  const nlohmann::json j = nlohmann::json::parse(slurp(o.string() + ".json"));
  EXPECT_FALSE(j["input"]["colour"].get<bool>());
  EXPECT_FALSE(j["features"]["colour"].get<bool>());
  EXPECT_EQ(j["features"]["note"], "the input has no colour: the colour block is off");
  EXPECT_TRUE(fs::exists(o.string() + ".png"));
  EXPECT_TRUE(fs::exists(o.string() + ".pcd"));
}

TEST(Robustness, ColourAndDepthOfDifferentSizes) {
  const RgbdCrop c = ycb_crop();
  const fs::path o = kTmp / "sizes-out";
  const CliRun r = segment_rgbd(c, c.colour(cv::Rect(0, 0, 32, 24)), c.depth, "sizes", o);
  expect_input_error(r, "sizes-depth.png", o);
  EXPECT_NE(r.err.find("expected the same size"), std::string::npos) << r.err;
}

TEST(Robustness, DepthAllZero) {
  const RgbdCrop c = ycb_crop();
  const fs::path o = kTmp / "zero-out";
  // The second run below writes these: a run before this one must not leave them behind.
  for (const char* ext : {".pcd", ".png", ".json"}) fs::remove(o.string() + ext);
  const CliRun r = segment_rgbd(c, c.colour, cv::Mat::zeros(c.depth.size(), CV_16UC1), "zero", o);
  expect_input_error(r, "zero-depth.png", o);
  EXPECT_NE(r.err.find("no valid depth"), std::string::npos) << r.err;
  // The crop itself is fine: the same files with the real depth give a result.
  EXPECT_EQ(segment_rgbd(c, c.colour, c.depth, "crop", o).code, 0);
}

TEST(Robustness, SixteenVersusEightBitImages) {
  const RgbdCrop c = ycb_crop();
  const fs::path o = kTmp / "bits-out";
  cv::Mat depth8, colour16;
  c.depth.convertTo(depth8, CV_8U, 1.0 / 256);
  c.colour.convertTo(colour16, CV_16U, 257);
  CliRun r = segment_rgbd(c, c.colour, depth8, "depth8", o);
  expect_input_error(r, "depth8-depth.png", o);
  EXPECT_NE(r.err.find("expected 16-bit"), std::string::npos) << r.err;
  r = segment_rgbd(c, colour16, c.depth, "colour16", o);
  expect_input_error(r, "colour16-color.png", o);
  EXPECT_NE(r.err.find("8-bit"), std::string::npos) << r.err;
}

// A database file that is missing, cut short, not a database, or a version-1 folder: exit 1, the
// file named, nothing written. (Damaged records inside a whole file:
// tests/recognition/test_database.cpp.)
TEST(Robustness, DatabaseFileMissingTruncatedOrOld) {
  const fs::path o = kTmp / "db-missing-out";
  const std::string object = "recognize --object " + kData + "/pcl/milk.pcd --db ";
  const fs::path db = milk_database("db-missing");
  fs::remove(db / "database.sqlite");
  expect_input_error(run(object + db.string() + " -o " + o.string()), "database.sqlite", o);
  const fs::path db2 = milk_database("db-truncated");
  fs::resize_file(db2 / "database.sqlite", fs::file_size(db2 / "database.sqlite") / 2);
  expect_input_error(run(object + db2.string() + " -o " + o.string()), "database.sqlite", o);
  const fs::path db3 = milk_database("db-junk");
  std::ofstream(db3 / "database.sqlite", std::ios::trunc)
      << "SQLite format 3" << std::string(9000, 'x');
  expect_input_error(run(object + db3.string() + " -o " + o.string()), "database.sqlite", o);
  const fs::path db4 = kTmp / "db-v1";
  fs::remove_all(db4);
  fs::create_directories(db4);
  std::ofstream(db4 / "index.json") << R"({"format": "proxseg-model-database", "version": 1})";
  expect_input_error(run(object + db4.string() + " -o " + o.string()), "proxseg db upgrade", o);
}

TEST(Robustness, ConfigWithUnknownKeysOrWrongTypes) {
  const fs::path o = kTmp / "config-out";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {R"({"mrf": {"pairwise_wieght": 0.1}})", "pairwise_wieght"},
      {R"({"voxels": {"voxel_size": "big"}})", "voxels.voxel_size"},
      {R"({"colour": {}})", "colour"},
      {R"([1, 2])", "bad-config.json"},
      {R"({"clustering": {"alpha": 1e999}})", "bad-config.json"},
      {R"({"mrf": {"pairwise_weight": 0.1})", "bad-config.json"}};
  for (const auto& [text, named] : cases) {
    std::ofstream(kTmp / "bad-config.json") << text;
    expect_input_error(run("segment " + learn0() + " --config " +
                           (kTmp / "bad-config.json").string() + " -o " + o.string()),
                       named, o);
  }
  std::ofstream(kTmp / "rec.json") << R"({"recognition": {"ransac_iters": 5}})";
  const fs::path db = milk_database("db-config");
  expect_input_error(run("recognize --object " + kData + "/pcl/milk.pcd --db " + db.string() +
                         " --config " + (kTmp / "rec.json").string() + " -o " + o.string()),
                     "ransac_iters", o);
}

TEST(Robustness, OutputDirectoryNotWritable) {
  fs::create_directories(kTmp);
  std::ofstream(kTmp / "a-file") << "x";
  const fs::path o = kTmp / "a-file" / "out";
  CliRun r = run("segment " + learn0() + " -o " + o.string());
  expect_input_error(r, "a-file", o);
  r = run("segment --batch " + kData + "/mosd/learn -o " + o.string());
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("a-file"), std::string::npos) << r.err;
  // A folder that exists but takes no new file, whoever asks (root too): /proc/self. The input
  // is broken and the database missing: an error naming the folder, not them, shows that the
  // folder was checked before anything was read.
  const std::string broken = pcd_file("broken-input.pcd", "not a PCD\n");
  r = run("segment " + broken + " -o /proc/self/out");
  expect_input_error(r, "/proc/self", "/proc/self/out");
  EXPECT_EQ(r.err.find("broken-input"), std::string::npos) << r.err;
  r = run("recognize " + broken + " --db " + (kTmp / "no-database").string() +
          " -o /proc/self/out");
  expect_input_error(r, "/proc/self", "/proc/self/out");
  EXPECT_EQ(r.err.find("no-database"), std::string::npos) << r.err;
  fs::remove_all(kTmp / "broken-batch");
  fs::create_directories(kTmp / "broken-batch");
  fs::copy_file(broken, kTmp / "broken-batch" / "f.pcd");
  r = run("segment --batch " + (kTmp / "broken-batch").string() + " -o /proc/self");
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("/proc/self"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("f.pcd"), std::string::npos) << r.err;
  if (::geteuid() != 0) {  // root writes through permissions; /proc/self above covers it
    const fs::path ro = kTmp / "read-only";
    fs::create_directories(ro);
    fs::permissions(ro, fs::perms::owner_read | fs::perms::owner_exec);
    r = run("segment " + broken + " -o " + (ro / "out").string());
    expect_input_error(r, "read-only", ro / "out");
    EXPECT_EQ(r.err.find("broken-input"), std::string::npos) << r.err;
    EXPECT_TRUE(fs::is_empty(ro));
    fs::permissions(ro, fs::perms::owner_all);
  }
}

TEST(Robustness, InterruptDuringABatchLeavesWholeFilesAndASummary) {
  const fs::path in = kTmp / "batch-in", out = kTmp / "batch-out";
  fs::remove_all(in);
  fs::remove_all(out);
  fs::create_directories(in);
  // Eight frames: with one frame per core side by side, several are under way at once.
  for (int i = 0; i < 8; ++i)
    fs::create_symlink(kData + "/mosd/learn/learn" + std::to_string(i) + ".pcd",
                       in / ("learn" + std::to_string(i) + ".pcd"));
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    const std::string log = (kTmp / "batch.log").string();
    std::freopen(log.c_str(), "w", stdout);
    std::freopen(log.c_str(), "a", stderr);
    ::execl(kCli.c_str(), kCli.c_str(), "segment", "--batch", in.c_str(), "-o", out.c_str(),
            static_cast<char*>(nullptr));
    std::_Exit(127);
  }
  // Interrupt once the first scene is written, in the middle of the next ones.
  const auto start = std::chrono::steady_clock::now();
  while (!fs::exists(out / "learn0.json") &&
         std::chrono::steady_clock::now() - start < std::chrono::minutes(5))
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  ::kill(pid, SIGINT);
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status)) << slurp(kTmp / "batch.log");
  EXPECT_EQ(WEXITSTATUS(status), 130) << slurp(kTmp / "batch.log");
  const auto summary = nlohmann::json::parse(slurp(out / "summary.json"));
  EXPECT_TRUE(summary["interrupted"].get<bool>());
  EXPECT_EQ(summary["frames_total"], 8);
  const int done = summary["frames_done"].get<int>();
  EXPECT_GE(done, 1);
  EXPECT_LT(done, 8);
  // Exactly the outputs of the frames the summary lists, each whole; no temporary file left.
  std::set<std::string> expected = {"summary.json", "summary.jsonl"};
  const auto rows = proxseg::frame_rows(out.string());
  EXPECT_EQ(rows.size(), static_cast<std::size_t>(done));
  for (const auto& s : rows) {
    const std::string stem = s["frame"].get<std::string>();
    for (const char* ext : {".pcd", ".png", ".json"}) expected.insert(stem + ext);
    EXPECT_EQ(proxseg::read_pcd((out / (stem + ".pcd")).string(), "instance").size(), 307200u);
    EXPECT_FALSE(cv::imread((out / (stem + ".png")).string()).empty());
    EXPECT_NO_THROW(nlohmann::json::parse(slurp(out / (stem + ".json"))));
  }
  std::set<std::string> found;
  for (const auto& e : fs::directory_iterator(out)) found.insert(e.path().filename().string());
  EXPECT_EQ(found, expected);
}

TEST(Robustness, SegmentIsByteIdenticalAtOneAndTwoThreadsAndAcrossRuns) {
  std::vector<std::array<std::string, 3>> outputs;
  for (const char* threads : {"1", "2", "1", "2"}) {
    const fs::path o =
        kTmp / (std::string("det-") + threads + "-" + std::to_string(outputs.size()));
    const CliRun r = run("segment " + learn0() + " --threads " + threads + " -o " + o.string());
    ASSERT_EQ(r.code, 0) << r.err;
    outputs.push_back({slurp(o.string() + ".pcd"), slurp(o.string() + ".png"),
                       without_times(nlohmann::json::parse(slurp(o.string() + ".json"))).dump()});
  }
  for (std::size_t i = 1; i < outputs.size(); ++i) {
    EXPECT_TRUE(outputs[i][0] == outputs[0][0]) << "labelled PCD differs, run " << i;
    EXPECT_TRUE(outputs[i][1] == outputs[0][1]) << "picture differs, run " << i;
    EXPECT_EQ(outputs[i][2], outputs[0][2]) << "report differs, run " << i;
  }
}

TEST(Robustness, RecognizeIsByteIdenticalAtOneAndTwoThreadsAndAcrossRuns) {
  const fs::path db = milk_database("db-det");
  std::vector<std::array<std::string, 3>> outputs;
  for (const char* threads : {"1", "2", "1", "2"}) {
    // One folder per run, the same file names: the report names its PCD and picture.
    const fs::path o =
        kTmp / (std::string("rec-") + threads + "-" + std::to_string(outputs.size())) / "scene";
    const CliRun r = run("recognize " + kData + "/pcl/milk_cartoon_all_small_clorox.pcd --db " +
                         db.string() + " --threads " + threads + " -o " + o.string());
    ASSERT_EQ(r.code, 0) << r.err;
    outputs.push_back({slurp(o.string() + ".pcd"), slurp(o.string() + ".png"),
                       without_times(nlohmann::json::parse(slurp(o.string() + ".json"))).dump()});
  }
  for (std::size_t i = 1; i < outputs.size(); ++i) {
    EXPECT_TRUE(outputs[i][0] == outputs[0][0]) << "object ids differ, run " << i;
    EXPECT_TRUE(outputs[i][1] == outputs[0][1]) << "picture differs, run " << i;
    EXPECT_EQ(outputs[i][2], outputs[0][2]) << "report differs, run " << i;
  }
}
