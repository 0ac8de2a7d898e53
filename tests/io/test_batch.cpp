// Batch work over datasets (docs/batch.md): frame discovery, shards, the resumable summary, and
// `segment --batch` / `recognize --batch` against single runs, on real frames.
#include <proxseg/core/errors.hpp>
#include <proxseg/core/version.hpp>
#include <proxseg/io/batch.hpp>
#include <proxseg/io/cloud_io.hpp>

#include "support/cli_util.hpp"

#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <thread>

namespace fs = std::filesystem;

namespace {
using namespace cli_test;
const fs::path kTmp = fs::path(PROXSEG_TEST_TMP) / "batch";
const std::string kFrames = kData + "/ycbv/frames";

std::string test_name() {
  return ::testing::UnitTest::GetInstance()->current_test_info()->name();
}

// A fresh folder for this test (ctest runs each test case in its own process).
fs::path fresh(const std::string& name) {
  const fs::path dir = kTmp / test_name() / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

CliRun run(const std::string& args) {
  return run_in(kTmp / test_name(), args);
}

void link(const fs::path& target, const fs::path& at) {
  fs::create_directories(at.parent_path());
  fs::create_symlink(target, at);
}

// YCB-Video frame k's three files linked at DIR/<name>-{color,depth}.png, -meta.json.
void link_ycb(int k, const fs::path& dir, const std::string& name) {
  char stem[16];
  std::snprintf(stem, sizeof stem, "/%06d", k);
  for (const char* part : {"-color.png", "-depth.png", "-meta.json"})
    link(kFrames + stem + part, dir / (name + part));
}

// A dataset of real frames in nested folders: mOSD clouds in two levels and YCB-Video RGB-D
// pairs in a sequence folder.
fs::path real_dataset(int mosd, int ycb) {
  const fs::path dir = fresh("data");
  for (int i = 0; i < mosd; ++i)
    link(kData + "/mosd/learn/learn" + std::to_string(i) + ".pcd",
         dir / (i % 2 ? "tabletop/odd" : "tabletop") / ("learn" + std::to_string(i) + ".pcd"));
  for (int k = 1; k <= ycb; ++k) {
    char name[16];
    std::snprintf(name, sizeof name, "%06d", k);
    link_ycb(k, dir / "ycb", name);
  }
  return dir;
}

#ifdef PROXSEG_SANITIZE
constexpr int kMosd = 3, kYcb = 1;  // the sanitizer build is several times slower
#else
constexpr int kMosd = 8, kYcb = 2;
#endif

// Every output file under dir (the batch's own summaries aside), by its relative path.
std::map<std::string, std::string> outputs(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    const std::string rel = e.path().lexically_relative(dir).generic_string();
    if (e.is_regular_file() && rel.rfind("summary", 0) != 0) files[rel] = slurp(e.path());
  }
  return files;
}

// A report without what differs from run to run: the times, and the memory.
nlohmann::json timeless(nlohmann::json j) {
  j.erase("times_ms");
  j.erase("concurrent_times_ms");
  j.erase("step_times_ms");
  if (j.contains("candidates") && j["candidates"].is_array())
    for (auto& c : j["candidates"]) c.erase("times_ms");
  return j;
}

// The outputs of two batches are the same: the same files, byte for byte, reports apart from
// their times.
void expect_same_outputs(const fs::path& a, const fs::path& b) {
  const auto fa = outputs(a), fb = outputs(b);
  std::set<std::string> na, nb;
  for (const auto& [k, v] : fa) na.insert(k);
  for (const auto& [k, v] : fb) nb.insert(k);
  ASSERT_EQ(na, nb);
  for (const auto& [name, bytes] : fa) {
    if (fs::path(name).extension() == ".json")
      EXPECT_EQ(timeless(nlohmann::json::parse(bytes)),
                timeless(nlohmann::json::parse(fb.at(name))))
          << name;
    else
      EXPECT_TRUE(bytes == fb.at(name)) << name;
  }
}

std::vector<std::string> ids(const std::vector<proxseg::FrameSource>& frames) {
  std::vector<std::string> out;
  for (const auto& f : frames) out.push_back(f.id);
  return out;
}

// A row's output files with their sizes, the reports' only by name (their times vary in length).
nlohmann::json sizes_but_json(nlohmann::json outputs) {
  for (auto& [name, bytes] : outputs.items())
    if (fs::path(name).extension() == ".json") bytes = nullptr;
  return outputs;
}

// The frame rows of a summary log, in order.
std::vector<nlohmann::json> frame_rows(const fs::path& log) {
  std::vector<nlohmann::json> rows;
  std::ifstream in(log);
  for (std::string line; std::getline(in, line);) {
    const auto j = nlohmann::json::parse(line);
    if (j.contains("frame")) rows.push_back(j);
  }
  return rows;
}

}  // namespace

