// SegmentParams and RecognitionParams <-> JSON, row by row of the parameter table
// (core/parameters.hpp): the JSON sections are the table's.
#include <proxseg/core/parameters.hpp>
#include <proxseg/io/params.hpp>

#include <limits>
#include <set>

#include "input_file.hpp"

namespace proxseg {
namespace {

using nlohmann::json;

json value_json(const ParamValue& value) {
  return std::visit([](const auto& v) { return json(v); }, value);
}

// A JSON value as the row's type: InputError "field KEY: expected ..., got VALUE".
ParamValue json_value(const Parameter& row, const json& v) {
  auto wrong = [&](const char* expected) -> ParamValue {
    throw InputError("field " + row.key() + ": expected " + expected + ", got " + v.dump());
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
    json& where = row.section.empty() ? j : j[row.section];
    where[row.name] = value_json(get_parameter(params, row.key()));
  }
  return j;
}

// An unknown key: InputError "config: unknown key KEY (did you mean ...?)".
[[noreturn]] void unknown_key(const std::vector<Parameter>& table, const std::string& key) {
  const std::string near = nearest_parameter(table, key);
  throw InputError("config: unknown key " + key +
                   (near.empty() ? "" : " (did you mean " + near + "?)"));
}

template <class P>
P from_json_with(const json& j, P base, const std::vector<Parameter>& table) {
  if (!j.is_object()) throw InputError("config: expected a JSON object, got " + j.dump());
  std::set<std::string> sections;
  for (const Parameter& row : table)
    if (!row.section.empty()) sections.insert(row.section);
  // Unknown keys are errors: a typo must not silently leave a default in place.
  auto set = [&](const std::string& key, const json& v) {
    const Parameter* row = nullptr;
    for (const Parameter& r : table)
      if (r.key() == key) row = &r;
    if (!row) unknown_key(table, key);
    set_parameter(base, key, json_value(*row, v));
  };
  for (const auto& [key, value] : j.items()) {
    if (sections.count(key)) {
      if (!value.is_object())
        throw InputError("field " + key + ": expected an object, got " + value.dump());
      for (const auto& [sub, v] : value.items()) set(key + "." + sub, v);
    } else {
      set(key, value);
    }
  }
  validate(base);
  return base;
}

json read_json_file(const std::string& path) {
  const std::string text = detail::read_input_file(path);
  try {
    return json::parse(text);
  } catch (const json::exception& e) {  // parse errors, and numbers out of range (out_of_range.406)
    throw InputError(path + ": not valid JSON (" + e.what() + ")");
  }
}

}  // namespace

json to_json(const SegmentParams& params) {
  return to_json_with(params, segment_parameters());
}

SegmentParams params_from_json(const json& j, SegmentParams base) {
  return from_json_with(j, base, segment_parameters());
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
  return from_json_with(j, base, recognition_parameters());
}

std::pair<SegmentParams, RecognitionParams> read_recognize_params(const std::string& path,
                                                                  SegmentParams seg,
                                                                  RecognitionParams rec) {
  const json j = read_json_file(path);
  try {
    if (!j.is_object())
      throw InputError("expected {\"segmentation\": {...}, \"recognition\": {...}}");
    for (const auto& [key, value] : j.items())
      if (key != "segmentation" && key != "recognition")
        throw InputError("config: unknown key " + key +
                         " (expected \"segmentation\" and/or \"recognition\")");
    if (j.contains("segmentation")) seg = params_from_json(j.at("segmentation"), seg);
    if (j.contains("recognition")) rec = recognition_params_from_json(j.at("recognition"), rec);
  } catch (const InputError& e) {
    throw InputError(path + ": " + e.what());
  }
  return {seg, rec};
}

SegmentParams read_params(const std::string& path, SegmentParams base) {
  const json j = read_json_file(path);
  try {
    return params_from_json(j, base);
  } catch (const InputError& e) {
    throw InputError(path + ": " + e.what());
  }
}

}  // namespace proxseg
