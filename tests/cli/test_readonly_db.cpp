// Reading a model database without write access (issue 54, docs/database.md "Readers"): another
// user, a read-only file or folder, a read-only mount. Readers open the file read-only and, where
// they may not write beside it, as immutable: they read it and leave no file behind. A -wal that
// holds changes is read, or refused with its name, never ignored.
#include <sys/stat.h>
#include <unistd.h>

#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "support/cli_util.hpp"

namespace {
using namespace cli_test;

const std::string kMilk = kData + "/pcl/milk.pcd";

bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// `sh -c SCRIPT`, its output captured beside the script in `dir` (which the script may not write:
// the captures go to a folder of root's).
CliRun sh(const fs::path& dir, const std::string& script) {
  const std::string name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
  const fs::path cap = fs::path(PROXSEG_TEST_TMP) / "readonly_db" / name;
  fs::create_directories(cap);
  std::ofstream(cap / "script.sh") << "cd '" << dir.string() << "' && " << script << "\n";
  const std::string out = (cap / "out.txt").string(), err = (cap / "err.txt").string();
  const int status =
      std::system(("sh " + (cap / "script.sh").string() + " >" + out + " 2>" + err).c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(out), slurp(err)};
}

std::set<std::string> names_in(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
  return names;
}

// A folder anyone may enter, under the system's temporary folder (the build tree may be where
// another user cannot go: a clone under /root), holding `proxseg`, `proxseg-tools`, the
// libraries of the build tree they load (bin/), the frame milk.pcd and the database db/ of one
// view of it, made by root. Removed by the destructor.
struct World {
  fs::path dir;
  World() {
    std::string tmpl = (fs::temp_directory_path() / "proxseg-readonly-XXXXXX").string();
    dir = ::mkdtemp(tmpl.data()) ? fs::path(tmpl) : fs::path();
    if (dir.empty()) return;
    ::chmod(dir.c_str(), 0755);
    fs::create_directories(dir / "bin");
    const fs::path build = fs::path(kCli).parent_path();
    for (const char* exe : {"proxseg", "proxseg-tools"}) {
      fs::copy_file(build / exe, dir / "bin" / exe);
      // The libraries it loads from outside the system's folders (the build tree's).
      const CliRun ldd = sh(dir, "ldd '" + (build / exe).string() + "'");
      std::istringstream lines(ldd.out);
      for (std::string line; std::getline(lines, line);) {
        const auto arrow = line.find("=> /");
        if (arrow == std::string::npos) continue;
        const std::string lib = line.substr(arrow + 3, line.find(" (", arrow) - arrow - 3);
        if (lib.rfind("/lib", 0) == 0 || lib.rfind("/usr/", 0) == 0) continue;
        std::error_code ec;
        fs::copy_file(lib, dir / "bin" / fs::path(lib).filename(), fs::copy_options::skip_existing,
                      ec);
      }
    }
    fs::copy_file(kMilk, dir / "milk.pcd");
    ::chmod((dir / "milk.pcd").c_str(), 0644);
    const CliRun add = sh(dir, proxseg() + " db add db --name milk milk.pcd -q");
    EXPECT_EQ(add.code, 0) << add.err;
  }
  ~World() {
    if (!dir.empty()) {
      ::chmod((dir / "db").c_str(), 0755);  // remove_all must enter it
      fs::remove_all(dir);
    }
  }
  std::string proxseg() const {
    return "env LD_LIBRARY_PATH='" + (dir / "bin").string() + "' '" +
           (dir / "bin/proxseg").string() + "'";
  }
};

// The reads a user without write access makes: info, check, list as JSON and a recognition.
void expect_reads(const World& w, const std::string& as, const fs::path& db) {
  const std::string p = as + w.proxseg();
  CliRun r = sh(w.dir, p + " db info '" + db.string() + "' --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json info = nlohmann::json::parse(r.out);
  EXPECT_EQ(info["views"], 1) << r.out;
  r = sh(w.dir, p + " db check '" + db.string() + "'");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(has(r.out, ": 1 of 1 view whole")) << r.out;
  r = sh(w.dir, p + " recognize -q --db '" + db.string() + "' --object milk.pcd -o -");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json report = nlohmann::json::parse(r.out);
  ASSERT_EQ(report["candidates"].size(), 1u) << r.out.substr(0, 400);
  EXPECT_EQ(report["candidates"][0]["best"]["name"], "milk");
}

bool can_runuser() {
  return ::geteuid() == 0 && std::system("runuser -u nobody -- true 2>/dev/null") == 0;
}

TEST(ReadOnlyDb, AnotherUserReadsItAndLeavesNothing) {
  if (!can_runuser()) GTEST_SKIP() << "needs root and runuser (to read as the user nobody)";
  World w;
  ASSERT_FALSE(w.dir.empty());
  ::chmod((w.dir / "db").c_str(), 0755);
  ::chmod((w.dir / "db/database.sqlite").c_str(), 0644);
  const std::set<std::string> before = names_in(w.dir / "db");
  ASSERT_EQ(before, std::set<std::string>{"database.sqlite"});
  expect_reads(w, "runuser -u nobody -- ", w.dir / "db");
  EXPECT_EQ(names_in(w.dir / "db"), before);
  // Writing is refused with what is wrong, and changes nothing.
  const CliRun r =
      sh(w.dir, "runuser -u nobody -- " + w.proxseg() + " db add db --name m milk.pcd");
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_TRUE(has(r.err, "database.sqlite")) << r.err;
  EXPECT_EQ(names_in(w.dir / "db"), before);
}

TEST(ReadOnlyDb, AFileItMayNotReadIsSaidSo) {
  if (!can_runuser()) GTEST_SKIP() << "needs root and runuser (to read as the user nobody)";
  World w;
  ASSERT_FALSE(w.dir.empty());
  ::chmod((w.dir / "db/database.sqlite").c_str(), 0600);
  for (const char* cmd : {"check", "info"}) {
    SCOPED_TRACE(cmd);
    const CliRun r = sh(w.dir, "runuser -u nobody -- " + w.proxseg() + " db " + cmd + " db");
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_TRUE(has(r.err, "database.sqlite")) << r.err;
    EXPECT_TRUE(has(r.err, "Permission denied")) << r.err;
    EXPECT_FALSE(has(r.err, "see proxseg db check")) << r.err;
  }
}

// A user's own database made read-only (0444) in its own folder: read without a -wal or -shm
// left beside it (they would keep the file's mode 0444, and a later writer could not use them).
// Root may write anything, but a file and a folder without write permission for anyone are
// read as they are too.
TEST(ReadOnlyDb, AReadOnlyFileGetsNothingBeside) {
  World w;
  ASSERT_FALSE(w.dir.empty());
  const fs::path db = w.dir / "db";
  ::chmod((db / "database.sqlite").c_str(), 0444);
  ::chmod(db.c_str(), 0555);
  const std::set<std::string> before = names_in(db);
  expect_reads(w, "", db);
  EXPECT_EQ(names_in(db), before);
  if (!can_runuser()) GTEST_SKIP() << "needs root and runuser (to read as the user nobody)";
  ::chmod(db.c_str(), 0755);
  ASSERT_EQ(std::system(("chown -R nobody '" + db.string() + "'").c_str()), 0);
  expect_reads(w, "runuser -u nobody -- ", db);
  EXPECT_EQ(names_in(db), before);
  // Made writable again, it takes a view.
  ::chmod((db / "database.sqlite").c_str(), 0644);
  const CliRun r =
      sh(w.dir, "runuser -u nobody -- " + w.proxseg() + " db add db --name m milk.pcd");
  EXPECT_EQ(r.code, 0) << r.err;
}

// A read-only mount (a private mount namespace: nothing outlives the test).
TEST(ReadOnlyDb, AReadOnlyMountIsRead) {
  if (::geteuid() != 0 || std::system("unshare -m true 2>/dev/null") != 0)
    GTEST_SKIP() << "needs root and unshare -m (for a read-only bind mount)";
  World w;
  ASSERT_FALSE(w.dir.empty());
  fs::create_directories(w.dir / "ro");
  const std::set<std::string> before = names_in(w.dir / "db");
  const std::string mount = "mount --bind -o ro db ro && ";
  const CliRun probe = sh(w.dir, "unshare -m sh -c '" + mount + "true'");
  if (probe.code != 0) GTEST_SKIP() << "mount --bind -o ro refused here: " << probe.err;
  const std::pair<std::string, std::string> cases[] = {
      {"db info ro --json", "\"views\": 1"},
      {"db check ro", "1 of 1 view whole"},
      {"recognize -q --db ro --object milk.pcd -o -", "\"name\": \"milk\""}};
  for (const auto& [cmd, says] : cases) {
    SCOPED_TRACE(cmd);
    const CliRun r = sh(w.dir, "unshare -m sh -c \"" + mount + w.proxseg() + " " + cmd + "\"");
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(has(r.out, says)) << r.out.substr(0, 300);
  }
  EXPECT_EQ(names_in(w.dir / "db"), before);
}

}  // namespace
