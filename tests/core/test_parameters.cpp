// The parameter table (core/parameters.hpp) against the structs it describes, the CLI's help,
// flags and --set made from it, and docs/parameters.md.
#include <proxseg/core/errors.hpp>
#include <proxseg/core/parameters.hpp>
#include <proxseg/io/params.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "support/cli_util.hpp"
#include "util/field_count.hpp"

namespace {

using namespace proxseg;
using cli_test::CliRun;
using cli_test::slurp;
namespace fs = std::filesystem;

const fs::path kSource = PROXSEG_SOURCE_DIR;
const fs::path kTmp = fs::path(PROXSEG_TEST_TMP) / "parameters";

CliRun run(const std::string& args) {
  return cli_test::run_in(kTmp, args);
}

// The row's value in the JSON of the parameters: "selection.image.normal_step" is
// j["selection"]["image"]["normal_step"].
const nlohmann::json& value_at(const nlohmann::json& j, const Parameter& row) {
  std::string pointer = "/" + row.key();
  std::replace(pointer.begin(), pointer.end(), '.', '/');
  return j.at(nlohmann::json::json_pointer(pointer));
}

// A struct with every kind of member the parameter structs hold.
struct FakeParams {
  double a = 1, b{2};
  std::vector<double> radii = {0.1, 0.2};
  enum class E { kX, kY };
  E e = E::kX;
  MrfParams section;
  std::string name = "x";
  int f(int x) const { return x; }
};

TEST(ParameterTable, FieldCountSeesEveryKindOfMember) {
  // What the compile-time check of the adaptations (parameter_members.hpp) relies on.
  static_assert(detail::field_count<FakeParams>() == 6);
  EXPECT_EQ(detail::field_count<FakeParams>(), 6u);
  EXPECT_EQ(detail::field_count<MrfParams>(), 5u);
  EXPECT_EQ(detail::field_count<SegmentParams>(), 9u);
}

TEST(ParameterTable, HasARowForEveryMember) {
  // The table is made from the adapted members (checked against the structs at compile time)
  // and refuses to build when one has no row: here it built, with every row's key distinct.
  for (const std::vector<Parameter>* table : {&segment_parameters(), &recognition_parameters()}) {
    std::set<std::string> keys;
    for (const Parameter& row : *table) EXPECT_TRUE(keys.insert(row.key()).second) << row.key();
    EXPECT_GT(keys.size(), 30u);
  }
  EXPECT_EQ(require_parameter(segment_parameters(), "selection.image.normal_step").key(),
            "selection.image.normal_step");
}

TEST(ParameterTable, DefaultsAreTheStructsOwn) {
  // The rows' defaults against the JSON of default-constructed structs (read member by member).
  const nlohmann::json seg = to_json(SegmentParams{}), rec = to_json(RecognitionParams{});
  for (const auto& [table, j] :
       {std::pair{&segment_parameters(), &seg}, std::pair{&recognition_parameters(), &rec}})
    for (const Parameter& row : *table) {
      const nlohmann::json& v = value_at(*j, row);
      std::visit([&](const auto& d) { EXPECT_EQ(nlohmann::json(d), v) << row.key(); },
                 row.default_value);
    }
}

TEST(ParameterTable, PaperValuesAreThePaperPresets) {
  const SegmentParams paper = preset("paper");
  int stated = 0;
  for (const Parameter& row : segment_parameters())
    if (!row.paper.empty()) {
      ++stated;
      EXPECT_EQ(row.paper, format_parameter(get_parameter(paper, row.key()))) << row.key();
    }
  EXPECT_GE(stated, 10);
  EXPECT_EQ(require_parameter(segment_parameters(), "mrf.pairwise_weight").paper, "0.275");
}

TEST(ParameterTable, ValidateChecksEveryRowsRange) {
  for (const Parameter& row : segment_parameters()) {
    if (row.type == ParamType::kBool || row.type == ParamType::kChoice) continue;
    SegmentParams p;
    const double outside = std::isfinite(row.min) ? row.min - 1 : row.max + 1;
    if (row.type == ParamType::kUnsigned) continue;
    set_parameter(p, row.key(),
                  row.type == ParamType::kInt ? ParamValue(int(outside)) : ParamValue(outside));
    EXPECT_THROW(validate(p), InputError) << row.key();
  }
  SegmentParams p;
  p.selection.containers.max_radius = 0.01;  // under the minimum radius
  EXPECT_THROW(validate(p), InputError);
  RecognitionParams r;
  r.lookalike_share = 0;  // off
  EXPECT_NO_THROW(validate(r));
  r.lookalike_share = 0.3;  // neither off nor a majority
  EXPECT_THROW(validate(r), InputError);
}

TEST(ParameterTable, SetsAndGetsByKeyOrBareName) {
  SegmentParams p;
  set_parameter(p, "voxel_size", 0.03);
  set_parameter(p, "mrf.method", std::string("expansion"));
  set_parameter(p, "mrf.max_cycles", 5);
  EXPECT_EQ(p.voxels.voxel_size, 0.03);
  EXPECT_EQ(p.mrf.method, MrfMethod::kExpansion);
  EXPECT_EQ(std::get<int>(get_parameter(p, "max_cycles")), 5);
  EXPECT_THROW(set_parameter(p, "mrf.method", std::string("swp")), InputError);
  EXPECT_THROW(set_parameter(p, "mrf.max_cycles", 1.5), InputError);
  try {
    set_parameter(p, "mrf.pairwise", 0.1);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("did you mean mrf.pairwise_weight?"), std::string::npos)
        << e.what();
  }
  EXPECT_EQ(closest_name("voxelsize", {"voxel_size", "threads"}), "voxel_size");
  EXPECT_EQ(closest_name("zzz", {"voxel_size", "threads"}), "");
}

