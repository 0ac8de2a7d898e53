// Names that are not UTF-8 (issue 54): bytes until shown, and shown in JSON with their bad bytes
// as \xFF-style text. A batch with such a frame finishes, writes its summary and resumes. Names
// in the batch page's links are percent-encoded and relative, whatever bytes they hold.
#include <cctype>
#include <cstring>
#include <fstream>
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
  // lit\xFF: UTF-8 holding escape-like text, shown escaped too so that it reads back to itself.
  for (const std::string name : {"a", "bad\xff", "bad\xfe", "lit\\xFF", "z"})
    fs::copy_file(learn0(), in / (name + ".pcd"));
  const std::string args =
      "segment --batch " + in.string() + " -o " + out.string() + " --outputs json";
  CliRun r = run(args);
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json summary = nlohmann::json::parse(slurp(out / "summary.json"));
  EXPECT_EQ(summary["frames_done"], 5) << summary.dump(2);
  EXPECT_EQ(summary["frames_failed"], 0);
  std::set<std::string> names;
  for (const auto& row : frame_rows(out / "summary.jsonl")) names.insert(row["frame"]);
  // Two bad names stay two (no U+FFFD for both), shown as \xFF text.
  EXPECT_EQ(names, (std::set<std::string>{"a", "bad\\xFF", "bad\\xFE", "lit\\\\xFF", "z"}));
  EXPECT_TRUE(fs::exists(out / "bad\xff.json"));
  EXPECT_TRUE(nlohmann::json::accept(slurp(out / "bad\xff.json")));  // its report is JSON too
  // --resume finds them all finished: no frame is done again.
  r = run(args + " --resume");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(frame_rows(out / "summary.jsonl").size(), 5u) << r.err;
  EXPECT_EQ(nlohmann::json::parse(slurp(out / "summary.json"))["frames_done"], 5);
}

// A report printed on stdout (`-o -`, `--json`) shows an input named with bytes that are not
// UTF-8 as it shows it in files: JSON, never a type_error.
TEST(Names, ReportsOnStdoutShowNamesNotUtf8) {
  const fs::path in = kTmp / "stdout-in";
  fs::remove_all(in);
  fs::create_directories(in);
  fs::copy_file(learn0(), in / "bad\xff.pcd");
  const CliRun r = run("segment " + (in / "bad\xff.pcd").string() + " -o - --outputs json");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(nlohmann::json::accept(r.out)) << r.out.substr(0, 300);
  const CliRun e = run("eval-seg " + (in / "bad\xff.pcd").string() + " " +
                       (in / "bad\xff.pcd").string() + " --json");
  ASSERT_EQ(e.code, 0) << e.err;
  ASSERT_TRUE(nlohmann::json::accept(e.out)) << e.out.substr(0, 300);
  EXPECT_NE(nlohmann::json::parse(e.out)["truth"].get<std::string>().find("bad\\xFF"),
            std::string::npos);
}

// The hostile frame names of issue 54 (point 2): a scheme, a fragment, a query, a percent sign
// and an escape, space, quotes and markup, text that is not ASCII, bytes that are not UTF-8,
// a frame in a subfolder (its id holds a '/'), and one whose files are renamed (summary-frame.*).
const std::vector<std::string> kHostile = {"javascript:alert(document.domain)",
                                           "a#b",
                                           "50%",
                                           "%41",
                                           "q?x=1",
                                           "sp ace",
                                           "quote\"'<&>",
                                           "lit\\xFF",  // text that reads as an escape
                                           "\xc3\xbcn\xc3\xaf",
                                           "bad\xff",
                                           "d#ir/j:s",
                                           "summary"};

// A scene small enough to segment in a few milliseconds, written to path: 64x48 points of a
// grey table and a red box in front of it (ASCII PCD, packed RGB as an integer).
void write_tiny_scene(const fs::path& path) {
  std::ofstream out(path);
  out << "VERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\n"
         "WIDTH 64\nHEIGHT 48\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3072\nDATA ascii\n";
  for (int v = 0; v < 48; ++v)
    for (int u = 0; u < 64; ++u) {
      const bool box = u >= 20 && u < 40 && v >= 14 && v < 30;
      const double z = box ? 0.8 : 1.0 + 0.004 * v;
      out << (u - 32) * z / 60 << ' ' << (v - 24) * z / 60 << ' ' << z << ' '
          << (box ? 0xC81E1E : 0x787878) << '\n';
    }
}

// The rows embedded in a batch page (#proxseg-rows), parsed.
nlohmann::json page_rows(const std::string& page) {
  const std::string open = "<script id=\"proxseg-rows\" type=\"application/json\">";
  const auto from = page.find(open);
  EXPECT_NE(from, std::string::npos);
  const auto to = page.find("</script>", from);
  return nlohmann::json::parse(page.substr(from + open.size(), to - from - open.size()))["rows"];
}

// The bytes a browser fetches for a link: relative ("./"), nothing but unreserved characters,
// '/' between folders and %XX escapes (so no scheme, no fragment, no query), the escapes read
// back. "" (a failure) for a link that is not so.
std::string fetched_path(const std::string& link) {
  if (link.compare(0, 2, "./") != 0) return "";
  std::string bytes;
  for (std::size_t i = 2; i < link.size(); ++i) {
    const char c = link[i];
    if (c == '%' && i + 2 < link.size() && std::isxdigit(static_cast<unsigned char>(link[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(link[i + 2]))) {
      bytes += static_cast<char>(std::stoi(link.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else if (std::isalnum(static_cast<unsigned char>(c)) || std::strchr("-._~/", c)) {
      bytes += c;
    } else {
      return "";
    }
  }
  return bytes;
}

// Every link of the batch page (a card's picture and its 3D page) is "./" and the name
// percent-encoded, and is the file the batch wrote: no name becomes a scheme or a fragment.
TEST(Names, BatchPageLinksAreRelativePercentEncodedAndResolve) {
  const fs::path in = kTmp / "links-in", out = kTmp / "links-out", scene = kTmp / "scene.pcd";
  fs::remove_all(in);
  fs::remove_all(out);
  fs::create_directories(in / "d#ir");
  write_tiny_scene(scene);
  for (const std::string& name : kHostile) fs::copy_file(scene, in / (name + ".pcd"));
  CliRun r =
      run("segment --batch " + in.string() + " -o " + out.string() + " -q --outputs png,html");
  ASSERT_EQ(r.code, 0) << r.err;
  r = run("view " + out.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string page = slurp(out / "index.html");
  const nlohmann::json rows = page_rows(page);
  ASSERT_EQ(rows.size(), kHostile.size()) << rows.dump();
  for (const auto& row : rows)
    for (int field : {5, 6}) {  // the picture and the 3D page (batch.js: F.picture, F.page)
      ASSERT_TRUE(row[field].is_string()) << row.dump();
      const std::string link = row[field], path = fetched_path(link);
      if (path.empty())
        ADD_FAILURE() << "not relative and percent-encoded: " << link;
      else
        EXPECT_TRUE(fs::is_regular_file(out / path)) << link << " is no file of the batch";
    }
  // Nor does the page hold a link of its own made from a name.
  for (const char* attribute : {"href=", "src="})
    EXPECT_EQ(page.find(attribute), std::string::npos) << attribute;
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
