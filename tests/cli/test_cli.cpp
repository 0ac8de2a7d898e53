// The proxseg command line: outputs, exit codes (0 ok, 1 bad input, 2 usage), error messages.
#include <proxseg/core/version.hpp>
#include <proxseg/io/cloud_io.hpp>

#include "support/cli_util.hpp"

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
using namespace cli_test;
const fs::path kTmp = fs::path(PROXSEG_TEST_TMP) / "cli";
CliRun run(const std::string& args) {
  return run_in(kTmp, args);
}
}  // namespace

TEST(Cli, HelpOnEveryCommand) {
  for (const char* cmd :
       {"--help", "segment --help", "synth --help", "eval-seg --help", "db --help", "db add --help",
        "db render --help", "db info --help", "recognize --help", "summary --help"}) {
    const CliRun r = run(cmd);
    EXPECT_EQ(r.code, 0) << cmd;
    EXPECT_NE(r.out.find("Usage"), std::string::npos) << cmd;
  }
}

// The commands that need recognition run in proxseg-tools (apps/proxseg.cpp): without it beside
// the program (or in ../libexec/proxseg), they fail with a message naming what is missing, and
// segment still works.
TEST(Cli, ToolCommandsWithoutProxsegToolsFailClearly) {
  const fs::path alone = kTmp / "alone";
  fs::remove_all(alone);
  fs::create_directories(alone);
  fs::copy_file(kCli, alone / "proxseg");
  const std::string exe = (alone / "proxseg").string();
  CliRun r = run_in(kTmp, "recognize --help", exe);
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("proxseg-tools for `recognize`"), std::string::npos) << r.err;
  r = run_in(kTmp, "segment " + learn0() + " -o " + (alone / "scene").string(), exe);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(alone / "scene.pcd"));
}

TEST(Cli, VersionNamesTheReleaseAndTheCommit) {
  const CliRun r = run("--version");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out, std::string("proxseg ") + PROXSEG_VERSION + " (commit " + proxseg::git_commit() +
                       ")\n");
  EXPECT_STREQ(proxseg::version(), PROXSEG_VERSION);
  // 12 hex digits of `git describe` (with -dirty for a modified tree), or "unknown" outside git.
  const std::string commit = proxseg::git_commit();
  EXPECT_TRUE(commit == "unknown" ||
              (commit.size() >= 12 && commit.find_first_not_of("0123456789abcdef") >= 12))
      << commit;
}