TEST(Batch, NaturalOrderComparesNumbersAsNumbers) {
  EXPECT_TRUE(proxseg::natural_less("scene2", "scene10"));
  EXPECT_FALSE(proxseg::natural_less("scene10", "scene2"));
  EXPECT_TRUE(proxseg::natural_less("a/000009", "a/000010"));
  EXPECT_TRUE(proxseg::natural_less("learn", "learn0"));
  EXPECT_TRUE(proxseg::natural_less("x1y2", "x1y10"));
  EXPECT_FALSE(proxseg::natural_less("same", "same"));
  // Leading zeros: equal numbers, then the plain text decides (a strict order).
  EXPECT_NE(proxseg::natural_less("f01", "f1"), proxseg::natural_less("f1", "f01"));
}

TEST(Batch, DiscoversCloudsAndRgbdPairsInNestedFolders) {
  const fs::path dir = fresh("tree");
  link(learn0(), dir / "a" / "learn0.pcd");
  link(kData + "/mosd/learn/learn1.pcd", dir / "a" / "b" / "learn1.pcd");
  link_ycb(1, dir / "seq1", "000001");
  link(kFrames + "/000002-color.png", dir / "seq1" / "000002-color.png");  // no meta: no camera
  link(kFrames + "/000002-depth.png", dir / "seq1" / "000002-depth.png");
  link(learn0(), dir / ".hidden" / "learn9.pcd");  // hidden folders are skipped
  std::ofstream(dir / "notes.txt") << "not a frame\n";
  // BOP-like streams, found with other patterns.
  link(kFrames + "/000003-color.png", dir / "bop" / "rgb" / "000003.png");
  link(kFrames + "/000003-depth.png", dir / "bop" / "depth" / "000003.png");
  std::ofstream(dir / "bop" / "camera.json")
      << R"({"fx": 1066.778, "fy": 1067.487, "cx": 312.9869, "cy": 241.3109, "depth_scale": 10000})";

  const auto frames = proxseg::discover_frames({dir.string()});
  EXPECT_EQ(ids(frames),
            (std::vector<std::string>{"a/b/learn1", "a/learn0", "seq1/000001", "seq1/000002"}));
  EXPECT_EQ(fs::path(frames[1].cloud), dir / "a" / "learn0.pcd");
  EXPECT_EQ(fs::path(frames[2].colour), dir / "seq1" / "000001-color.png");
  EXPECT_EQ(fs::path(frames[2].depth), dir / "seq1" / "000001-depth.png");
  EXPECT_EQ(fs::path(frames[2].camera), dir / "seq1" / "000001-meta.json");
  EXPECT_TRUE(frames[3].camera.empty());
  const proxseg::Frame ycb = proxseg::read_frame(frames[2]);
  EXPECT_EQ(ycb.width, 640);
  EXPECT_EQ(ycb.height, 480);
  try {
    proxseg::read_frame(frames[3]);
    ADD_FAILURE() << "a pair without a camera read";
  } catch (const proxseg::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("000002-color.png"), std::string::npos) << e.what();
  }
  // One intrinsics file for the pairs without meta.
  proxseg::RgbdNaming with_camera;
  with_camera.intrinsics = (dir / "bop" / "camera.json").string();
  EXPECT_EQ(fs::path(proxseg::discover_frames({dir.string()}, with_camera)[3].camera),
            dir / "bop" / "camera.json");

  // Streams in folders: {id} in a file name below a folder per stream.
  proxseg::RgbdNaming bop;
  bop.colour = "rgb/{id}.png";
  bop.depth = "depth/{id}.png";
  bop.meta = "";
  bop.intrinsics = (dir / "bop" / "camera.json").string();
  const auto streams = proxseg::discover_frames({dir.string()}, bop);
  ASSERT_EQ(ids(streams), (std::vector<std::string>{"a/b/learn1", "a/learn0", "bop/000003"}));
  EXPECT_EQ(fs::path(streams[2].depth), dir / "bop" / "depth" / "000003.png");
  const proxseg::Frame from_streams = proxseg::read_frame(streams[2]);
  EXPECT_EQ(from_streams.valid_count(),
            proxseg::read_frame(proxseg::discover_frames({kFrames + "/000003-color.png"})[0])
                .valid_count());

  // A glob: ids relative to the deepest folder that holds every match.
  EXPECT_EQ(ids(proxseg::discover_frames({(dir / "**" / "*.pcd").string()})),
            (std::vector<std::string>{"b/learn1", "learn0"}));
  EXPECT_EQ(ids(proxseg::discover_frames({(dir / "*" / "*-color.png").string()})),
            (std::vector<std::string>{"000001", "000002"}));

  // A list file: clouds, colour images, explicit pairs; comments and blank lines.
  std::ofstream(dir / "list.txt") << "# frames\n\na/learn0.pcd\nseq1/000001-color.png\n"
                                  << "  seq1/000002-color.png seq1/000002-depth.png "
                                     "bop/camera.json  \n";
  const auto listed = proxseg::discover_frames({(dir / "list.txt").string()});
  ASSERT_EQ(ids(listed), (std::vector<std::string>{"a/learn0", "seq1/000001", "seq1/000002"}));
  EXPECT_EQ(fs::path(listed[2].camera), dir / "bop" / "camera.json");
  EXPECT_EQ(proxseg::read_frame(listed[2]).width, 640);

  // Errors name the source, the line, or both frames of a name.
  std::ofstream(dir / "bad-list.txt") << "a/learn0.pcd\nno/such.pcd\n";
  try {
    proxseg::discover_frames({(dir / "bad-list.txt").string()});
    ADD_FAILURE() << "a missing listed file";
  } catch (const proxseg::FileError& e) {
    EXPECT_NE(std::string(e.what()).find("bad-list.txt:2"), std::string::npos) << e.what();
  }
  EXPECT_THROW(proxseg::discover_frames({(dir / "nothing-here").string()}), proxseg::FileError);
  EXPECT_THROW(proxseg::discover_frames({(dir / "seq1" / "*.pcd").string()}), proxseg::InputError);
  link(kData + "/pcl/milk.pcd", dir / "a" / "learn0.ply");
  try {
    proxseg::discover_frames({dir.string()});
    ADD_FAILURE() << "two frames of one name";
  } catch (const proxseg::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("two frames named a/learn0"), std::string::npos)
        << e.what();
  }
  proxseg::RgbdNaming no_id;
  no_id.colour = "rgb.png";  // a pattern without {id}
  EXPECT_THROW(proxseg::discover_frames({dir.string()}, no_id), proxseg::InputError);
}

