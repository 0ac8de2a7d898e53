// Names that are not UTF-8 (issue 54): bytes until shown, and shown in JSON with their bad bytes
// as \xFF-style text. A batch with such a frame finishes, writes its summary and resumes.
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "support/cli_util.hpp"

namespace {
using namespace cli_test;
const fs::path kTmp = fs::path(PROXSEG_TEST_TMP) / "names";
CliRun run(const std::string& args) {
  return run_in(kTmp, args);
}

// The frame rows of a summary log, each line parsed (a line that is not JSON fails the test).
std::vector<nlohmann::json> frame_rows(const fs::path& log) {
  std::vector<nlohmann::json> rows;
  std::istringstream in(slurp(log));
  for (std::string line; std::getline(in, line);) {
    const nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
    EXPECT_FALSE(j.is_discarded()) << line;
    if (j.is_object() && j.contains("frame")) rows.push_back(j);
  }
  return rows;
}

TEST(Names, BatchWithFramesNotUtf8FinishesAndResumes) {
  const fs::path in = kTmp / "batch-in", out = kTmp / "batch-out";
  fs::remove_all(in);
  fs::remove_all(out);
  fs::create_directories(in);
  for (const std::string name : {"a", "bad\xff", "bad\xfe", "z"})
    fs::copy_file(learn0(), in / (name + ".pcd"));
  const std::string args =
      "segment --batch " + in.string() + " -o " + out.string() + " --outputs json";
  CliRun r = run(args);
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json summary = nlohmann::json::parse(slurp(out / "summary.json"));
  EXPECT_EQ(summary["frames_done"], 4) << summary.dump(2);
  EXPECT_EQ(summary["frames_failed"], 0);
  std::set<std::string> names;
  for (const auto& row : frame_rows(out / "summary.jsonl")) names.insert(row["frame"]);
  // Two bad names stay two (no U+FFFD for both), shown as \xFF text.
  EXPECT_EQ(names, (std::set<std::string>{"a", "bad\\xFF", "bad\\xFE", "z"}));
  EXPECT_TRUE(fs::exists(out / "bad\xff.json"));
  EXPECT_TRUE(nlohmann::json::accept(slurp(out / "bad\xff.json")));  // its report is JSON too
  // --resume finds them all finished: no frame is done again.
  r = run(args + " --resume");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(frame_rows(out / "summary.jsonl").size(), 4u) << r.err;
  EXPECT_EQ(nlohmann::json::parse(slurp(out / "summary.json"))["frames_done"], 4);
}

const std::string kMug = kData + "/ycbv/models/025_mug/points.xyz";

// An object name that is not UTF-8 is refused at `db add` and `db rename --to` (exit 1, the name
// shown as \xFF).
TEST(Names, DbAddRefusesObjectNameNotUtf8) {
  const fs::path db = kTmp / "db-refused";
  fs::remove_all(db);
  const CliRun r = run("db add " + db.string() + " --name 'mug\xff' --xyz " + kMug);
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("mug\\xFF"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("UTF-8"), std::string::npos) << r.err;
  ASSERT_EQ(run("db add " + db.string() + " --name mug --xyz " + kMug).code, 0);
  const CliRun renamed = run("db rename " + db.string() + " --name mug --to 'mug\xfe'");
  EXPECT_EQ(renamed.code, 1) << renamed.err;
  EXPECT_NE(renamed.err.find("mug\\xFE"), std::string::npos) << renamed.err;
}

// A database that already holds such a name (an older version took it; here put in by sqlite3)
// opens: `db info --json` and `recognize` show it as mug\xFF; rename by that text mends it.
TEST(Names, DatabaseHoldingObjectNameNotUtf8StillOpens) {
  const fs::path db = kTmp / "db-old";
  fs::remove_all(db);
  ASSERT_EQ(run("db add " + db.string() + " --name mug --xyz " + kMug).code, 0);
  const std::string sql = "sqlite3 " + (db / "database.sqlite").string() +
                          " \"UPDATE views SET object = CAST(X'6D7567FF' AS TEXT)\"";
  ASSERT_EQ(std::system(sql.c_str()), 0);
  CliRun r = run("db info " + db.string() + " --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json info = nlohmann::json::parse(r.out);
  EXPECT_NE(info.dump().find("mug\\\\xFF"), std::string::npos) << r.out;
  r = run("recognize " + learn0() + " --db " + db.string() + " -o -");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(nlohmann::json::accept(r.out)) << r.out;  // whatever the database's names
  r = run("db rename " + db.string() + " --name 'mug\\xFF' --to mug");
  ASSERT_EQ(r.code, 0) << r.err;
  r = run("db info " + db.string() + " --json");
  EXPECT_EQ(nlohmann::json::parse(r.out)["objects"][0]["name"], "mug") << r.out;
}

}  // namespace
