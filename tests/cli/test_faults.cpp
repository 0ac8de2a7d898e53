// An unfriendly environment, as docs/robustness.md ("Faults") lists it: memory running out,
// special files where inputs should be, batch frames named like the batch's own files, links that
// lead nowhere, damaged summary logs. Every run goes through the CLI under a time limit (a hang
// fails the test instead of stopping the suite), and must end with exit 0 or 1 and a message,
// never a signal.
#include <proxseg/io/cloud_io.hpp>

#include <sys/stat.h>
#include <unistd.h>

#include <nlohmann/json.hpp>
#include <set>

#include "support/cli_util.hpp"
#include "support/frame_window.hpp"
#include "support/fresh_dir.hpp"

namespace {
using namespace cli_test;
const fs::path kTmp = fs::path(PROXSEG_TEST_TMP) / "faults";

std::string test_name() {
  return ::testing::UnitTest::GetInstance()->current_test_info()->name();
}

// A fresh folder for this test, removed when its process ends.
fs::path fresh(const std::string& name) {
  return proxseg::test::fresh_dir("faults-" + test_name() + "-" + name);
}

#ifdef PROXSEG_SANITIZE
constexpr int kLimitSeconds = 300;  // the sanitizer build is several times slower
#else
constexpr int kLimitSeconds = 60;
#endif

// `proxseg ARGS` killed after kLimitSeconds (exit code -1 then: a hang is a failure), with a
// shell prefix (e.g. "ulimit -v N;") run first in the same shell.
CliRun run(const std::string& args, const std::string& before = "") {
  const std::string limit = "timeout -s KILL " + std::to_string(kLimitSeconds) + " ";
  CliRun r = run_in(kTmp / test_name(), args, before + limit + kCli);
  if (r.code == 137) r.code = -1;  // killed by the time limit
  return r;
}

// A crop of mOSD learn0 (rows r0.., columns c0.., w x h): a small real frame that segments fast.
std::string crop(const fs::path& at, int c0, int r0, int w, int h) {
  proxseg::Frame f = proxseg::test::frame_window(proxseg::read_pcd(learn0()), r0, c0, h, w);
  f.label.clear();  // points and colours only
  fs::create_directories(at.parent_path());
  proxseg::write_pcd(at.string(), f, {});
  return at.string();
}

// Exit 1 with one line naming `name` and saying `what`, quickly (not killed by the limit).
void expect_refused(const CliRun& r, const std::string& name, const std::string& what) {
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find(name), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(what), std::string::npos) << r.err;
}

std::vector<nlohmann::json> log_lines(const fs::path& log) {
  std::vector<nlohmann::json> lines;
  std::ifstream in(log);
  for (std::string line; std::getline(in, line);)
    lines.push_back(nlohmann::json::parse(line, nullptr, false));
  return lines;
}

}  // namespace

// A FIFO or a link to /dev/zero as the cloud, a FIFO as --config or --intrinsics: refused at
// once (no hang, no endless read), naming the file and what it is.
TEST(Faults, SpecialFilesAreRefused) {
  const fs::path dir = fresh("in");
  const fs::path o = dir / "out";
  ASSERT_EQ(::mkfifo((dir / "f.pcd").c_str(), 0600), 0);
  expect_refused(run("segment " + (dir / "f.pcd").string() + " -o " + o.string()), "f.pcd",
                 "is a FIFO");
  fs::create_symlink("/dev/zero", dir / "z.pcd");
  expect_refused(run("segment " + (dir / "z.pcd").string() + " -o " + o.string()), "z.pcd",
                 "is a character device");
  fs::create_directories(dir / "d.pcd");
  expect_refused(run("segment " + (dir / "d.pcd").string() + " -o " + o.string()), "d.pcd",
                 "is a directory");
  ASSERT_EQ(::mkfifo((dir / "config.json").c_str(), 0600), 0);
  expect_refused(run("segment " + learn0() + " --config " + (dir / "config.json").string() +
                     " -o " + o.string()),
                 "config.json", "is a FIFO");
  ASSERT_EQ(::mkfifo((dir / "k.json").c_str(), 0600), 0);
  const std::string base = kData + "/ycbv/frames/000001";
  expect_refused(run("segment --color " + base + "-color.png --depth " + base +
                     "-depth.png --intrinsics " + (dir / "k.json").string() + " -o " + o.string()),
                 "k.json", "is a FIFO");
  expect_refused(run("segment --color " + (dir / "f.pcd").string() + " --depth " + base +
                     "-depth.png --meta " + base + "-meta.json -o " + o.string()),
                 "f.pcd", "is a FIFO");
  for (const char* ext : {".pcd", ".png", ".json"}) EXPECT_FALSE(fs::exists(o.string() + ext));
}