TEST(Batch, ShardsPartitionTheFramesStably) {
  std::vector<proxseg::FrameSource> frames(500);
  for (std::size_t i = 0; i < frames.size(); ++i) frames[i].id = "seq/" + std::to_string(i);
  std::set<std::string> seen;
  for (int s = 1; s <= 3; ++s) {
    const auto shard = proxseg::shard_frames(frames, s, 3);
    EXPECT_GT(shard.size(), 130u);  // about a third each
    for (const auto& f : shard) EXPECT_TRUE(seen.insert(f.id).second) << f.id;
  }
  EXPECT_EQ(seen.size(), frames.size());
  // A frame keeps its shard when the dataset grows.
  auto more = frames;
  more.resize(800);
  for (std::size_t i = 500; i < more.size(); ++i) more[i].id = "seq/" + std::to_string(i);
  const auto before = ids(proxseg::shard_frames(frames, 2, 3));
  auto after = ids(proxseg::shard_frames(more, 2, 3));
  after.resize(before.size());
  EXPECT_EQ(before, after);
  EXPECT_EQ(ids(proxseg::shard_frames(frames, 1, 1)), ids(frames));
  EXPECT_THROW(proxseg::shard_frames(frames, 0, 3), proxseg::InputError);
  EXPECT_THROW(proxseg::shard_frames(frames, 4, 3), proxseg::InputError);
}