TEST(ParameterTable, ConfigKeysGetSuggestions) {
  try {
    params_from_json(nlohmann::json::parse(R"({"mrf": {"pairwise": 0.1}})"));
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown key mrf.pairwise (did you mean "
                                         "mrf.pairwise_weight?)"),
              std::string::npos)
        << e.what();
  }
  try {
    params_from_json(nlohmann::json::parse(R"({"voxel_size": 0.01})"));
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("did you mean voxels.voxel_size?"), std::string::npos)
        << e.what();
  }
}

TEST(ParameterTable, SelectionSectionsNestInTheJson) {
  SegmentParams p;
  p.selection.image.normal_step = 6;
  p.selection.occlusion.enabled = false;
  const nlohmann::json j = to_json(p);
  EXPECT_EQ(j["selection"]["image"]["normal_step"], 6);
  EXPECT_EQ(j["selection"]["occlusion"]["enabled"], false);
  EXPECT_EQ(j["selection"]["voxels"]["merge_min_boundary"], 3);
  EXPECT_EQ(j["selection"]["containers"]["min_radius"], 0.02);
  EXPECT_FALSE(j["selection"].contains("image_normal_step"));
  EXPECT_EQ(to_json(params_from_json(j)), j);
  try {  // a section given a value
    params_from_json(nlohmann::json::parse(R"({"selection": {"image": 4}})"));
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("field selection.image: expected an object"),
              std::string::npos)
        << e.what();
  }
  // "enabled" is a name of three sections: the bare name is refused, naming them.
  try {
    set_parameter(p, "enabled", false);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("selection.occlusion.enabled"), std::string::npos)
        << e.what();
  }
}

TEST(ParameterTable, OldSelectionKeysAreReadWithADeprecationNote) {
  std::vector<std::string> notes;
  const SegmentParams p = params_from_json(
      nlohmann::json::parse(R"({"selection": {"image_normal_step": 5, "join_occluded": false,
                                "merge_convex": false, "cluster_tolerance": 0.02}})"),
      {}, &notes);
  EXPECT_EQ(p.selection.image.normal_step, 5);
  EXPECT_FALSE(p.selection.occlusion.enabled);
  EXPECT_FALSE(p.selection.voxels.merge_convex);
  EXPECT_EQ(p.selection.cluster_tolerance, 0.02);
  ASSERT_EQ(notes.size(), 3u);  // cluster_tolerance kept its key
  EXPECT_EQ(notes[0],
            "config: selection.image_normal_step is now selection.image.normal_step (the old "
            "key will be removed)");
  SegmentParams q;
  set_parameter(q, "occlusion_window", 50);                 // the bare old name
  set_parameter(q, "selection.container_min_depth", 0.03);  // the old key
  EXPECT_EQ(q.selection.occlusion.window, 50);
  EXPECT_EQ(q.selection.containers.min_depth, 0.03);
  const std::vector<Parameter>& table = segment_parameters();
  const Parameter& row = require_parameter(table, "selection.occlusion.window");
  EXPECT_EQ(row.old_key, "selection.occlusion_window");
  EXPECT_EQ(renamed_note(row, "selection.occlusion.window"), "");
  EXPECT_EQ(renamed_note(row, "window"), "");
  EXPECT_NE(renamed_note(row, "occlusion_window"), "");
  EXPECT_EQ(require_parameter(table, "selection.cluster_tolerance").old_key, "");
}

