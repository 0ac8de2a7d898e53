// A batch folder is owned by one set of settings (issue 54, point 7): a batch with other
// settings is refused before any work, even while the first runs; shards of one setting still
// run side by side; `proxseg summary` refuses a log of two settings; `--resume` redoes the frames
// whose input changed since its row (size, time) or whose row cannot tell; the settings' first
// difference names the parameter given (point 9).
#include <nlohmann/json.hpp>

#include <chrono>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "support/cli_util.hpp"

namespace {
using namespace cli_test;
using nlohmann::json;

fs::path dir() {
  return fs::path(PROXSEG_TEST_TMP) / "batch_owner" /
         ::testing::UnitTest::GetInstance()->current_test_info()->name();
}

// A fresh folder of this test's.
fs::path fresh(const std::string& name) {
  const fs::path d = dir() / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// `proxseg ARGS` with its output captured in files named by tag (runs may go side by side).
CliRun run(const std::string& args, const std::string& tag = "run") {
  const std::string out = (dir() / (tag + ".stdout")).string(),
                    err = (dir() / (tag + ".stderr")).string();
  const int status = std::system((kCli + " " + args + " >" + out + " 2>" + err).c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(out), slurp(err)};
}

// Two runs started together.
std::pair<CliRun, CliRun> run_together(const std::string& a, const std::string& b) {
  CliRun ra, rb;
  std::thread ta([&] { ra = run(a, "a"); });
  std::thread tb([&] { rb = run(b, "b"); });
  ta.join();
  tb.join();
  return {ra, rb};
}

// A folder of mOSD learn frames copied (not linked: tests replace them) as NAME.pcd.
fs::path frames(const std::vector<std::pair<std::string, int>>& names) {
  const fs::path in = fresh("in");
  for (const auto& [name, k] : names)
    fs::copy_file(kData + "/mosd/learn/learn" + std::to_string(k) + ".pcd", in / (name + ".pcd"));
  return in;
}

std::vector<json> lines(const fs::path& log) {
  std::vector<json> out;
  std::istringstream in(slurp(log));
  for (std::string line; std::getline(in, line);) out.push_back(json::parse(line));
  return out;
}

// How many rows each frame has in a log.
std::map<std::string, int> rows_per_frame(const fs::path& log) {
  std::map<std::string, int> n;
  for (const json& j : lines(log))
    if (j.contains("frame")) ++n[j["frame"].get<std::string>()];
  return n;
}

// Every frame report in out (the batch's own summaries aside).
std::vector<json> reports(const fs::path& out) {
  std::vector<json> r;
  for (const auto& e : fs::directory_iterator(out))
    if (e.path().extension() == ".json" && e.path().filename().string().rfind("summary", 0) != 0)
      r.push_back(json::parse(slurp(e.path())));
  return r;
}

bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

}  // namespace

// The case: `--preset paper` and `--shard 1/2` (default settings) into one folder at once.
TEST(BatchOwner, OtherSettingsAreRefusedBeforeAnyWorkEvenWhileTheFirstRuns) {
  const fs::path in = frames({{"a", 0}, {"b", 1}}), out = fresh("out");
  const std::string paper = "segment --batch " + in.string() + " -o " + out.string() +
                            " --outputs json --preset paper",
                    shard = "segment --batch " + in.string() + " -o " + out.string() +
                            " --outputs json --shard 1/2";
  const auto [ra, rb] = run_together(paper, shard);
  ASSERT_TRUE((ra.code == 0 && rb.code == 1) || (ra.code == 1 && rb.code == 0))
      << "paper: " << ra.code << " " << ra.err << "\nshard: " << rb.code << " " << rb.err;
  const bool paper_won = ra.code == 0;
  const CliRun& lost = paper_won ? rb : ra;
  EXPECT_TRUE(has(lost.err, "other settings") && has(lost.err, "parameters/") &&
              has(lost.err, "another -o folder"))
      << lost.err;
  EXPECT_EQ(std::count(lost.err.begin(), lost.err.end(), '\n'), 1) << lost.err;
  // The refused run wrote nothing: no log, and every report holds the winner's parameters.
  const std::string won_log = paper_won ? "summary" : "summary.shard-1-of-2";
  EXPECT_FALSE(fs::exists(out / (paper_won ? "summary.shard-1-of-2.jsonl" : "summary.jsonl")));
  const json won = json::parse(slurp(out / (won_log + ".json")));
  const std::vector<json> written = reports(out);
  EXPECT_EQ(written.size(), won["frames_done"].get<std::size_t>());
  for (const json& report : written) EXPECT_EQ(report["parameters"], won["parameters"]);
  // After the winner, the other settings are still refused.
  const CliRun again = run(paper_won ? shard : paper);
  EXPECT_EQ(again.code, 1) << again.err;
  EXPECT_TRUE(has(again.err, "other settings")) << again.err;
}

TEST(BatchOwner, ShardsOfOneSettingRunSideBySideAsOneRun) {
  const fs::path in = frames({{"a", 0}, {"b", 1}, {"c", 2}, {"d", 3}});
  const fs::path one = fresh("one"), two = fresh("two");
  const std::string args = "segment --batch " + in.string() + " --outputs labels --threads 1 -o ";
  ASSERT_EQ(run(args + one.string()).code, 0);
  const auto [r1, r2] =
      run_together(args + two.string() + " --shard 1/2", args + two.string() + " --shard 2/2");
  ASSERT_EQ(r1.code, 0) << r1.err;
  ASSERT_EQ(r2.code, 0) << r2.err;
  for (const char* f : {"a", "b", "c", "d"})
    for (const char* kind : {".label.png", ".instance.png"})
      EXPECT_TRUE(slurp(one / (std::string(f) + kind)) == slurp(two / (std::string(f) + kind)))
          << f << kind;
  const CliRun s = run("summary " + two.string() + " --json");
  ASSERT_EQ(s.code, 0) << s.err;
  EXPECT_EQ(json::parse(s.out)["frames_done"], 4);
}

TEST(BatchOwner, SummaryRefusesALogOfTwoSettings) {
  const fs::path in = frames({{"a", 0}}), o1 = fresh("o1"), o2 = fresh("o2");
  const std::string args = "segment --batch " + in.string() + " --outputs json -o ";
  ASSERT_EQ(run(args + o1.string()).code, 0);
  ASSERT_EQ(run(args + o2.string() + " --voxel-size 0.01").code, 0);
  const std::string first = slurp(o1 / "summary.jsonl");
  // Two runs' lines in one log: the second header's settings differ.
  std::ofstream(o1 / "summary.jsonl", std::ios::binary) << first << slurp(o2 / "summary.jsonl");
  CliRun r = run("summary " + o1.string());
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_TRUE(has(r.err, "summary.jsonl") && has(r.err, "voxel_size")) << r.err;
  // One row whose fingerprint is not its header's.
  std::vector<json> log = lines(o2 / "summary.jsonl");
  std::string text;
  for (json& j : log) {
    if (j.contains("frame")) j["fingerprint"] = "0123456789abcdef";
    text += j.dump() + "\n";
  }
  std::ofstream(o2 / "summary.jsonl", std::ios::binary) << text;
  r = run("summary " + o2.string());
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_TRUE(has(r.err, "summary.jsonl:2") && has(r.err, "0123456789abcdef")) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

TEST(BatchOwner, ResumeRedoesTheFramesWhoseInputChanged) {
  const fs::path in = frames({{"a", 0}, {"b", 1}, {"c", 2}, {"d", 3}}), out = fresh("out");
  const std::string args =
      "segment --batch " + in.string() + " -o " + out.string() + " --outputs json --threads 1";
  ASSERT_EQ(run(args).code, 0);
  const json b_before = json::parse(slurp(out / "b.json"));
  // b: another frame (another size); c: the same bytes written again (a newer time).
  fs::copy_file(kData + "/mosd/learn/learn4.pcd", in / "b.pcd",
                fs::copy_options::overwrite_existing);
  const std::string c = slurp(in / "c.pcd");
  std::ofstream(in / "c.pcd", std::ios::binary) << c;
  fs::last_write_time(in / "c.pcd", fs::last_write_time(in / "c.pcd") + std::chrono::seconds(2));
  // a: its row as an older proxseg wrote it, without its inputs' size, time and fingerprint.
  std::string text;
  for (json j : lines(out / "summary.jsonl")) {
    if (j.value("frame", "") == "a")
      for (const char* key : {"input_sizes", "input_mtimes_ns", "fingerprint"}) j.erase(key);
    text += j.dump() + "\n";
  }
  std::ofstream(out / "summary.jsonl", std::ios::binary) << text;
  const CliRun r = run(args + " --resume");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(rows_per_frame(out / "summary.jsonl"),
            (std::map<std::string, int>{{"a", 2}, {"b", 2}, {"c", 2}, {"d", 1}}))
      << r.err;
  EXPECT_TRUE(has(r.err, "1 frame logged without")) << r.err;
  EXPECT_TRUE(has(r.err, "2 frames whose input changed")) << r.err;
  // Done again, b's report is the new input's.
  EXPECT_NE(json::parse(slurp(out / "b.json"))["input"]["valid_points"],
            b_before["input"]["valid_points"]);
  // Nothing changed since: nothing is done again.
  ASSERT_EQ(run(args + " --resume").code, 0);
  EXPECT_EQ(rows_per_frame(out / "summary.jsonl")["d"], 1);
  EXPECT_EQ(rows_per_frame(out / "summary.jsonl")["b"], 2);
}

// --voxel-size (like every flag of stages 2-4) turns the paper's labels on: the difference to
// name is voxel_size, the one given; paper_labels only when nothing else differs, said why.
TEST(BatchOwner, SettingsDifferenceNamesTheParameterGiven) {
  const fs::path in = frames({{"a", 0}, {"b", 1}}), out = fresh("out");
  const std::string args =
      "segment --batch " + in.string() + " -o " + out.string() + " --outputs json";
  ASSERT_EQ(run(args + " --shard 1/2").code, 0);
  for (const std::string more : {" --shard 1/2 --resume", " --shard 2/2"}) {
    const CliRun r = run(args + more + " --voxel-size 0.01");
    EXPECT_EQ(r.code, 1) << more;
    EXPECT_TRUE(has(r.err, "parameters/voxels/voxel_size (0.02 in that batch, 0.01 in this run)"))
        << more << ": " << r.err;
    EXPECT_FALSE(has(r.err, "paper_labels")) << more << ": " << r.err;
  }
  // The default voxel size given: only paper_labels differs, and the message says why.
  const CliRun r = run(args + " --shard 1/2 --resume --voxel-size 0.02");
  EXPECT_EQ(r.code, 1);
  EXPECT_TRUE(has(r.err, "parameters/paper_labels") && has(r.err, "--voxel-size")) << r.err;
}