TEST(Batch, SummaryLogKeepsWholeLinesLocksAndChecksTheSettings) {
  const fs::path out = fresh("out");
  const nlohmann::json header = {
      {"command", "segment"}, {"outputs", "json"}, {"parameters", {{"a", 1}}}, {"frames", 2}};
  std::ofstream(out / "one.json") << "12345";
  {
    proxseg::SummaryLog log(out.string(), "summary", header, false);
    log.append({{"frame", "one"}, {"outputs", {{"one.json", 5}}}});
    // One process per summary: a second is refused while the first holds it.
    EXPECT_THROW(proxseg::SummaryLog(out.string(), "summary", header, true), proxseg::InputError);
  }
  // A killed run's half-written line.
  std::ofstream(out / "summary.jsonl", std::ios::app) << R"({"frame": "two", "outp)";
  EXPECT_EQ(proxseg::finished_frames(out.string()), std::set<std::string>{"one"});
  std::ofstream(out / "one.json") << "1234";  // not the size the summary recorded: not whole
  EXPECT_TRUE(proxseg::finished_frames(out.string()).empty());
  std::ofstream(out / "one.json") << "12345";
  {
    proxseg::SummaryLog log(out.string(), "summary", header, true);
    log.append({{"frame", "two"}, {"error", "x.pcd: broken"}});
    log.close(false, 100);
  }
  const std::string text = slurp(out / "summary.jsonl");
  EXPECT_EQ(text.find("outp\""), std::string::npos);
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 5);  // header, one, header, two, end
  const nlohmann::json s = proxseg::summarize({(out / "summary.jsonl").string()}, true);
  EXPECT_EQ(s["frames_total"], 2);
  EXPECT_EQ(s["frames_done"], 1);
  EXPECT_EQ(s["frames_failed"], 1);
  // Each row carries the fingerprint of the settings it was made with.
  const std::string fingerprint = proxseg::settings_fingerprint(header);
  EXPECT_EQ(s["failed"],
            nlohmann::json::array({nlohmann::json{
                {"frame", "two"}, {"error", "x.pcd: broken"}, {"fingerprint", fingerprint}}}));
  EXPECT_EQ(s["bytes_written"], 5);
  EXPECT_FALSE(s["interrupted"].get<bool>());
  // The failed frame done on a later resume: each frame's last row counts.
  {
    proxseg::SummaryLog log(out.string(), "summary", header, true);
    log.append({{"frame", "two"}, {"outputs", {{"two.json", 3}}}});
    log.close(false, 90);
  }
  const nlohmann::json again = proxseg::summarize({(out / "summary.jsonl").string()}, true);
  EXPECT_EQ(again["frames_done"], 2);
  EXPECT_EQ(again["frames_failed"], 0);
  EXPECT_EQ(again["failed"], nlohmann::json::array());
  EXPECT_EQ(again["bytes_written"], 8);
  EXPECT_EQ(again["peak_rss_mib"], 100);
  const nlohmann::json rows = proxseg::frame_rows(out.string());
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[1],
            nlohmann::json(
                {{"frame", "two"}, {"outputs", {{"two.json", 3}}}, {"fingerprint", fingerprint}}));
  // Other parameters may not resume into this folder; a new run may.
  nlohmann::json other = header;
  other["parameters"]["a"] = 2;
  try {
    proxseg::SummaryLog(out.string(), "summary", other, true);
    ADD_FAILURE() << "resumed with other parameters";
  } catch (const proxseg::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("parameters/a (1 earlier, 2 now)"), std::string::npos)
        << e.what();
  }
  EXPECT_NO_THROW(proxseg::SummaryLog(out.string(), "summary", other, false));
}

TEST(Batch, SettingsFingerprintIsAStableHashOfTheSettingsAlone) {
  const nlohmann::json header = {{"command", "segment"},
                                 {"outputs", "json"},
                                 {"parameters", {{"b", 0.5}, {"a", 1}}},
                                 {"shard", "1/2"},
                                 {"frames", 3}};
  // FNV-1a (64 bits) of {"command":"segment","database":null,"outputs":"json",
  // "parameters":{"a":1,"b":0.5}}: the same on every machine, run and build.
  EXPECT_EQ(proxseg::settings_fingerprint(header), "ea2325509955fb52");
  // What is not a setting (the shard, counts, the build) leaves it; a parameter changes it.
  nlohmann::json other = header;
  other["shard"] = "2/2";
  other["frames"] = 5;
  other["proxseg"] = {{"version", "x"}};
  EXPECT_EQ(proxseg::settings_fingerprint(other), proxseg::settings_fingerprint(header));
  other["parameters"]["a"] = 2;
  EXPECT_NE(proxseg::settings_fingerprint(other), proxseg::settings_fingerprint(header));
}

