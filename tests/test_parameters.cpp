// The parameter table (core/parameters.hpp) against the structs it describes, the CLI's help,
// flags and --set made from it, and docs/parameters.md.
#include <proxseg/core/parameters.hpp>
#include <proxseg/io/params.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <regex>
#include <set>

#include "cli_util.hpp"

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

// The data members declared in `struct NAME { ... };` of a header, read from its text (C++ has
// no reflection): the names of every `TYPE a = x, b = y;` statement, nested structs' members
// (TYPE ending in Params) given as "TYPE:" + name.
std::vector<std::string> declared_fields(const fs::path& header, const std::string& name) {
  std::string text = slurp(header);
  text = std::regex_replace(text, std::regex("//[^\n]*"), "");
  const std::size_t start = text.find("struct " + name + " {");
  EXPECT_NE(start, std::string::npos) << name << " in " << header;
  std::size_t i = text.find('{', start) + 1;
  int depth = 1;
  std::string body;
  for (; depth > 0 && i < text.size(); ++i) {
    if (text[i] == '{') ++depth;
    if (text[i] == '}') --depth;
    if (depth > 0) body += text[i];
  }
  std::vector<std::string> fields;
  std::stringstream statements(body);
  std::string st;
  while (std::getline(statements, st, ';')) {
    st = std::regex_replace(st, std::regex("\\s+"), " ");
    st = std::regex_replace(st, std::regex("\\{[^{}]*\\}"), "{}");  // {0.015, 0.03}
    if (st.find("enum") != std::string::npos || st.find('(') != std::string::npos) continue;
    std::smatch m;
    if (!std::regex_match(st, m, std::regex(" *([A-Za-z_:0-9<>]+) (.*)"))) continue;
    const std::string type = m[1];
    std::stringstream items(m[2].str());
    std::string item;
    while (std::getline(items, item, ',')) {
      std::smatch n;
      if (std::regex_search(item, n, std::regex("^ *([a-z_0-9]+)")))
        fields.push_back(
            (type.size() > 6 && type.substr(type.size() - 6) == "Params" ? type + ":" : "") +
            n[1].str());
    }
  }
  return fields;
}

// The row's value in the JSON of the parameters: "selection.image.normal_step" is
// j["selection"]["image"]["normal_step"].
const nlohmann::json& value_at(const nlohmann::json& j, const Parameter& row) {
  std::string pointer = "/" + row.key();
  std::replace(pointer.begin(), pointer.end(), '.', '/');
  return j.at(nlohmann::json::json_pointer(pointer));
}

std::set<std::string> keys(const std::vector<Parameter>& table) {
  std::set<std::string> k;
  for (const Parameter& row : table) k.insert(row.key());
  return k;
}

// The keys of every field of struct `type`, nested structs' fields under their member's name
// ("selection.image.normal_step").
void declared_keys(const std::map<std::string, fs::path>& headers, const std::string& type,
                   const std::string& prefix, std::set<std::string>& out) {
  ASSERT_TRUE(headers.count(type)) << "no header for " << type;
  for (const std::string& f : declared_fields(headers.at(type), type)) {
    const auto colon = f.find(':');
    if (colon == std::string::npos)
      out.insert(prefix + f);
    else
      declared_keys(headers, f.substr(0, colon), prefix + f.substr(colon + 1) + ".", out);
  }
}

// Every field of the parameter structs (in the headers) has a row, and every row a field.
void expect_table_covers(const std::vector<Parameter>& table, const std::string& top,
                         const std::map<std::string, fs::path>& headers) {
  std::set<std::string> declared;
  declared_keys(headers, top, "", declared);
  const std::set<std::string> rows = keys(table);
  for (const std::string& d : declared)
    EXPECT_TRUE(rows.count(d)) << d << " is a field of " << top << " but not in the table";
  for (const std::string& r : rows)
    EXPECT_TRUE(declared.count(r)) << r << " is in the table but not a field of " << top;
  EXPECT_GT(declared.size(), 30u);
}

TEST(ParameterTable, HasARowForEveryFieldOfTheSegmentationStructs) {
  const fs::path core = kSource / "include/proxseg/core";
  expect_table_covers(segment_parameters(), "SegmentParams",
                      {{"SegmentParams", core / "pipeline.hpp"},
                       {"VoxelParams", core / "voxels.hpp"},
                       {"FeatureParams", core / "features.hpp"},
                       {"ClusteringParams", core / "clustering.hpp"},
                       {"KMeansParams", core / "clustering.hpp"},
                       {"MrfParams", core / "mrf.hpp"},
                       {"SelectionParams", core / "selection.hpp"},
                       {"VoxelSelectionParams", core / "selection.hpp"},
                       {"ImageSelectionParams", core / "selection.hpp"},
                       {"OcclusionParams", core / "selection.hpp"},
                       {"ContainerParams", core / "selection.hpp"}});
}

TEST(ParameterTable, HasARowForEveryFieldOfTheRecognitionStructs) {
  const fs::path core = kSource / "include/proxseg/core";
  expect_table_covers(recognition_parameters(), "RecognitionParams",
                      {{"RecognitionParams", core / "recognition_types.hpp"},
                       {"RegistrationParams", core / "registration_types.hpp"}});
}

TEST(ParameterTable, HeaderReaderSeesEveryKindOfDeclaration) {
  // The header reader above is what the two tests rely on: it must see a field it is shown.
  const fs::path h = kTmp / "fake.hpp";
  fs::create_directories(kTmp);
  std::ofstream(h) << "struct FakeParams {\n  // a comment; with a = sign\n  double a = 1, b{2};\n"
                      "  std::vector<double> radii = {0.1, 0.2};\n  enum class E { kX, kY };\n"
                      "  E e = E::kX;\n  int f(int x) const;\n  double\n      wrapped = 3;\n};\n";
  const std::vector<std::string> f = declared_fields(h, "FakeParams");
  EXPECT_EQ(f, (std::vector<std::string>{"a", "b", "radii", "e", "wrapped"}));
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
