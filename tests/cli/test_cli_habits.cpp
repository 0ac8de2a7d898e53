// The CLI's habits (docs/cli.md): one error style with suggestions, one spelling per
// concept with the other accepted, unit sanity for meshes, one numbering of candidates and
// objects, plurals, the resume note, --quiet and --verbose.
#include <proxseg/io/cloud_io.hpp>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>
#include <regex>
#include <set>

#include "support/cli_util.hpp"

namespace {

using cli_test::CliRun;
using cli_test::kData;
using cli_test::slurp;
namespace fs = std::filesystem;

const fs::path kTmp = fs::path(PROXSEG_TEST_TMP) / "cli_habits";

CliRun run(const std::string& args) {
  return cli_test::run_in(kTmp, args);
}

std::string learn0() {
  return kData + "/mosd/learn/learn0.pcd";
}

// A scratch folder of its own for the calling test.
fs::path scratch() {
  const fs::path d = kTmp / ::testing::UnitTest::GetInstance()->current_test_info()->name();
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(CliHabits, UsageErrorsHaveThePrefixAndSuggestAFlag) {
  const std::string o = (scratch() / "a").string();
  CliRun r = run("segment " + learn0() + " -o " + o + " --voxelsize 0.01");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(
      r.err.rfind("proxseg: error: unknown option --voxelsize (did you mean --voxel-size?)", 0), 0u)
      << r.err;
  EXPECT_TRUE(has(r.err, "Run `proxseg segment --help`")) << r.err;
  r = run("segmnet " + learn0());
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(has(r.err, "proxseg: error: unknown command segmnet (did you mean segment?)"))
      << r.err;
  r = run("segment " + learn0());  // no -o
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err.rfind("proxseg: error: --output is required", 0), 0u) << r.err;
  r = run("recognize --db x --min-scor 0.5 " + learn0() + " -o " + o);  // proxseg-tools too
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(has(r.err, "proxseg: error: unknown option --min-scor (did you mean --min-score?)"))
      << r.err;
  r = run("segment " + learn0() + " -o " + o + " --mrf-method swp");
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(has(r.err,
                  "--mrf-method: expected \"swap\" or \"expansion\", got \"swp\" (did you "
                  "mean swap?)"))
      << r.err;
}

TEST(CliHabits, UnknownConfigKeysAndSetKeysGetSuggestions) {
  const fs::path d = scratch();
  std::ofstream(d / "c.json") << R"({"mrf": {"pairwise": 0.1}})";
  CliRun r = run("segment " + learn0() + " -o " + (d / "a").string() + " --config " +
                 (d / "c.json").string());
  EXPECT_EQ(r.code, 1);
  EXPECT_TRUE(has(r.err, "proxseg: error: " + (d / "c.json").string() +
                             ": config: unknown key mrf.pairwise (did you mean "
                             "mrf.pairwise_weight?)"))
      << r.err;
  r = run("segment " + learn0() + " -o " + (d / "a").string() + " --set mrf.pairwise=0.1");
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(has(r.err,
                  "--set mrf.pairwise=0.1: unknown parameter mrf.pairwise (did you mean "
                  "mrf.pairwise_weight?)"))
      << r.err;
  r = run("segment " + learn0() + " -o " + (d / "a").string() + " --set voxel_size=abc");
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(has(r.err, "expected a number, got \"abc\"")) << r.err;
}

TEST(CliHabits, SetReachesEveryParameterAndFlagsAskForTheLabelsTheyChange) {
  const fs::path d = scratch();
  const CliRun r =
      run("segment " + learn0() + " -o " + (d / "a").string() +
          " --set selection.image.merge_window=5 --set features.normal_edge_ratio=0.02 "
          "--set kmeans.tolerance=1e-5 --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json p = nlohmann::json::parse(r.out)["parameters"];
  EXPECT_EQ(p["selection"]["image"]["merge_window"], 5);
  EXPECT_DOUBLE_EQ(p["features"]["normal_edge_ratio"].get<double>(), 0.02);
  EXPECT_DOUBLE_EQ(p["kmeans"]["tolerance"].get<double>(), 1e-5);
  EXPECT_TRUE(p["paper_labels"].get<bool>());  // k-means was asked about
  const CliRun recognize = run("recognize --db " + (d / "none").string() + " " + learn0() + " -o " +
                               (d / "b").string() + " --set min_scor=0.3");
  EXPECT_EQ(recognize.code, 2);
  EXPECT_TRUE(has(recognize.err, "did you mean min_score?")) << recognize.err;
}

TEST(CliHabits, OneSpellingInTheHelpTheOtherAccepted) {
  const CliRun help = run("segment --help");
  ASSERT_EQ(help.code, 0);
  for (const std::string shown :
       {"--no-colour", "--colour-weight", "--colour ", "--colour-pattern"})
    EXPECT_TRUE(has(help.out, shown)) << shown;
  for (const std::string hidden : {"--no-color", "--color-weight", "--color ", "--color-pattern"})
    EXPECT_FALSE(has(help.out, hidden)) << hidden;
  const fs::path d = scratch();
  const CliRun british = run("segment " + learn0() + " -o " + (d / "a").string() +
                             " --no-colour --colour-weight 2 --json");
  const CliRun american = run("segment " + learn0() + " -o " + (d / "b").string() +
                              " --no-color --color-weight 2 --json");
  ASSERT_EQ(british.code, 0) << british.err;
  ASSERT_EQ(american.code, 0) << american.err;
  const auto params = [](const CliRun& r) { return nlohmann::json::parse(r.out)["parameters"]; };
  EXPECT_EQ(params(british), params(american));
  EXPECT_FALSE(params(american)["features"]["use_colour"].get<bool>());
}

TEST(CliHabits, MeshesOfAnImplausibleSizeForTheirUnitAreRefusedWithTheFix) {
  const fs::path d = scratch();
  const std::string mesh = kData + "/lmo/models/obj_000001.ply";  // millimetres
  CliRun r = run("db render " + (d / "db").string() + " --name ape " + mesh + " --views 2");
  EXPECT_EQ(r.code, 1);
  EXPECT_TRUE(has(r.err,
                  "142.1 m across with --units m, too large for an object: its "
                  "coordinates look like millimetres; use --units mm"))
      << r.err;
  EXPECT_FALSE(fs::exists(d / "db")) << "refused before the database is made";
  r = run("db render " + (d / "db").string() + " --name ape " + mesh + " --views 2 --units mm");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(has(r.out, "1 object, 2 views")) << r.out;  // and plurals
  const CliRun help = run("db render --help");
  EXPECT_TRUE(std::regex_search(help.out, std::regex("--units TEXT:\\{m,mm\\}=m|--units.*=m")))
      << help.out;
}

TEST(CliHabits, PlaceholderColoursAreNamedAsSuch) {
  const fs::path d = scratch();
  const CliRun r = run("db add " + (d / "db").string() + " --name milk " + kData + "/pcl/milk.pcd");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(has(r.err, "its colours are one placeholder colour throughout")) << r.err;
  EXPECT_FALSE(has(r.err, "no colour")) << r.err;
  EXPECT_TRUE(has(r.out, ": 1 object, 1 view\n")) << r.out;
}

TEST(CliHabits, RecognizeNumbersCandidatesAndObjectsOneWayEverywhere) {
  const fs::path d = scratch();
  const std::string frames = kData + "/ycbv/frames/";
  for (const std::string name : {"009_gelatin_box", "025_mug", "061_foam_brick"})
    ASSERT_EQ(run("db add " + (d / "db").string() + " -q --name " + name + " --xyz " + kData +
                  "/ycbv/models/" + name + "/points.xyz")
                  .code,
              0);
  const std::string scene = "--colour " + frames + "000004-color.png --depth " + frames +
                            "000004-depth.png --meta " + frames + "000004-meta.json";
  const CliRun r =
      run("recognize --db " + (d / "db").string() + " " + scene + " -o " + (d / "r").string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_FALSE(has(r.err, "union of")) << "trials are for --verbose: " << r.err;
  const nlohmann::json report = nlohmann::json::parse(slurp(d / "r.json"));
  // Progress lines name candidates by instance id; the table maps each object id to them.
  std::set<std::string> progressed;
  std::smatch m;
  for (std::string err = r.err; std::regex_search(err, m, std::regex("\\] candidate ([0-9+]+): "));
       err = m.suffix())
    progressed.insert(m[1]);
  EXPECT_FALSE(progressed.empty()) << r.err;
  std::size_t rows = 0;
  std::stringstream table(r.out);
  std::string line;
  std::getline(table, line);
  EXPECT_EQ(line.rfind("id   candidates points  name", 0), 0u) << line;
  while (std::getline(table, line)) {
    std::stringstream cells(line);
    int id = 0;
    std::string candidates;
    cells >> id >> candidates;
    ASSERT_LT(rows, report["candidates"].size());
    const nlohmann::json& o = report["candidates"][rows];
    EXPECT_EQ(o["id"].get<int>(), id);
    std::string of;
    for (const auto& i : o["instances"])
      of += (of.empty() ? "" : "+") + std::to_string(i.get<int>());
    EXPECT_EQ(of, candidates);
    if (o["origin"] == "candidate") {
      EXPECT_TRUE(progressed.count(of)) << of;
    }
    ++rows;
  }
  EXPECT_EQ(rows, report["candidates"].size());
  // PREFIX.pcd's object field holds the same ids.
  const proxseg::Frame pcd = proxseg::read_pcd((d / "r.pcd").string(), "object");
  std::set<std::uint32_t> ids(pcd.label.begin(), pcd.label.end());
  ids.erase(0);
  EXPECT_EQ(ids.size(), rows);
}

TEST(CliHabits, QuietSaysOnlyProblemsAndVerboseIsAccepted) {
  const fs::path d = scratch();
  CliRun r = run("segment -q " + learn0() + " -o " + (d / "a").string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_FALSE(r.out.empty());  // the result still goes to stdout
  r = run("--quiet segment " + learn0() + " -o " + (d / "a").string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  r = run("segment " + learn0() + " -o " + (d / "a").string());
  EXPECT_TRUE(has(r.err, "valid points")) << r.err;
  r = run("segment --verbose " + learn0() + " -o " + (d / "a").string());
  EXPECT_EQ(r.code, 0) << r.err;
}

// Global options go before the command too, as in git (`proxseg -q db info DB`): also for the
// commands that proxseg-tools runs.
TEST(CliHabits, GlobalOptionsGoBeforeAnyCommand) {
  const std::string db = (scratch() / "db").string();
  const std::string milk = kData + "/pcl/milk.pcd";
  CliRun r = run("--quiet db add " + db + " --name milk " + milk);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  for (const std::string flags : {"-q", "--quiet", "-v", "--verbose", "-q -v"}) {
    SCOPED_TRACE(flags);
    r = run(flags + " db info " + db + " --json");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["views"], 1);
  }
  r = run("-q recognize --db " + db + " --object " + milk + " -o -");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  r = run("-q --bogus db info " + db);  // still a usage error, naming the flag
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(has(r.err, "unknown option --bogus")) << r.err;
}

// What `db check` cannot open is said as it is (not a database, missing), not "see proxseg db
// check"; a file it may not read: tests/cli/test_readonly_db.cpp.
TEST(CliHabits, DbCheckSaysWhyItCannotOpenAFile) {
  const fs::path d = scratch();
  fs::create_directories(d / "junk");
  std::ofstream(d / "junk/database.sqlite") << std::string(4096, 'x');
  for (const std::string& cmd : std::vector<std::string>{
           "db check ", "db info ", "recognize --object " + learn0() + " -o - --db "}) {
    SCOPED_TRACE(cmd);
    CliRun r = run(cmd + (d / "junk").string());
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_TRUE(has(r.err, (d / "junk/database.sqlite").string() + ": not a SQLite database file"))
        << r.err;
    EXPECT_FALSE(has(r.err, "see proxseg db check")) << r.err;
  }
  const CliRun r = run("db check " + (d / "none").string());
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_TRUE(has(r.err, "none: does not exist")) << r.err;
}

TEST(CliHabits, ABatchRunAgainWithoutResumeSaysSo) {
  const fs::path d = scratch();
  fs::create_directories(d / "in");
  fs::copy_file(learn0(), d / "in/a.pcd");
  const std::string cmd = "segment --batch " + (d / "in").string() + " -o " + (d / "out").string();
  CliRun r = run(cmd);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_FALSE(has(r.err, "--resume")) << r.err;
  EXPECT_TRUE(has(r.err, "proxseg: 1 frame\n")) << r.err;
  r = run(cmd);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(has(r.err,
                  "holds 1 frame an earlier run finished; doing them again "
                  "(--resume skips them)"))
      << r.err;
  r = run(cmd + " --resume");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_FALSE(has(r.err, "doing them again")) << r.err;
}

}  // namespace