TEST(Batch, ThreeShardsGiveTheOutputsOfOneRun) {
  const fs::path data = real_dataset(kMosd, kYcb), one = fresh("one"), three = fresh("three");
  CliRun r = run("segment --batch " + data.string() + " -o " + one.string() + " --outputs all");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto single = nlohmann::json::parse(slurp(one / "summary.json"));
  EXPECT_EQ(single["frames_done"], kMosd + kYcb);
  std::size_t sharded = 0;
  for (int s = 1; s <= 3; ++s) {
    r = run("segment --batch " + data.string() + " -o " + three.string() +
            " --outputs all --shard " + std::to_string(s) + "/3 --json");
    ASSERT_EQ(r.code, 0) << r.err;
    const auto summary = nlohmann::json::parse(r.out);
    EXPECT_EQ(summary["shards"], nlohmann::json::array({std::to_string(s) + "/3"}));
    sharded += summary["frames_done"].get<std::size_t>();
    EXPECT_TRUE(fs::exists(three / ("summary.shard-" + std::to_string(s) + "-of-3.jsonl")));
  }
  EXPECT_EQ(sharded, static_cast<std::size_t>(kMosd + kYcb));
  expect_same_outputs(one, three);
  // The nested input folders are mirrored.
  EXPECT_TRUE(fs::exists(three / "tabletop" / "odd" / "learn1.pcd"));
  EXPECT_TRUE(fs::exists(three / "ycb" / "000001.label.png"));
  // The merged summary lists the same frames, with the same outputs, as the single run's.
  r = run("summary " + three.string() + " --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto merged = nlohmann::json::parse(r.out);
  EXPECT_EQ(merged, nlohmann::json::parse(slurp(three / "summary.json")));
  EXPECT_EQ(merged["frames_total"], kMosd + kYcb);
  EXPECT_EQ(merged["frames_done"], kMosd + kYcb);
  EXPECT_EQ(merged["frames_missing"], 0);
  EXPECT_EQ(merged["parameters"], single["parameters"]);
  EXPECT_EQ(merged["logs"],
            nlohmann::json({"summary.shard-1-of-3.jsonl", "summary.shard-2-of-3.jsonl",
                            "summary.shard-3-of-3.jsonl"}));
  EXPECT_FALSE(merged.contains("frames"));  // the rows stay in the logs
  const auto merged_rows = proxseg::frame_rows(three.string()),
             single_rows = proxseg::frame_rows(one.string());
  ASSERT_EQ(merged_rows.size(), static_cast<std::size_t>(kMosd + kYcb));
  ASSERT_EQ(merged_rows.size(), single_rows.size());
  std::uintmax_t bytes = 0;
  for (std::size_t i = 0; i < merged_rows.size(); ++i) {
    EXPECT_EQ(merged_rows[i]["frame"], single_rows[i]["frame"]);
    EXPECT_EQ(sizes_but_json(merged_rows[i]["outputs"]), sizes_but_json(single_rows[i]["outputs"]));
    EXPECT_EQ(merged_rows[i]["k"], single_rows[i]["k"]);
    for (const auto& [file, size] : merged_rows[i]["outputs"].items())
      bytes += size.get<std::uintmax_t>();
  }
  EXPECT_EQ(merged["bytes_written"], bytes);
  // The label images hold the PCD's fields.
  const auto pcd = proxseg::read_pcd((three / "ycb" / "000001.pcd").string(), "instance");
  const auto png = proxseg::read_label_png((three / "ycb" / "000001.instance.png").string());
  EXPECT_EQ(png.width, 640);
  EXPECT_EQ(png.values, pcd.label);
  // A missing shard shows in the merge.
  fs::remove(three / "summary.shard-2-of-3.jsonl");
  r = run("summary " + three.string() + " --json");
  EXPECT_EQ(r.code, 1);
  const auto partial = nlohmann::json::parse(r.out);
  EXPECT_EQ(partial["shards_missing"], nlohmann::json::array({"2/3"}));
  EXPECT_EQ(partial["frames_total"], kMosd + kYcb);
  EXPECT_GT(partial["frames_missing"].get<int>(), 0);
  EXPECT_EQ(partial["frames_missing"].get<int>() + partial["frames_done"].get<int>(), kMosd + kYcb);
}

TEST(Batch, ResumeAfterAKillFinishesTheRestAsAnUninterruptedRun) {
  const fs::path data = real_dataset(kMosd, 0), whole = fresh("whole"), killed = fresh("killed");
  const std::string outputs = " --outputs labels,pcd,json";
  ASSERT_EQ(run("segment --batch " + data.string() + " -o " + whole.string() + outputs).code, 0);
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    const std::string log = (kTmp / test_name() / "killed.log").string();
    std::freopen(log.c_str(), "w", stdout);
    std::freopen(log.c_str(), "a", stderr);
    ::execl(kCli.c_str(), kCli.c_str(), "segment", "--batch", data.c_str(), "-o", killed.c_str(),
            "--outputs", "labels,pcd,json", static_cast<char*>(nullptr));
    std::_Exit(127);
  }
  // SIGKILL (no chance to clean up) once two frames are logged.
  const auto start = std::chrono::steady_clock::now();
  while (frame_rows(killed / "summary.jsonl").size() < 2 &&
         std::chrono::steady_clock::now() - start < std::chrono::minutes(5))
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ::kill(pid, SIGKILL);
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFSIGNALED(status));
  const std::size_t before = frame_rows(killed / "summary.jsonl").size();
  ASSERT_GE(before, 2u);
  ASSERT_LT(before, static_cast<std::size_t>(kMosd)) << "the batch ended before the kill";

  const CliRun r = run("segment --batch " + data.string() + " -o " + killed.string() + outputs +
                       " --resume --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto summary = nlohmann::json::parse(r.out);
  EXPECT_EQ(summary["frames_done"], kMosd);
  EXPECT_EQ(summary["frames_missing"], 0);
  // Each frame was done once: the resumed run skipped the finished ones.
  std::map<std::string, int> times;
  for (const auto& row : frame_rows(killed / "summary.jsonl")) ++times[row["frame"]];
  EXPECT_EQ(times.size(), static_cast<std::size_t>(kMosd));
  for (const auto& [id, n] : times) EXPECT_EQ(n, 1) << id;
  expect_same_outputs(whole, killed);  // no temporary file left either
}