// POINTS beyond 2^31 - 1: says that it is too large, not that it is no integer.
TEST(Faults, PointCountsBeyondTheLimitAreCalledTooLarge) {
  const fs::path dir = fresh("in");
  std::ofstream(dir / "big.pcd") << "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 "
                                    "1\nWIDTH 2147483648\nHEIGHT 1\nPOINTS 2147483648\nDATA "
                                    "binary\n";
  expect_refused(run("segment " + (dir / "big.pcd").string() + " -o " + (dir / "out").string()),
                 "big.pcd", "WIDTH 2147483648 is too large");
}

// AddressSanitizer reserves terabytes of address space for its shadow: it cannot run under an
// address-space limit.
#ifdef PROXSEG_SANITIZE
#define SKIP_UNDER_SANITIZER() GTEST_SKIP() << "ulimit -v and AddressSanitizer do not mix"
#else
#define SKIP_UNDER_SANITIZER() (void)0
#endif

// A binary PCD far longer than its header promises is read only as far as the header says.
TEST(Faults, ReadingStopsWhereTheHeaderSays) {
  SKIP_UNDER_SANITIZER();
  const fs::path dir = fresh("in");
  const std::string small = crop(dir / "small.pcd", 200, 150, 40, 30);
  // 200 MB of zeros after the data: reading it all would take far longer than segmenting.
  ASSERT_EQ(::truncate(small.c_str(), static_cast<off_t>(fs::file_size(small)) + (200 << 20)), 0);
  const CliRun r = run("segment " + small + " -o " + (dir / "out").string(), "ulimit -v 400000; ");
  EXPECT_EQ(r.code, 0) << r.err;
}

// A frame named summary.pcd (and summary.shard-1-of-2.pcd) in a batch: its outputs do not take
// the batch's summary names, the summary counts both frames, and --resume redoes nothing.
TEST(Faults, BatchFramesNamedLikeTheSummaryKeepTheirOutputs) {
  const fs::path data = fresh("data"), out = kTmp / test_name() / "out";
  fs::remove_all(out);
  crop(data / "summary.pcd", 200, 150, 40, 30);
  crop(data / "summary.shard-1-of-2.pcd", 240, 150, 40, 30);
  crop(data / "plain.pcd", 280, 150, 40, 30);
  CliRun r = run("segment --batch " + data.string() + " -o " + out.string() + " --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json summary = nlohmann::json::parse(r.out);
  EXPECT_EQ(summary["frames_done"], 3);
  EXPECT_EQ(nlohmann::json::parse(cli_test::slurp(out / "summary.json")), summary);
  for (const char* stem : {"summary-frame", "summary.shard-1-of-2-frame", "plain"})
    for (const char* ext : {".pcd", ".png", ".json"})
      EXPECT_TRUE(fs::exists(out / (std::string(stem) + ext))) << stem << ext;
  r = run("segment --batch " + data.string() + " -o " + out.string() + " --resume");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("3 done before"), std::string::npos) << r.err;
  // A frame already named like a renamed one: refused before any work.
  crop(data / "summary-frame.pcd", 320, 150, 40, 30);
  r = run("segment --batch " + data.string() + " -o " + (out.string() + "2"));
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("would both write"), std::string::npos) << r.err;
}

// A link loop, a dangling link, a FIFO named like a frame and an unreadable folder in a batch
// folder: each a failed row naming it, the other frames done, the summary written (exit 1).
TEST(Faults, UnreadableEntriesOfABatchFolderAreFailedRows) {
  const fs::path data = fresh("data"), out = kTmp / test_name() / "out";
  fs::remove_all(out);
  crop(data / "a.pcd", 200, 150, 40, 30);
  crop(data / "deep" / "b.pcd", 240, 150, 40, 30);
  fs::create_symlink("loop", data / "loop");
  fs::create_symlink("nowhere.pcd", data / "gone.pcd");
  ASSERT_EQ(::mkfifo((data / "pipe.pcd").c_str(), 0600), 0);
  ASSERT_EQ(::mkfifo((data / "notes.txt").c_str(), 0600), 0);  // not a frame: ignored
  const bool root = ::geteuid() == 0;                          // root reads through permissions
  if (!root) {
    crop(data / "locked" / "c.pcd", 280, 150, 40, 30);
    fs::permissions(data / "locked", fs::perms::none);
  }
  const CliRun r = run("segment --batch " + data.string() + " -o " + out.string() + " --json");
  if (!root) fs::permissions(data / "locked", fs::perms::owner_all);
  EXPECT_EQ(r.code, 1) << r.err;
  const nlohmann::json summary = nlohmann::json::parse(r.out);
  EXPECT_EQ(summary["frames_done"], 2);
  std::map<std::string, std::string> failed;
  for (const auto& row : summary["failed"]) failed[row["frame"]] = row["error"];
  ASSERT_EQ(failed.size(), root ? 3u : 4u) << summary.dump(2);
  EXPECT_NE(failed["loop"].find("symbolic link loop"), std::string::npos) << failed["loop"];
  EXPECT_NE(failed["gone"].find("dangling symbolic link"), std::string::npos) << failed["gone"];
  EXPECT_NE(failed["pipe"].find("is a FIFO"), std::string::npos) << failed["pipe"];
  if (!root) {
    EXPECT_NE(failed["locked"].find("cannot read the folder"), std::string::npos)
        << failed["locked"];
  }
  EXPECT_TRUE(fs::exists(out / "summary.json"));
}

