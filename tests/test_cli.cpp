// The proxseg command line: outputs, exit codes (0 ok, 1 bad input, 2 usage), error messages.
#include <proxseg/io.hpp>

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

namespace fs = std::filesystem;

namespace {
const std::string kData = PROXSEG_DATA_DIR;
const std::string kCli = PROXSEG_CLI;
const fs::path kTmp = fs::path(PROXSEG_TEST_TMP) / "cli";

struct CliRun {
  int code;
  std::string out, err;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

CliRun run(const std::string& args) {
  fs::create_directories(kTmp);
  // ctest runs test cases in parallel processes: one pair of capture files per test case.
  const std::string name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
  const std::string out = (kTmp / (name + ".stdout")).string(),
                    err = (kTmp / (name + ".stderr")).string();
  const int status = std::system((kCli + " " + args + " >" + out + " 2>" + err).c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(out), slurp(err)};
}

std::string learn0() {
  const std::string p = kData + "/mosd/learn/learn0.pcd";
  if (!fs::exists(p)) ADD_FAILURE() << "missing real data: " << p;
  return p;
}

// Exit 1, one line on stderr naming `name`, and none of PREFIX.{pcd,png,json} written.
void expect_input_error(const CliRun& r, const std::string& name, const fs::path& prefix) {
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find(name), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  for (const char* ext : {".pcd", ".png", ".json"})
    EXPECT_FALSE(fs::exists(prefix.string() + ext)) << ext;
}
}  // namespace

TEST(Cli, HelpOnEveryCommand) {
  for (const char* cmd : {"--help", "segment --help", "synth --help"}) {
    const CliRun r = run(cmd);
    EXPECT_EQ(r.code, 0) << cmd;
    EXPECT_NE(r.out.find("Usage"), std::string::npos) << cmd;
  }
}

TEST(Cli, UsageErrorsExitTwo) {
  const fs::path o = kTmp / "usage";
  for (const std::string& args :
       {std::string(""), std::string("segment"), std::string("frobnicate"), "segment " + learn0(),
        "segment " + learn0() + " -o " + o.string() + " --no-such-flag",
        "segment " + learn0() + " --color c.png --depth d.png -o " + o.string(),
        "segment --color c.png -o " + o.string(),
        "segment --color c.png --depth d.png -o " + o.string(),
        "segment " + learn0() + " -o " + o.string() + " --mrf-method magic"}) {
    EXPECT_EQ(run(args).code, 2) << args;
  }
}

TEST(Cli, SegmentsARealSceneIntoThreeFiles) {
  const fs::path o = kTmp / "l0";
  const CliRun r = run("segment " + learn0() + " -o " + o.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const proxseg::Frame f = proxseg::read_pcd(o.string() + ".pcd");
  EXPECT_EQ(f.width, 640);
  EXPECT_EQ(f.height, 480);
  ASSERT_EQ(f.label.size(), f.size());
  for (std::size_t i = 0; i < f.size(); ++i) ASSERT_EQ(f.label[i] == 0, !f.valid(i)) << i;
  const nlohmann::json j = nlohmann::json::parse(slurp(o.string() + ".json"));
  EXPECT_EQ(j["parameters"]["voxels"]["voxel_size"], 0.02);
  EXPECT_EQ(j["parameters"]["mrf"]["method"], "swap");
  for (const char* stage : {"voxels", "features", "initial_clustering", "kmeans", "mrf", "total"})
    EXPECT_GE(j["times_ms"][stage].get<double>(), 0.0) << stage;
  EXPECT_GE(j["k"].get<int>(), 2);
  EXPECT_LE(j["mrf"]["energy_after"].get<double>(), j["mrf"]["energy_before"].get<double>());
  EXPECT_GT(j["voxels"]["count"].get<int>(), 2000);
  std::size_t labelled = 0;
  for (const auto& l : j["labels"]) labelled += l["points"].get<std::size_t>();
  EXPECT_EQ(labelled, f.valid_count());
  const cv::Mat png = cv::imread(o.string() + ".png");
  EXPECT_EQ(png.cols, 640);
  EXPECT_EQ(png.rows, 480);
}

TEST(Cli, JsonOnStdoutConfigAndFlags) {
  const fs::path o = kTmp / "cfg";
  fs::create_directories(kTmp);
  std::ofstream(kTmp / "params.json")
      << R"({"voxels": {"voxel_size": 0.03}, "mrf": {"pairwise_weight": 0.2}})";
  const CliRun r = run("segment " + learn0() + " -o " + o.string() + " --config " +
                       (kTmp / "params.json").string() + " --wc 0.1 --no-mrf --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["parameters"]["voxels"]["voxel_size"], 0.03);   // from the config
  EXPECT_EQ(j["parameters"]["mrf"]["pairwise_weight"], 0.1);  // the flag wins
  EXPECT_EQ(j["parameters"]["mrf"]["enabled"], false);
  EXPECT_EQ(j["mrf"]["energy_after"], j["mrf"]["energy_before"]);
}

TEST(Cli, RgbdPairWithMeta) {
  const std::string base = kData + "/ycbv/frames/000001";
  const fs::path o = kTmp / "y1";
  const CliRun r = run("segment --color " + base + "-color.png --depth " + base +
                       "-depth.png --meta " + base + "-meta.json -o " + o.string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(proxseg::read_pcd(o.string() + ".pcd").width, 640);
  EXPECT_TRUE(fs::exists(o.string() + ".png"));
}

TEST(Cli, BadInputsExitOneWithTheFileNamedAndNoOutput) {
  fs::create_directories(kTmp);
  const fs::path o = kTmp / "bad";
  expect_input_error(run("segment " + (kTmp / "missing.pcd").string() + " -o " + o.string()),
                     "missing.pcd", o);
  std::ofstream(kTmp / "cloud.xyz") << "0 0 1\n";
  expect_input_error(run("segment " + (kTmp / "cloud.xyz").string() + " -o " + o.string()),
                     "cloud.xyz", o);
  std::ofstream(kTmp / "nocolour.pcd")
      << "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
         "WIDTH 1\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 1\nDATA ascii\n0 0 1\n";
  expect_input_error(run("segment " + (kTmp / "nocolour.pcd").string() + " -o " + o.string()),
                     "nocolour.pcd", o);
  std::ofstream(kTmp / "nan.pcd")
      << "VERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\n"
         "WIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA ascii\n"
         "nan nan nan 0\nnan nan nan 0\n";
  expect_input_error(run("segment " + (kTmp / "nan.pcd").string() + " -o " + o.string()), "nan.pcd",
                     o);
  // A real file cut in half.
  const std::string whole = slurp(learn0());
  std::ofstream(kTmp / "truncated.pcd", std::ios::binary) << whole.substr(0, whole.size() / 2);
  expect_input_error(run("segment " + (kTmp / "truncated.pcd").string() + " -o " + o.string()),
                     "truncated.pcd", o);
  // Colour and depth of different sizes.
  const std::string base = kData + "/ycbv/frames/000001";
  cv::Mat depth = cv::imread(base + "-depth.png", cv::IMREAD_UNCHANGED), small;
  cv::resize(depth, small, cv::Size(320, 240), 0, 0, cv::INTER_NEAREST);
  cv::imwrite((kTmp / "small-depth.png").string(), small);
  expect_input_error(
      run("segment --color " + base + "-color.png --depth " + (kTmp / "small-depth.png").string() +
          " --meta " + base + "-meta.json -o " + o.string()),
      "small-depth.png", o);
  // Configs: unknown key, wrong type.
  std::ofstream(kTmp / "unknown.json") << R"({"mrf": {"pairwise_wieght": 0.1}})";
  expect_input_error(run("segment " + learn0() + " --config " + (kTmp / "unknown.json").string() +
                         " -o " + o.string()),
                     "pairwise_wieght", o);
  std::ofstream(kTmp / "wrongtype.json") << R"({"voxels": {"voxel_size": "big"}})";
  expect_input_error(run("segment " + learn0() + " --config " + (kTmp / "wrongtype.json").string() +
                         " -o " + o.string()),
                     "voxels.voxel_size", o);
  expect_input_error(run("segment " + learn0() + " --voxel-size -1 -o " + o.string()), "voxel_size",
                     o);
}

TEST(Cli, OutputCannotOverwriteTheInput) {
  fs::create_directories(kTmp);
  fs::copy_file(learn0(), kTmp / "scene.pcd", fs::copy_options::overwrite_existing);
  const auto before = fs::file_size(kTmp / "scene.pcd");
  EXPECT_EQ(
      run("segment " + (kTmp / "scene.pcd").string() + " -o " + (kTmp / "scene").string()).code, 2);
  EXPECT_EQ(fs::file_size(kTmp / "scene.pcd"), before);
}

TEST(Cli, UnwritableOutputIsAnInputErrorWithNothingLeft) {
  fs::create_directories(kTmp);
  std::ofstream(kTmp / "a-file") << "x";
  const CliRun r = run("segment " + learn0() + " -o " + (kTmp / "a-file" / "out").string());
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("a-file"), std::string::npos) << r.err;
}

TEST(Cli, ByteIdenticalOutputsAtOneAndTwoThreads) {
  const fs::path a = kTmp / "t1", b = kTmp / "t2";
  ASSERT_EQ(run("segment " + learn0() + " --threads 1 -o " + a.string()).code, 0);
  ASSERT_EQ(run("segment " + learn0() + " --threads 2 -o " + b.string()).code, 0);
  EXPECT_EQ(slurp(a.string() + ".pcd"), slurp(b.string() + ".pcd"));
  EXPECT_EQ(slurp(a.string() + ".png"), slurp(b.string() + ".png"));
}

TEST(Cli, SynthWritesAGroundTruthScene) {
  const fs::path o = kTmp / "synth.pcd";
  const CliRun r = run("synth -o " + o.string() + " --seed 3");
  ASSERT_EQ(r.code, 0) << r.err;
  const proxseg::Frame f = proxseg::read_pcd(o.string());
  EXPECT_EQ(f.width, 640);
  ASSERT_EQ(f.label.size(), f.size());
  EXPECT_EQ(*std::max_element(f.label.begin(), f.label.end()), 6u);
  EXPECT_EQ(run("synth -o " + o.string() + " --noise -1").code, 1);
}