TEST(Batch, SegmentBatchReportsABadFrameAndDoesTheRest) {
  const fs::path in = fresh("in"), out = fresh("out");
  link(kData + "/pcl/milk.pcd", in / "milk.pcd");
  link(learn0(), in / "learn0.pcd");
  std::ofstream(in / "broken.ply") << "not a ply\n";
  const CliRun r = run("segment --batch " + in.string() + " -o " + out.string() + " --json");
  EXPECT_EQ(r.code, 1) << r.err;  // one frame failed; the others are done
  const auto summary = nlohmann::json::parse(r.out);
  EXPECT_EQ(summary, nlohmann::json::parse(slurp(out / "summary.json")));
  EXPECT_EQ(summary["frames_total"], 3);
  EXPECT_EQ(summary["frames_done"], 2);
  EXPECT_EQ(summary["frames_failed"], 1);
  EXPECT_EQ(summary["proxseg"]["version"], PROXSEG_VERSION);
  ASSERT_EQ(summary["failed"].size(), 1u);
  EXPECT_EQ(summary["failed"][0]["frame"], "broken");
  EXPECT_NE(summary["failed"][0]["error"].get<std::string>().find("broken.ply"), std::string::npos);
  const auto rows = proxseg::frame_rows(out.string());
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0]["frame"], "broken");  // natural order
  EXPECT_EQ(rows[0], summary["failed"][0]);
  EXPECT_NE(r.err.find("broken.ply"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("frames/s, ETA"), std::string::npos) << r.err;  // the progress bar
  for (const char* ext : {".pcd", ".png", ".json"}) {
    EXPECT_TRUE(fs::exists(out / (std::string("learn0") + ext))) << ext;
    EXPECT_FALSE(fs::exists(out / (std::string("broken") + ext))) << ext;
  }
  EXPECT_GT(rows[1]["rss_mib"].get<double>(), 0);
  EXPECT_EQ(summary["parameters"]["voxels"]["voxel_size"], 0.02);
  // The batch segments each frame exactly as `segment` does.
  ASSERT_EQ(run("segment " + learn0() + " -o " + (out.parent_path() / "single").string()).code, 0);
  EXPECT_TRUE(slurp(out / "learn0.pcd") == slurp(out.parent_path() / "single.pcd"));
  // --outputs: only the label images.
  const fs::path labels = fresh("labels");
  EXPECT_EQ(
      run("segment --batch " + in.string() + " -o " + labels.string() + " --outputs labels").code,
      1);
  std::set<std::string> written;
  for (const auto& e : fs::directory_iterator(labels)) written.insert(e.path().filename());
  EXPECT_EQ(written,
            (std::set<std::string>{"learn0.instance.png", "learn0.label.png", "milk.instance.png",
                                   "milk.label.png", "summary.json", "summary.jsonl"}));
  EXPECT_EQ(proxseg::read_label_png((labels / "learn0.label.png").string()).values,
            proxseg::read_pcd((out / "learn0.pcd").string(), "label").label);
}