// Entries of a list file that are no files say what they are.
TEST(Faults, ListFileEntriesSayWhatTheyAre) {
  const fs::path data = fresh("data");
  crop(data / "a.pcd", 200, 150, 40, 30);
  fs::create_directories(data / "folder");
  ASSERT_EQ(::mkfifo((data / "pipe").c_str(), 0600), 0);
  fs::create_symlink("loop", data / "loop");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"folder", "is a directory"},
      {"pipe", "is a FIFO"},
      {"loop", "symbolic link loop"},
      {"missing.pcd", "file not found"}};
  for (const auto& [entry, what] : cases) {
    std::ofstream(data / "list.txt") << "a.pcd\n" << entry << "\n";
    const CliRun r = run("segment --batch " + (data / "list.txt").string() + " -o " +
                         (kTmp / test_name() / "out").string());
    expect_refused(r, "list.txt:2: " + entry, what);
  }
}

// A garbage line and a row of the wrong types in the middle of summary.jsonl: --resume names
// both (file and line), skips them, redoes only the frame whose row was damaged, and `proxseg
// summary` says the same; nothing fails on the types.
TEST(Faults, DamagedSummaryLinesAreReportedSkippedAndTheirFramesRedone) {
  const fs::path data = fresh("data"), out = kTmp / test_name() / "out";
  fs::remove_all(out);
  for (int i = 0; i < 6; ++i) crop(data / ("f" + std::to_string(i) + ".pcd"), 40 * i, 150, 40, 30);
  CliRun r = run("segment --batch " + data.string() + " -o " + out.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const fs::path log = out / "summary.jsonl";
  std::vector<std::string> lines;
  {
    std::ifstream in(log);
    for (std::string line; std::getline(in, line);) lines.push_back(line);
  }
  ASSERT_EQ(lines.size(), 8u);  // header, 6 frames, end
  // Line 3 (a frame's row; frames finish in any order) cut in half; then a row whose frame is a
  // number.
  const std::string cut = nlohmann::json::parse(lines[2])["frame"];
  lines[2] = lines[2].substr(0, lines[2].size() / 2);
  lines.insert(lines.begin() + 5, R"({"frame":5})");
  // And a 4 MB line whose frame name never ends (read without recursing per character).
  lines.insert(lines.begin() + 6, R"({"frame":")" + std::string(4 << 20, 'a'));
  {
    std::ofstream o(log, std::ios::trunc);
    for (const auto& l : lines) o << l << "\n";
  }
  r = run("summary " + out.string() + " --json");
  EXPECT_EQ(r.code, 1) << r.err;  // a frame is missing now
  EXPECT_NE(r.err.find("summary.jsonl:3: damaged line (not JSON); skipped, frame " + cut +
                       " is done again"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("summary.jsonl:6: damaged line (\"frame\" is not a string); skipped"),
            std::string::npos)
      << r.err;
  const nlohmann::json merged = nlohmann::json::parse(r.out);
  EXPECT_EQ(merged["frames_done"], 5);
  EXPECT_EQ(merged["frames_missing"], 1);
  EXPECT_EQ(merged["damaged_lines"].size(), 3u);
  EXPECT_NE(r.err.find("summary.jsonl:7: damaged line (not JSON); skipped\n"), std::string::npos);

  r = run("segment --batch " + data.string() + " -o " + out.string() + " --resume --json");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("summary.jsonl:3"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("5 done before"), std::string::npos) << r.err;
  const nlohmann::json summary = nlohmann::json::parse(r.out);
  EXPECT_EQ(summary["frames_done"], 6);
  // The second run's rows: the frame whose row was cut, only.
  std::vector<std::string> redone;
  int headers = 0;
  for (const auto& line : log_lines(log)) {
    if (line.is_discarded()) continue;
    headers += line.contains("header");
    if (headers == 2 && line.contains("frame") && line["frame"].is_string())
      redone.push_back(line["frame"]);
  }
  EXPECT_EQ(redone, std::vector<std::string>{cut});
}

// Memory exhausted (an address-space limit) while segmenting one frame, at limits from where the
// program cannot even start to where it has room: exit 0 or 1 with a message, never a signal.
TEST(Faults, OutOfMemoryIsAnErrorNamingTheFrame) {
  SKIP_UNDER_SANITIZER();
  const fs::path out = kTmp / test_name() / "out";
  std::set<int> codes;
  for (const int mib : {60, 90, 120, 160, 200, 300}) {
    for (const std::string flags : {"", " --paper-labels --threads 4"}) {
      const CliRun r = run("segment " + learn0() + flags + " -o " + out.string(),
                           "ulimit -v " + std::to_string(mib * 1024) + "; ");
      EXPECT_TRUE(r.code == 0 || r.code == 1) << mib << " MiB" << flags << ": " << r.code << r.err;
      // Out of memory names the frame; below what the program needs to start, the bare message.
      if (r.code == 1 && r.err.find("proxseg: error: out of memory\n") == std::string::npos) {
        EXPECT_NE(r.err.find("proxseg: error: " + learn0() + ": "), std::string::npos) << r.err;
      }
      codes.insert(r.code);
    }
  }
  EXPECT_EQ(codes, (std::set<int>{0, 1}));  // the sweep reaches both
}

// In a batch, a frame that runs out of memory is a failed row; the others are done.
TEST(Faults, OutOfMemoryInABatchIsAFailedRow) {
  SKIP_UNDER_SANITIZER();
  const fs::path data = fresh("data"), out = kTmp / test_name() / "out";
  fs::remove_all(out);
  crop(data / "a.pcd", 200, 150, 40, 30);
  fs::create_symlink(learn0(), data / "big.pcd");
  crop(data / "c.pcd", 280, 150, 40, 30);
  const CliRun r =
      run("segment --batch " + data.string() + " --paper-labels -o " + out.string() + " --json",
          "ulimit -v 150000; ");
  ASSERT_TRUE(r.code == 0 || r.code == 1) << r.code << r.err;
  const nlohmann::json summary = nlohmann::json::parse(r.out);
  EXPECT_GE(summary["frames_done"].get<int>(), 2);
  for (const auto& row : summary["failed"])
    EXPECT_NE(row["error"].get<std::string>().find("out of memory"), std::string::npos) << row;
  EXPECT_TRUE(fs::exists(out / "summary.json"));
}

// --max-memory: a frame whose estimate is above it is refused before it starts (exit 1, naming
// it); in a batch it is a failed row and the smaller frames are done.
TEST(Faults, MaxMemoryRefusesAFrameBeforeItStarts) {
  const fs::path data = fresh("data"), out = kTmp / test_name() / "out";
  fs::remove_all(out);
  for (const char* ext : {".pcd", ".png", ".json"}) fs::remove(out.string() + "-one" + ext);
  CliRun r = run("segment " + learn0() + " --max-memory 40 -o " + out.string() + "-one");
  expect_refused(r, "learn0.pcd", "MiB to segment (estimated), more than max_memory_mib 40");
  EXPECT_FALSE(fs::exists(out.string() + "-one.json"));
  r = run("segment " + learn0() + " --max-memory 400 -o " + out.string() + "-one");
  EXPECT_EQ(r.code, 0) << r.err;
  crop(data / "a.pcd", 200, 150, 40, 30);
  fs::create_symlink(learn0(), data / "big.pcd");
  r = run("segment --batch " + data.string() + " --max-memory 40 -o " + out.string() + " --json");
  EXPECT_EQ(r.code, 1) << r.err;
  const nlohmann::json summary = nlohmann::json::parse(r.out);
  EXPECT_EQ(summary["frames_done"], 1);
  ASSERT_EQ(summary["failed"].size(), 1u);
  EXPECT_NE(summary["failed"][0]["error"].get<std::string>().find("refused before starting"),
            std::string::npos);
  r = run("segment " + learn0() + " --max-memory -1 -o " + out.string());
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("max_memory_mib"), std::string::npos) << r.err;
}
