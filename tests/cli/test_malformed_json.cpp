// Malformed JSON where the CLI reads it (issue 54): a config nested 100,000 deep, reports for
// `proxseg view` nested as deep or with fields of the wrong type or shape. Every run must end with
// exit 1 and one short line naming the file (and the field), never a signal.
#include <algorithm>
#include <nlohmann/json.hpp>
#include <string>

#include "support/cli_util.hpp"

namespace {
using namespace cli_test;
using nlohmann::json;

fs::path dir() {
  const std::string name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
  const fs::path d = fs::path(PROXSEG_TEST_TMP) / "malformed_json" / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

CliRun run(const std::string& args) {
  return run_in(fs::path(PROXSEG_TEST_TMP) / "malformed_json", args);
}

void write(const fs::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

std::string deep(int n) {
  return std::string(n, '[') + std::string(n, ']');
}

// Exit 1 and one short line on stderr holding every one of `names`.
void expect_short_error(const CliRun& r, std::initializer_list<std::string> names) {
  EXPECT_EQ(r.code, 1) << r.err.substr(0, 500);
  for (const std::string& n : names) EXPECT_NE(r.err.find(n), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err.substr(0, 500);
  EXPECT_LT(r.err.size(), 400u) << r.err.substr(0, 500);
}

// A segmentation of learn0 as PREFIX.{pcd,json} in d; its report.
json segment(const fs::path& prefix) {
  const CliRun r = run("segment " + learn0() + " -o " + prefix.string() + " --outputs pcd,json");
  EXPECT_EQ(r.code, 0) << r.err;
  return json::parse(slurp(prefix.string() + ".json"));
}

// A recognition's result made from a segmentation: its cloud's instances as the objects, one
// named object with `pose` in the report.
fs::path recognition_with_pose(const json& pose) {
  const fs::path prefix = dir() / "r";
  json report = segment(prefix);
  std::string pcd = slurp(prefix.string() + ".pcd");
  pcd.replace(pcd.find("label instance\n"), 15, "label object\n");
  write(prefix.string() + ".pcd", pcd);
  report["database"] = "models.db";
  const std::uint32_t id = report["candidates"][0]["id"];
  report["candidates"] = json::array(
      {{{"id", id}, {"name", "tin"}, {"colour", {1, 2, 3}}, {"score", 0.5}, {"pose", pose}}});
  write(prefix.string() + ".json", report.dump());
  return prefix;
}

const json kIdentity = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}};

TEST(MalformedJson, DeepConfigIsAnInputError) {
  const fs::path d = dir();
  write(d / "deep.json", deep(100000));
  const CliRun r = run("segment " + learn0() + " -o " + (d / "x").string() + " --config " +
                       (d / "deep.json").string());
  expect_short_error(r, {"deep.json", "nested deeper than 64"});
}

TEST(MalformedJson, DeepReportIsAnInputError) {
  const fs::path d = dir();
  segment(d / "r");
  write(d / "r.json", deep(100000));
  expect_short_error(run("view " + (d / "r").string()), {"r.json", "nested deeper than 64"});
}

TEST(MalformedJson, WellFormedRecognitionIsViewed) {
  const fs::path prefix = recognition_with_pose(kIdentity);
  const CliRun r = run("view " + prefix.string());
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(prefix.string() + ".html"));
}

TEST(MalformedJson, EmptyPoseRowsAreAnInputError) {
  const fs::path prefix = recognition_with_pose(json::parse("[[],[],[]]"));
  expect_short_error(run("view " + prefix.string()),
                     {"r.json: candidates[0].pose: expected 4 rows of 4 numbers"});
}

TEST(MalformedJson, ShortPoseRowsAreAnInputError) {
  const fs::path prefix = recognition_with_pose(json::parse("[[1],[2],[3]]"));
  expect_short_error(run("view " + prefix.string()), {"r.json", "candidates[0].pose"});
}

TEST(MalformedJson, PoseOfStringsIsAnInputError) {
  json pose = kIdentity;
  pose[1][2] = "0";
  const fs::path prefix = recognition_with_pose(pose);
  expect_short_error(run("view " + prefix.string()), {"r.json", "candidates[0].pose"});
}

TEST(MalformedJson, MissingIdIsAnInputError) {
  const fs::path d = dir();
  json report = segment(d / "r");
  report["candidates"][1].erase("id");
  write(d / "r.json", report.dump());
  expect_short_error(run("view " + (d / "r").string()), {"r.json", "candidates[1].id"});
}

TEST(MalformedJson, BoxOfWrongShapeIsAnInputError) {
  const fs::path d = dir();
  json report = segment(d / "r");
  report["candidates"][0]["box"]["axes"] = json::parse("[[1],[2],[3]]");
  write(d / "r.json", report.dump());
  expect_short_error(run("view " + (d / "r").string()), {"r.json", "candidates[0].box.axes"});
}

}  // namespace