TEST(ParameterFlags, OldKeysWarnOnStderrAndStillApply) {
  const fs::path d = kTmp / "old_keys";
  fs::create_directories(d);
  std::ofstream(d / "old.json") << R"({"selection": {"join_containers": false}})";
  const CliRun r =
      run("segment " + cli_test::learn0() + " -o " + (d / "s").string() + " --config " +
          (d / "old.json").string() + " --set selection.occlusion_min_rays=12 --json");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("proxseg: warning: config: selection.join_containers is now "
                       "selection.containers.enabled"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("proxseg: warning: --set selection.occlusion_min_rays is now "
                       "selection.occlusion.min_rays"),
            std::string::npos)
      << r.err;
  const nlohmann::json p = nlohmann::json::parse(r.out)["parameters"]["selection"];
  EXPECT_EQ(p["containers"]["enabled"], false);
  EXPECT_EQ(p["occlusion"]["min_rays"], 12);
}

// The --help of a command: flag -> its help text (the lines after it joined).
std::map<std::string, std::string> help_of(const std::string& command) {
  const CliRun r = run(command + " --help");
  EXPECT_EQ(r.code, 0) << r.err;
  std::map<std::string, std::string> help;
  std::stringstream lines(r.out);
  std::string line, flag;
  while (std::getline(lines, line)) {
    std::smatch m;
    if (std::regex_search(line, m, std::regex("^  (-[a-z],)?(--[a-z0-9-]+)"))) flag = m[2];
    if (!flag.empty()) help[flag] += line + " ";
  }
  return help;
}

void expect_help_shows_defaults(const std::string& command, const std::vector<Parameter>& table,
                                const nlohmann::json& defaults) {
  const auto help = help_of(command);
  int checked = 0;
  for (const Parameter& row : table) {
    if (row.flag.empty()) continue;
    const std::string flag = "--" + row.flag;
    ASSERT_TRUE(help.count(flag)) << command << " --help has no " << flag;
    const nlohmann::json& v = value_at(defaults, row);
    const std::string& text = help.at(flag);
    if (row.type == ParamType::kBool) {
      const bool on = v.get<bool>();
      EXPECT_NE(text.find(on ? "on by default" : "off by default"), std::string::npos)
          << flag << ": " << text;
    } else {
      std::smatch m;
      ASSERT_TRUE(std::regex_search(text, m, std::regex("\\(default ([^ ;,)]+)"))) << text;
      const std::string shown = m[1];
      if (v.is_string())
        EXPECT_EQ(shown, v.get<std::string>()) << flag;
      else
        EXPECT_DOUBLE_EQ(std::stod(shown), v.get<double>()) << flag;
    }
    ++checked;
  }
  EXPECT_GT(checked, 5);
}

TEST(ParameterFlags, HelpShowsTheDefaultsInEffect) {
  expect_help_shows_defaults("segment", segment_parameters(), to_json(SegmentParams{}));
  expect_help_shows_defaults("recognize", recognition_parameters(), to_json(RecognitionParams{}));
  const auto help = help_of("segment");
  EXPECT_NE(help.at("--wc").find("(default 0.05; paper 0.275)"), std::string::npos)
      << help.at("--wc");
}

TEST(ParameterFlags, DocsParametersIsTheGeneratedTable) {
  const CliRun r = run("params --markdown");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out, slurp(kSource / "docs/parameters.md"))
      << "docs/parameters.md is stale: `make docs` (or proxseg params --markdown) rewrites it";
}

}  // namespace