TEST(Batch, UsageAndInputErrors) {
  const fs::path in = real_dataset(2, 0), out = fresh("out");
  const std::string batch = "segment --batch " + in.string() + " -o " + out.string();
  EXPECT_EQ(run(batch + " --shard 0/3").code, 2);
  EXPECT_EQ(run(batch + " --shard 4/3").code, 2);
  EXPECT_EQ(run(batch + " --shard x").code, 2);
  EXPECT_EQ(run(batch + " --color c.png --depth d.png").code, 2);
  EXPECT_EQ(run(batch + " --outputs pcd,gif").code, 2);
  EXPECT_EQ(run("segment " + learn0() + " -o " + out.string() + "/x --resume").code, 2);
  EXPECT_EQ(run("segment --batch " + in.string() + " -o " + (in / "out").string()).code, 2);
  const CliRun r = run("segment --batch " + (in / "none").string() + " -o " + out.string());
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("none: no such file or folder"), std::string::npos) << r.err;
}

TEST(Batch, RecognizeBatchEqualsRecognizeFrameByFrame) {
  const fs::path db = fresh("db"), data = real_dataset(0, kYcb + 1), out = fresh("out");
  for (const char* name : {"009_gelatin_box", "025_mug", "061_foam_brick"}) {
    const CliRun r = run("db add " + db.string() + " --name " + name + " --xyz " + kData +
                         "/ycbv/models/" + name + "/points.xyz");
    ASSERT_EQ(r.code, 0) << r.err;
  }
  CliRun r = run("recognize --batch " + data.string() + " --db " + db.string() + " -o " +
                 out.string() + " --outputs all --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto summary = nlohmann::json::parse(r.out);
  EXPECT_EQ(summary["command"], "recognize");
  EXPECT_EQ(summary["frames_done"], kYcb + 1);
  for (const auto& row : proxseg::frame_rows(out.string())) {
    const std::string id = row["frame"];
    const fs::path base = data / id, single = out.parent_path() / "single" / id;
    r = run("recognize --color " + base.string() + "-color.png --depth " + base.string() +
            "-depth.png --meta " + base.string() + "-meta.json --db " + db.string() + " -o " +
            single.string() + " --outputs all");
    ASSERT_EQ(r.code, 0) << r.err;
    for (const char* ext : {".pcd", ".png", ".object.png"})
      EXPECT_TRUE(slurp(out / (id + ext)) == slurp(single.string() + ext)) << id << ext;
    EXPECT_EQ(timeless(nlohmann::json::parse(slurp(out / (id + ".json")))),
              timeless(nlohmann::json::parse(slurp(single.string() + ".json"))))
        << id;
    const auto report = nlohmann::json::parse(slurp(out / (id + ".json")));
    std::vector<std::string> names;
    for (const auto& c : report["candidates"]) names.push_back(c["name"]);
    EXPECT_EQ(row["objects"], names);
  }
  EXPECT_EQ(proxseg::read_label_png((out / "ycb" / "000001.object.png").string()).values,
            proxseg::read_pcd((out / "ycb" / "000001.pcd").string(), "object").label);
}