TEST(Cli, UsageErrorsExitTwo) {
  const fs::path o = kTmp / "usage";
  for (const std::string& args :
       {std::string(""), std::string("segment"), std::string("frobnicate"), "segment " + learn0(),
        "segment " + learn0() + " -o " + o.string() + " --no-such-flag",
        "segment " + learn0() + " --color c.png --depth d.png -o " + o.string(),
        "segment --color c.png -o " + o.string(),
        "segment --color c.png --depth d.png -o " + o.string(),
        "segment " + learn0() + " -o " + o.string() + " --mrf-method magic",
        "segment " + learn0() + " -o " + o.string() + " --preset magic", std::string("eval-seg"),
        "eval-seg " + learn0(), "eval-seg " + learn0() + " " + learn0() + " --batch " + kData,
        // The recognition benchmark is bench/rec_bench now (tests/bench/test_rec_bench.cpp).
        "bench-rec --models " + kData + "/lmo/models -o " + o.string()}) {
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
  // The default's labels are the image-grid surfaces: none on invalid points.
  for (std::size_t i = 0; i < f.size(); ++i)
    if (!f.valid(i)) {
      ASSERT_EQ(f.label[i], 0u) << i;
    }
  const nlohmann::json j = nlohmann::json::parse(slurp(o.string() + ".json"));
  EXPECT_EQ(j["parameters"]["voxels"]["voxel_size"], 0.02);
  EXPECT_EQ(j["parameters"]["mrf"]["method"], "swap");
  EXPECT_FALSE(j["parameters"]["paper_labels"].get<bool>());
  for (const char* stage : {"image_surfaces", "selection", "total"})
    EXPECT_GE(j["times_ms"][stage].get<double>(), 0.0) << stage;
  // --paper-labels: every valid point takes one of the paper's labels, and stages 2-6 run.
  const CliRun p = run("segment " + learn0() + " -o " + o.string() + " --paper-labels");
  ASSERT_EQ(p.code, 0) << p.err;
  const proxseg::Frame g = proxseg::read_pcd(o.string() + ".pcd");
  for (std::size_t i = 0; i < g.size(); ++i) ASSERT_EQ(g.label[i] == 0, !g.valid(i)) << i;
  const nlohmann::json k = nlohmann::json::parse(slurp(o.string() + ".json"));
  for (const char* stage : {"voxels", "features", "initial_clustering", "kmeans", "mrf", "total"})
    EXPECT_GE(k["times_ms"][stage].get<double>(), 0.0) << stage;
  EXPECT_GE(k["k"].get<int>(), 2);
  EXPECT_LE(k["mrf"]["energy_after"].get<double>(), k["mrf"]["energy_before"].get<double>());
  EXPECT_GT(k["voxels"]["count"].get<int>(), 2000);
  std::size_t labelled = 0;
  for (const auto& l : k["labels"]) labelled += l["points"].get<std::size_t>();
  EXPECT_EQ(labelled, g.valid_count());
  EXPECT_EQ(j["k"], 0);  // the default: surfaces, not the paper's labels
  const cv::Mat png = cv::imread(o.string() + ".png");
  EXPECT_EQ(png.cols, 640);
  EXPECT_EQ(png.rows, 480);
  // A coloured scene: every block, and nothing to note.
  EXPECT_TRUE(j["input"]["colour"].get<bool>());
  EXPECT_EQ(j["features"], nlohmann::json({{"colour", true}, {"texture", true}, {"shape", true}}));
  EXPECT_EQ(r.err.find("has no colour"), std::string::npos) << r.err;
}

namespace {
// An XYZ-only copy of a cloud (the colour field dropped), under kTmp.
std::string xyz_only(const std::string& path, const std::string& name) {
  proxseg::Frame f = proxseg::read_pcd(path);
  f.rgb.clear();
  fs::create_directories(kTmp);
  const std::string out = (kTmp / name).string();
  proxseg::write_pcd(out, f, {});
  EXPECT_FALSE(proxseg::read_pcd(out).coloured()) << out;
  return out;
}
}  // namespace

TEST(Cli, SegmentsAnXyzOnlyCloudWithoutColourAndTexture) {
  const std::string input = xyz_only(learn0(), "learn0-xyz.pcd");
  const fs::path o = kTmp / "xyz", dir = kTmp / "xyz-candidates";
  fs::remove_all(dir);
  for (const char* ext : {".pcd", ".png", ".json"}) fs::remove(o.string() + ext);
  const CliRun r = run("segment " + input + " -o " + o.string() + " --candidates-dir " +
                       dir.string() + " --paper-labels");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(
      r.err.find("proxseg: " + input + " has no colour: the colour and texture blocks are off\n"),
      std::string::npos)
      << r.err;
  const nlohmann::json j = nlohmann::json::parse(slurp(o.string() + ".json"));
  EXPECT_FALSE(j["input"]["colour"].get<bool>());
  EXPECT_FALSE(j["features"]["colour"].get<bool>());
  EXPECT_FALSE(j["features"]["texture"].get<bool>());
  EXPECT_TRUE(j["features"]["shape"].get<bool>());
  EXPECT_EQ(j["features"]["note"],
            "the input has no colour: the colour and texture blocks are off");
  // The parameters are what was asked for; "features" is what was used.
  EXPECT_TRUE(j["parameters"]["features"]["use_colour"].get<bool>());
  EXPECT_GE(j["k"].get<int>(), 2);
  const cv::Mat png = cv::imread(o.string() + ".png");
  EXPECT_EQ(png.cols, 640);
  EXPECT_EQ(png.rows, 480);
  // The outputs invent no colour either.
  const proxseg::Frame out = proxseg::read_pcd(o.string() + ".pcd");
  EXPECT_FALSE(out.coloured());
  EXPECT_EQ(out.label.size(), out.size());
  std::size_t candidates = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    EXPECT_FALSE(proxseg::read_pcd(e.path().string()).coloured()) << e.path();
    ++candidates;
  }
  EXPECT_EQ(candidates, j["selection"]["candidates"].get<std::size_t>());
  EXPECT_GE(candidates, 1u);
  // Asking for the blocks off already: nothing was taken off by the input, nothing to note.
  const CliRun quiet =
      run("segment " + input + " -o " + o.string() + " --no-colour --no-texture --json");
  ASSERT_EQ(quiet.code, 0) << quiet.err;
  EXPECT_EQ(quiet.err.find("has no colour"), std::string::npos) << quiet.err;
  EXPECT_FALSE(nlohmann::json::parse(quiet.out)["features"].contains("note"));
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

  // Every report says which build made it.
  EXPECT_EQ(j["proxseg"]["version"], PROXSEG_VERSION);
  EXPECT_EQ(j["proxseg"]["commit"], proxseg::git_commit());

  // Sweeps: the flag reaches the parameters and caps the MRF's cycles.
  const CliRun one = run("segment " + learn0() + " -o " + o.string() + " --mrf-cycles 1 --json");
  ASSERT_EQ(one.code, 0) << one.err;
  const nlohmann::json k = nlohmann::json::parse(one.out);
  EXPECT_EQ(k["parameters"]["mrf"]["max_cycles"], 1);
  EXPECT_EQ(k["mrf"]["cycles"], 1);
  EXPECT_LT(k["mrf"]["energy_after"].get<double>(), k["mrf"]["energy_before"].get<double>());
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

// More bad inputs, one test each, in test_robustness.cpp (the table of docs/robustness.md).
TEST(Cli, BadInputsExitOneWithTheFileNamedAndNoOutput) {
  fs::create_directories(kTmp);
  const fs::path o = kTmp / "bad";
  expect_input_error(run("segment " + (kTmp / "missing.pcd").string() + " -o " + o.string()),
                     "missing.pcd", o);
  std::ofstream(kTmp / "cloud.xyz") << "0 0 1\n";
  expect_input_error(run("segment " + (kTmp / "cloud.xyz").string() + " -o " + o.string()),
                     "cloud.xyz", o);
  // A real file cut in half.
  const std::string whole = slurp(learn0());
  std::ofstream(kTmp / "truncated.pcd", std::ios::binary) << whole.substr(0, whole.size() / 2);
  expect_input_error(run("segment " + (kTmp / "truncated.pcd").string() + " -o " + o.string()),
                     "truncated.pcd", o);
  expect_input_error(run("segment " + learn0() + " --voxel-size -1 -o " + o.string()), "voxel_size",
                     o);
  expect_input_error(run("segment " + learn0() + " --mrf-cycles 0 -o " + o.string()), "max_cycles",
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

TEST(Cli, SegmentWritesInstancesAndCandidates) {
  const fs::path o = kTmp / "inst", dir = kTmp / "inst-candidates";
  fs::remove_all(dir);
  const CliRun r =
      run("segment " + learn0() + " -o " + o.string() + " --candidates-dir " + dir.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const proxseg::Frame f = proxseg::read_pcd(o.string() + ".pcd", "instance");
  ASSERT_EQ(f.label.size(), f.size());
  const nlohmann::json j = nlohmann::json::parse(slurp(o.string() + ".json"));
  std::size_t objects = 0, background = 0;
  nlohmann::json instances = j["candidates"];
  for (const auto& c : j["background"]) {
    EXPECT_TRUE(c["background"].get<bool>());
    instances.push_back(c);
  }
  for (const auto& c : instances) {
    const std::uint32_t id = c["id"];
    const std::size_t points = c["points"];
    EXPECT_EQ(static_cast<std::size_t>(std::count(f.label.begin(), f.label.end(), id)), points);
    EXPECT_EQ(c["box"]["extent"].size(), 3u);
    EXPECT_EQ(c["box"]["axes"].size(), 3u);
    if (c["background"]) {
      ++background;
      continue;
    }
    ++objects;
    const proxseg::Frame cloud =
        proxseg::read_pcd((dir / ("candidate_" + std::to_string(id) + ".pcd")).string());
    EXPECT_EQ(cloud.size(), points);
    EXPECT_EQ(cloud.height, 1);
  }
  // learn0: two boxes on a table.
  EXPECT_EQ(objects, 2u);
  EXPECT_EQ(objects, j["selection"]["candidates"].get<std::size_t>());
  EXPECT_EQ(j["candidates"].size(), objects);
  EXPECT_EQ(background, 1u);
  EXPECT_EQ(static_cast<std::size_t>(std::distance(fs::directory_iterator(dir), {})), objects);
}

TEST(Cli, EvalSegScoresAPredictionAndRejectsAMismatch) {
  // The ground truth against itself is perfect.
  CliRun r = run("eval-seg " + learn0() + " " + learn0() + " --field label --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_DOUBLE_EQ(j["objects"]["object_f"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(j["parts"]["v_measure"].get<double>(), 1.0);
  r = run("eval-seg " + learn0() + " " + learn0() + " --field label");
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("objects  1.000"), std::string::npos) << r.out;
  // A prediction of another size: exit 1, the file named.
  const std::string other = kData + "/pcl/milk.pcd";
  r = run("eval-seg " + learn0() + " " + other);
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("milk.pcd"), std::string::npos) << r.err;
  // A ground truth without labels: exit 1.
  r = run("eval-seg " + other + " " + other);
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("label"), std::string::npos) << r.err;
}

TEST(Cli, EvalSegBatchWritesCsvAndSummaries) {
  // A folder with two learn scenes (links to the real data) and an unlabelled cloud.
  const fs::path dir = kTmp / "batch-in", out = kTmp / "batch-out";
  fs::remove_all(dir);
  fs::remove_all(out);
  fs::create_directories(dir);
  for (const char* name : {"learn0.pcd", "learn20.pcd"})
    fs::create_symlink(kData + "/mosd/learn/" + name, dir / name);
  fs::create_symlink(kData + "/pcl/milk.pcd", dir / "milk.pcd");
  // Predictions read from a folder: the ground truth itself, so every score is perfect.
  CliRun r = run("eval-seg --batch " + dir.string() + " --pred-dir " + dir.string() +
                 " --field label -o " + out.string() + " --json");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("[3/3]"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("skipped"), std::string::npos) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["scenes"], 2);
  EXPECT_EQ(j["skipped_unlabelled"], 1);
  const std::string csv = slurp(out / "scenes.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 3);
  EXPECT_NE(csv.find("learn20.pcd,stacked,predictions"), std::string::npos);
  const std::string md = slurp(out / "summary.md");
  for (const char* row :
       {"| predictions | boxes | 1 | 1.000 |", "| predictions | stacked | 1 | 1.000 |",
        "| predictions | all | 2 | 1.000 |"})
    EXPECT_NE(md.find(row), std::string::npos) << row << "\n" << md;
  const auto eval_summary = nlohmann::json::parse(slurp(out / "summary.json"));
  EXPECT_EQ(eval_summary["summary"].size(), 3u);
  EXPECT_EQ(eval_summary["proxseg"]["commit"], proxseg::git_commit());
  // Segmenting each scene (no --pred-dir): the method is named after the preset.
  fs::remove(dir / "learn20.pcd");
  fs::remove(dir / "milk.pcd");
  r = run("eval-seg --batch " + dir.string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("| proxseg default | boxes | 1 |"), std::string::npos) << r.out;
}

// The recognition issue's first acceptance run through the CLI: a database of the milk carton
// plus two rendered LINEMOD objects, then `recognize` on the real scene.
TEST(Cli, DatabaseAndRecognizeTheMilkScene) {
  const fs::path db = kTmp / "milkdb";
  fs::remove_all(db);
  CliRun r = run("db add " + db.string() + " --name milk " + kData + "/pcl/milk.pcd");
  ASSERT_EQ(r.code, 0) << r.err;
  for (const auto& [id, name] : {std::pair{"01", "ape"}, std::pair{"05", "can"}}) {
    r = run("db render " + db.string() + " --name " + name + " " + kData + "/lmo/models/obj_0000" +
            id + ".ply --views 4 --units mm");
    ASSERT_EQ(r.code, 0) << r.err;
  }
  r = run("db info " + db.string() + " --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto info = nlohmann::json::parse(r.out);
  EXPECT_EQ(info["views"], 9);
  EXPECT_EQ(info["objects"].size(), 3u);
  EXPECT_TRUE(fs::exists(db / "database.sqlite"));
  EXPECT_GT(info["file_bytes"].get<std::size_t>(), 100000u);

  const fs::path o = kTmp / "milk_rec";
  r = run("recognize " + kData + "/pcl/milk_cartoon_all_small_clorox.pcd --db " + db.string() +
          " -o " + o.string() + " --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto report = nlohmann::json::parse(r.out);
  EXPECT_EQ(report, nlohmann::json::parse(slurp(o.string() + ".json")));
  int milk = 0;
  for (const auto& c : report["candidates"])
    if (c["name"] == "milk") {
      ++milk;
      EXPECT_GE(c["fitness"].get<double>(), 0.9);
      EXPECT_EQ(c["pose"].size(), 4u);
      EXPECT_TRUE(c.contains("runner_up"));
    }
  EXPECT_EQ(milk, 1);
  // Every object says where it came from: a candidate of the selection, or a split or a merge
  // of candidates by recognition.
  for (const auto& c : report["candidates"]) {
    EXPECT_TRUE(c["origin"] == "candidate" || c["origin"] == "split" || c["origin"] == "merged");
    ASSERT_GE(c["instances"].size(), 1u);
    if (c["origin"] == "merged") {
      EXPECT_GE(c["instances"].size(), 2u);
    }
  }
  EXPECT_EQ(report["parameters"]["recognition"]["merge_distance"], 0.03);
  EXPECT_EQ(report["proxseg"]["version"], PROXSEG_VERSION);
  EXPECT_TRUE(report["parameters"].contains("recognition"));
  EXPECT_TRUE(report["parameters"].contains("segmentation"));
  // The picture: the scene and a legend to its right; the objects' ids in PREFIX.pcd
  // (tests/cli/test_recognize_outputs.cpp checks them against ground truth).
  const cv::Mat png = cv::imread(o.string() + ".png");
  EXPECT_EQ(report["picture"]["scene"]["width"], 640);
  EXPECT_EQ(png.cols, report["picture"]["width"].get<int>());
  EXPECT_GT(png.cols, 640);
  EXPECT_EQ(png.rows, 480);
  const proxseg::Frame labelled = proxseg::read_pcd(o.string() + ".pcd", "object");
  EXPECT_EQ(labelled.width, 640);
  EXPECT_EQ(labelled.label.size(), labelled.size());
  EXPECT_EQ(report["labels"]["field"], "object");

  // One segmented cloud.
  r = run("recognize --object " + kData + "/pcl/milk.pcd --db " + db.string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("milk"), std::string::npos) << r.out;

  // The database kept: checked, an object renamed and another removed.
  r = run("db check " + db.string());
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("9 of 9 views whole"), std::string::npos) << r.out;
  r = run("db rename " + db.string() + " --name can --to tin");
  EXPECT_EQ(r.code, 0) << r.err;
  r = run("db remove " + db.string() + " --name ape");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("removed ape (4 views); 2 objects, 5 views"), std::string::npos) << r.out;
  r = run("db info " + db.string());
  EXPECT_NE(r.out.find("tin: 4 views"), std::string::npos) << r.out;
  expect_input_error(run("db remove " + db.string() + " --name ape"), "no object named \"ape\"",
                     kTmp / "none");

  // Bad input: a truncated database file and a config with an unknown key.
  fs::remove_all(kTmp / "milkdb_broken");
  fs::copy(db, kTmp / "milkdb_broken", fs::copy_options::recursive);
  fs::resize_file(kTmp / "milkdb_broken" / "database.sqlite", 3000);
  const fs::path bad = kTmp / "milk_bad";
  expect_input_error(run("recognize --object " + kData + "/pcl/milk.pcd --db " +
                         (kTmp / "milkdb_broken").string() + " -o " + bad.string()),
                     "database.sqlite", bad);
  std::ofstream(kTmp / "rec_unknown.json") << R"({"recognition": {"ransac_iters": 5}})";
  expect_input_error(run("recognize --object " + kData + "/pcl/milk.pcd --db " + db.string() +
                         " --config " + (kTmp / "rec_unknown.json").string()),
                     "ransac_iters", bad);
  EXPECT_EQ(run("recognize --db " + db.string()).code, 2);
  EXPECT_EQ(run("db add " + db.string() + " --name x").code, 2);
}

// XYZ-only clouds in a database and against it: the milk carton without its (placeholder)
// colour, recognised as one object and in its scene.
TEST(Cli, RecognizesXyzOnlyClouds) {
  const fs::path db = kTmp / "xyzdb";
  fs::remove_all(db);
  const std::string milk = xyz_only(kData + "/pcl/milk.pcd", "milk-xyz.pcd");
  CliRun r = run("db add " + db.string() + " --name milk " + milk);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("no colour"), std::string::npos) << r.err;
  r = run("db render " + db.string() + " --name can " + kData +
          "/lmo/models/obj_000005.ply --views 4 --units mm");
  ASSERT_EQ(r.code, 0) << r.err;
  // --accumulate over a coloured and an XYZ-only view: one view, without colour.
  r = run("db add " + (kTmp / "xyzdb-acc").string() + " --name milk --accumulate " + kData +
          "/pcl/milk.pcd " + milk);
  fs::remove_all(kTmp / "xyzdb-acc");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("no colour"), std::string::npos) << r.err;

  const fs::path o = kTmp / "xyz_object";
  r = run("recognize --object " + milk + " --db " + db.string() + " -o " + o.string() + " --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto report = nlohmann::json::parse(r.out);
  ASSERT_EQ(report["candidates"].size(), 1u);
  EXPECT_EQ(report["candidates"][0]["name"], "milk");
  EXPECT_GE(report["candidates"][0]["fitness"].get<double>(), 0.9);
  EXPECT_FALSE(cv::imread(o.string() + ".png").empty());

  // A whole XYZ-only scene: segmented without colour and texture, the carton still found.
  const std::string scene =
      xyz_only(kData + "/pcl/milk_cartoon_all_small_clorox.pcd", "milk-scene-xyz.pcd");
  const fs::path s = kTmp / "xyz_scene";
  r = run("recognize " + scene + " --db " + db.string() + " -o " + s.string() + " --json");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find(scene + " has no colour: the colour and texture blocks are off"),
            std::string::npos)
      << r.err;
  const auto scene_report = nlohmann::json::parse(r.out);
  int found = 0;
  for (const auto& c : scene_report["candidates"]) found += c["name"] == "milk";
  EXPECT_EQ(found, 1);
  EXPECT_FALSE(proxseg::read_pcd(s.string() + ".pcd", "object").coloured());
  EXPECT_EQ(cv::imread(s.string() + ".png").rows, 480);
}
