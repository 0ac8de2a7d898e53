// SegmentParams and RecognitionParams <-> JSON, row by row of the parameter table
// (core/parameters.hpp): the JSON sections are the table's.
#include <proxseg/core/errors.hpp>
#include <proxseg/core/parameters.hpp>
#include <proxseg/io/params.hpp>

#include <algorithm>
#include <limits>
#include <set>

#include "io/json_file.hpp"

namespace proxseg {
namespace {

using nlohmann::json;

json value_json(const ParamValue& value) {
  return std::visit([](const auto& v) { return json(v); }, value);
}

// A JSON value as the row's type: InputError "field KEY: expected ..., got VALUE".
ParamValue json_value(const Parameter& row, const json& v) {
  auto wrong = [&](const char* expected) -> ParamValue {
    throw InputError("field " + row.key() + ": expected " + expected + ", got " +
                     detail::json_excerpt(v));
  };
  switch (row.type) {
    case ParamType::kBool:
      return v.is_boolean() ? ParamValue(v.get<bool>()) : wrong("true or false");
    case ParamType::kInt:
      if (!v.is_number_integer()) return wrong("an integer");
      if (v.is_number_unsigned() ? v.get<std::uint64_t>() > std::numeric_limits<int>::max()
                                 : v.get<std::int64_t>() < std::numeric_limits<int>::min() ||
                                       v.get<std::int64_t>() > std::numeric_limits<int>::max())
        return wrong("an integer of at most 10 digits");
      return v.get<int>();
    case ParamType::kUnsigned:
      return v.is_number_unsigned() ? ParamValue(v.get<std::uint64_t>())
                                    : wrong("a non-negative integer");
    case ParamType::kReal:
      return v.is_number() ? ParamValue(v.get<double>()) : wrong("a number");
    case ParamType::kChoice:
      if (!v.is_string()) return wrong(("one of " + row.range_text()).c_str());
      return parse_parameter(row, v.get<std::string>());
  }
  return wrong("a value");
}

template <class P>
json to_json_with(const P& params, const std::vector<Parameter>& table) {
  json j = json::object();
  for (const Parameter& row : table) {
    json* where = &j;  // "selection.image" -> j["selection"]["image"]
    for (std::size_t at = 0; at < row.section.size();) {
      const std::size_t dot = std::min(row.section.find('.', at), row.section.size());
      where = &(*where)[row.section.substr(at, dot - at)];
      at = dot + 1;
    }
    (*where)[row.name] = value_json(get_parameter(params, row.key()));
  }
  return j;
}

// An unknown key: InputError "config: unknown key KEY (did you mean ...?)".
[[noreturn]] void unknown_key(const std::vector<Parameter>& table, const std::string& key) {
  const std::string near = nearest_parameter(table, key);
  throw InputError("config: unknown key " + key +
                   (near.empty() ? "" : " (did you mean " + near + "?)"));
}

// The sections of the table, and every section that holds one ("selection" for
// "selection.image").
std::set<std::string> section_names(const std::vector<Parameter>& table) {
  std::set<std::string> sections;
  for (const Parameter& row : table) {
    if (row.section.empty()) continue;
    for (std::size_t dot = row.section.find('.'); dot != std::string::npos;
         dot = row.section.find('.', dot + 1))
      sections.insert(row.section.substr(0, dot));
    sections.insert(row.section);
  }
  return sections;
}

template <class P>
P from_json_with(const json& j, P base, const std::vector<Parameter>& table,
                 std::vector<std::string>* renamed) {
  if (!j.is_object())
    throw InputError("config: expected a JSON object, got " + detail::json_excerpt(j));
  const std::set<std::string> sections = section_names(table);
  // Unknown keys are errors: a typo must not silently leave a default in place.
  auto set = [&](const std::string& key, const json& v) {
    const Parameter* row = nullptr;
    for (const Parameter& r : table)
      if (r.key() == key || r.old_key == key) row = &r;
    if (!row) unknown_key(table, key);
    if (renamed && row->key() != key) renamed->push_back("config: " + renamed_note(*row, key));
    set_parameter(base, row->key(), json_value(*row, v));
  };
  auto read = [&](const auto& self, const json& object, const std::string& prefix) -> void {
    for (const auto& [name, value] : object.items()) {
      const std::string key = prefix + name;
      if (!sections.count(key)) {
        set(key, value);
      } else if (!value.is_object()) {
        throw InputError("field " + key + ": expected an object, got " +
                         detail::json_excerpt(value));
      } else {
        self(self, value, key + ".");
      }
    }
  };
  read(read, j, "");
  validate(base);
  return base;
}

}  // namespace

json to_json(const SegmentParams& params) {
  return to_json_with(params, segment_parameters());
}

SegmentParams params_from_json(const json& j, SegmentParams base,
                               std::vector<std::string>* renamed) {
  return from_json_with(j, base, segment_parameters(), renamed);
}

json to_json(const DescriptorParams& d) {
  return {{"voxel_size", d.voxel_size},
          {"normal_radius", d.normal_radius},
          {"fpfh_radii", d.fpfh_radii}};
}

json to_json(const RecognitionParams& params) {
  return to_json_with(params, recognition_parameters());
}

RecognitionParams recognition_params_from_json(const json& j, RecognitionParams base) {
  return from_json_with(j, base, recognition_parameters(), nullptr);
}

std::pair<SegmentParams, RecognitionParams> read_recognize_params(
    const std::string& path, SegmentParams seg, RecognitionParams rec,
    std::vector<std::string>* renamed) {
  const json j = detail::read_json_file(path);
  try {
    if (!j.is_object())
      throw InputError("expected {\"segmentation\": {...}, \"recognition\": {...}}");
    for (const auto& [key, value] : j.items())
      if (key != "segmentation" && key != "recognition")
        throw InputError("config: unknown key " + key +
                         " (expected \"segmentation\" and/or \"recognition\")");
    if (j.contains("segmentation")) seg = params_from_json(j.at("segmentation"), seg, renamed);
    if (j.contains("recognition")) rec = recognition_params_from_json(j.at("recognition"), rec);
  } catch (const InputError& e) {
    throw InputError(path + ": " + e.what());
  }
  return {seg, rec};
}

SegmentParams read_params(const std::string& path, SegmentParams base,
                          std::vector<std::string>* renamed) {
  const json j = detail::read_json_file(path);
  try {
    return params_from_json(j, base, renamed);
  } catch (const InputError& e) {
    throw InputError(path + ": " + e.what());
  }
}

}  // namespace proxseg
