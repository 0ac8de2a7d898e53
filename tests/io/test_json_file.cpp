// The shared reader of JSON files (src/io/json_file.hpp): nesting bounded before parsing,
// brackets in strings not counted, errors naming the file, values quoted by a short excerpt.
#include <gtest/gtest.h>

#include <proxseg/core/errors.hpp>

#include <filesystem>
#include <fstream>
#include <string>

#include "io/json_file.hpp"

namespace {
using namespace proxseg::detail;

std::string deep(int n) {
  return std::string(n, '[') + std::string(n, ']');
}

std::string message(const std::string& text, const std::string& where = "f.json") {
  try {
    parse_json(text, where);
  } catch (const proxseg::InputError& e) {
    return e.what();
  }
  return "";
}

TEST(JsonFile, DepthIsBounded) {
  EXPECT_FALSE(json_too_deep(deep(kMaxJsonDepth)));
  EXPECT_TRUE(json_too_deep(deep(kMaxJsonDepth + 1)));
  EXPECT_TRUE(json_too_deep(std::string(100000, '{')));
  EXPECT_EQ(parse_json(deep(kMaxJsonDepth), "f.json").size(), 1u);
  const std::string m = message(deep(100000));
  EXPECT_EQ(m, "f.json: nested deeper than 64 levels (expected at most 64)");
}

TEST(JsonFile, BracketsInStringsAreNotCounted) {
  const std::string text = "{\"a\": \"" + std::string(1000, '[') + "\\\"{\"}";
  EXPECT_FALSE(json_too_deep(text));
  EXPECT_EQ(parse_json(text, "f.json")["a"].get<std::string>().size(), 1002u);
}

TEST(JsonFile, InvalidJsonNamesTheFile) {
  const std::string m = message("{\"a\": ", "dir/c.json");
  EXPECT_EQ(m.rfind("dir/c.json: not valid JSON (", 0), 0u) << m;
  EXPECT_LT(m.size(), 300u);
}

TEST(JsonFile, ReadsAFile) {
  const auto p = std::filesystem::path(PROXSEG_TEST_TMP) / "json_file_reads.json";
  std::filesystem::create_directories(p.parent_path());
  std::ofstream(p) << deep(200);
  try {
    read_json_file(p.string());
    FAIL() << "no error";
  } catch (const proxseg::InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(p.string() + ": nested deeper", 0), 0u) << e.what();
  }
  std::ofstream(p) << "{\"k\": 3}";
  EXPECT_EQ(read_json_file(p.string())["k"], 3);
}

TEST(JsonFile, ExcerptsAreShortAndNeverWalkValues) {
  const nlohmann::json v = nlohmann::json::parse(deep(100000));  // dump() would recurse
  EXPECT_EQ(json_excerpt(v), "an array of 1 elements");
  EXPECT_EQ(json_excerpt(nlohmann::json::object()), "an object of 0 fields");
  EXPECT_EQ(json_excerpt(std::string(1000, 'x')).size(), 65u);  // quoted: 60, "..." and the quotes
  EXPECT_EQ(json_excerpt(3.5), "'3.5'");
}

}  // namespace
