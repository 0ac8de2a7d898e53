// The parameter table (parameters.hpp) made from its rows (parameter_rows.txt) and the members
// they name (parameter_members.hpp): the rows with their types, defaults and the paper's values,
// reading and setting a parameter by key, parsing and formatting values, ranges and the nearest
// name for a mistyped key.
#include <proxseg/core/errors.hpp>
#include <proxseg/core/parameters.hpp>

#include "parameter_members.hpp"
#include "parameter_rows.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <type_traits>

namespace proxseg {
namespace {

template <class T>
constexpr bool kIsEnum = std::is_enum_v<T>;

template <class T>
ParamType type_of() {
  if constexpr (std::is_same_v<T, bool>) return ParamType::kBool;
  if constexpr (std::is_same_v<T, int>) return ParamType::kInt;
  if constexpr (std::is_same_v<T, std::uint64_t>) return ParamType::kUnsigned;
  if constexpr (std::is_same_v<T, double>) return ParamType::kReal;
  return ParamType::kChoice;
}

template <class T>
ParamValue value_of(const T& v) {
  if constexpr (kIsEnum<T>)
    return value_names(v)[static_cast<int>(v)];
  else
    return v;
}

// Per ParamType, in the enum's order: its name in the table and what a value of it looks like
// (a choice lists its names instead).
struct TypeText {
  const char* name;
  const char* expected;
};
constexpr TypeText kTypeText[] = {{"bool", "true or false"},
                                  {"int", "an integer"},
                                  {"uint64", "a non-negative integer"},
                                  {"real", "a number"},
                                  {"choice", nullptr}};

std::string type_expected(const Parameter& row) {
  if (const char* text = kTypeText[static_cast<int>(row.type)].expected) return text;
  std::string s;
  for (std::size_t i = 0; i < row.choices.size(); ++i)
    s += (i == 0                        ? ""
          : i + 1 == row.choices.size() ? " or "
                                        : ", ") +
         ("\"" + row.choices[i] + "\"");
  return s;
}

[[noreturn]] void wrong_value(const Parameter& row, const ParamValue& value) {
  std::string got = format_parameter(value);
  if (std::holds_alternative<std::string>(value)) got = "\"" + got + "\"";
  throw InputError("field " + row.key() + ": expected " + type_expected(row) + ", got " + got);
}

template <class T>
void assign(const Parameter& row, T& out, const ParamValue& value) {
  if constexpr (std::is_same_v<T, bool>) {
    if (!std::holds_alternative<bool>(value)) wrong_value(row, value);
    out = std::get<bool>(value);
  } else if constexpr (std::is_same_v<T, int>) {
    long long v = 0;
    if (const int* i = std::get_if<int>(&value))
      v = *i;
    else if (const std::uint64_t* u = std::get_if<std::uint64_t>(&value); u && *u <= 1u << 30)
      v = static_cast<long long>(*u);
    else
      wrong_value(row, value);
    out = static_cast<int>(v);
  } else if constexpr (std::is_same_v<T, std::uint64_t>) {
    if (const std::uint64_t* u = std::get_if<std::uint64_t>(&value))
      out = *u;
    else if (const int* i = std::get_if<int>(&value); i && *i >= 0)
      out = static_cast<std::uint64_t>(*i);
    else
      wrong_value(row, value);
  } else if constexpr (std::is_same_v<T, double>) {
    if (const double* d = std::get_if<double>(&value))
      out = *d;
    else if (const int* i = std::get_if<int>(&value))
      out = *i;
    else if (const std::uint64_t* u = std::get_if<std::uint64_t>(&value))
      out = static_cast<double>(*u);
    else
      wrong_value(row, value);
  } else {
    const std::string* s = std::get_if<std::string>(&value);
    if (!s) wrong_value(row, value);
    const std::vector<std::string> names = value_names(T{});
    const auto it = std::find(names.begin(), names.end(), *s);
    if (it == names.end()) wrong_value(row, value);
    out = static_cast<T>(it - names.begin());
  }
}

// A table: its rows, and for each the index of its member in for_each_parameter's order.
struct Table {
  std::vector<Parameter> rows;
  std::vector<std::size_t> member;
};

// Per member of P in for_each_parameter's order: type, choices and value in params.
template <class P>
std::vector<Parameter> describe_members(const P& params) {
  std::vector<Parameter> members;
  auto describe = [&](const auto& value) {
    using T = std::decay_t<decltype(value)>;
    Parameter& row = members.emplace_back();
    row.type = type_of<T>();
    if constexpr (kIsEnum<T>) row.choices = value_names(value);
    row.default_value = value_of(value);
  };
  detail::for_each_parameter(params, describe);
  return members;
}

// A row of the text (parameter_rows.txt) with the type, choices and default of its member, and
// the paper's value from the paper preset where the text says "preset".
Parameter joined_row(Parameter row, const Parameter& member, const Parameter* paper) {
  row.type = member.type;
  row.choices = member.choices;
  row.default_value = member.default_value;
  if (row.type == ParamType::kUnsigned) row.min = 0;
  if (row.paper == "preset") row.paper = paper ? format_parameter(paper->default_value) : "";
  return row;
}

// The rows of parameter_rows.txt's table `which`, joined to the members of P by key; every
// member must have one row. paper: the paper preset, for the rows whose paper value it is.
template <class P>
Table make_table(const std::string& which, const P* paper) {
  std::vector<std::string> keys;
  detail::add_member_keys<P>("", keys);
  const std::vector<Parameter> members = describe_members(P{});
  const std::vector<Parameter> paper_members = paper ? describe_members(*paper) : members;
  Table table;
  for (const Parameter& text : detail::table_rows(which)) {
    const std::size_t m = std::find(keys.begin(), keys.end(), text.key()) - keys.begin();
    if (m == keys.size())
      throw std::logic_error("parameter_rows.txt: " + text.key() + " is no member of " + which);
    if (std::find(table.member.begin(), table.member.end(), m) != table.member.end())
      throw std::logic_error("parameter_rows.txt: " + text.key() + " has two rows");
    table.rows.push_back(joined_row(text, members[m], paper ? &paper_members[m] : nullptr));
    table.member.push_back(m);
  }
  if (table.rows.size() != keys.size())
    for (std::size_t m = 0; m < keys.size(); ++m)
      if (std::find(table.member.begin(), table.member.end(), m) == table.member.end())
        throw std::logic_error("parameter_rows.txt: no row for " + keys[m] + " (" + which + ")");
  return table;
}

const Table& segment_table() {
  static const Table table = [] {
    const SegmentParams paper = preset("paper");
    return make_table<SegmentParams>("segmentation", &paper);
  }();
  return table;
}

const Table& recognition_table() {
  static const Table table = make_table<RecognitionParams>("recognition", nullptr);
  return table;
}

// The value of key's member in params.
template <class P>
ParamValue get_with(const Table& table, const P& params, const std::string& key) {
  const Parameter& row = require_parameter(table.rows, key);
  const std::size_t target = table.member[&row - table.rows.data()];
  ParamValue out;
  std::size_t i = 0;
  auto read = [&](const auto& member) {
    if (i++ == target) out = value_of(member);
  };
  detail::for_each_parameter(params, read);
  return out;
}

template <class P>
void set_with(const Table& table, P& params, const std::string& key, const ParamValue& value) {
  const Parameter& row = require_parameter(table.rows, key);
  const std::size_t target = table.member[&row - table.rows.data()];
  std::size_t i = 0;
  auto write = [&](auto& member) {
    if (i++ == target) assign(row, member, value);
  };
  detail::for_each_parameter(params, write);
}

// The name part of the row's old key ("image_normal_step"); "" when it has none.
std::string old_name(const Parameter& row) {
  return row.old_key.empty() ? "" : row.old_key.substr(row.old_key.rfind('.') + 1);
}

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j)
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] != b[j - 1])});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

std::string number_text(double v) {
  std::ostringstream s;
  s.precision(15);
  s << v;
  return s.str();
}

}  // namespace

std::string Parameter::key() const {
  return section.empty() ? name : section + "." + name;
}

std::string Parameter::type_name() const {
  return kTypeText[static_cast<int>(type)].name;
}

std::string Parameter::range_text() const {
  if (type == ParamType::kBool) return "true | false";
  if (type == ParamType::kChoice) {
    std::string s;
    for (const std::string& c : choices) s += (s.empty() ? "" : " | ") + c;
    return s;
  }
  const std::string u = unit.empty() ? "" : " " + unit;
  std::string s;
  const bool low = std::isfinite(min), high = std::isfinite(max);
  if (low && high && !min_open && !max_open && (min != 0 || max != 1 || !unit.empty()))
    s = number_text(min) + " .. " + number_text(max) + u;
  else if (low && high)
    s = std::string("in ") + (min_open ? "(" : "[") + number_text(min) + ", " + number_text(max) +
        (max_open ? ")" : "]") + u;
  else if (low)
    s = (min_open ? "> " : ">= ") + number_text(min) + u;
  else if (high)
    s = (max_open ? "< " : "<= ") + number_text(max) + u;
  else
    s = "any";
  return zero_off ? "0 (off) or " + s : s;
}

const std::vector<Parameter>& segment_parameters() {
  return segment_table().rows;
}

const std::vector<Parameter>& recognition_parameters() {
  return recognition_table().rows;
}

const Parameter* find_parameter(const std::vector<Parameter>& table, const std::string& key) {
  const Parameter* bare = nullptr;
  int bare_count = 0;
  for (const Parameter& row : table) {
    if (row.key() == key || (!row.old_key.empty() && row.old_key == key)) return &row;
    if (row.name == key || old_name(row) == key) bare = &row, ++bare_count;
  }
  return bare_count == 1 ? bare : nullptr;
}

std::string renamed_note(const Parameter& row, const std::string& key) {
  if (row.old_key.empty() || (key != row.old_key && key != old_name(row))) return "";
  return key + " is now " + row.key() + " (the old key will be removed)";
}

const Parameter& require_parameter(const std::vector<Parameter>& table, const std::string& key) {
  if (const Parameter* row = find_parameter(table, key)) return *row;
  std::string owners;
  for (const Parameter& row : table)
    if (row.name == key) owners += (owners.empty() ? "" : ", ") + row.key();
  if (!owners.empty())
    throw InputError("parameter " + key + " is in several sections: give one of " + owners);
  const std::string near = nearest_parameter(table, key);
  throw InputError("unknown parameter " + key +
                   (near.empty() ? "" : " (did you mean " + near + "?)"));
}

std::string nearest_parameter(const std::vector<Parameter>& table, const std::string& key) {
  std::vector<std::string> keys;
  for (const Parameter& row : table) keys.push_back(row.key());
  if (std::string near = closest_name(key, keys); !near.empty()) return near;
  // The name in the wrong section ("mrf.voxel_size"), or at the top level without its section.
  const std::string bare = key.substr(key.rfind('.') == std::string::npos ? 0 : key.rfind('.') + 1);
  for (const Parameter& row : table)
    if (row.name == bare) return row.key();
  return "";
}

ParamValue get_parameter(const SegmentParams& params, const std::string& key) {
  return get_with(segment_table(), params, key);
}
ParamValue get_parameter(const RecognitionParams& params, const std::string& key) {
  return get_with(recognition_table(), params, key);
}
void set_parameter(SegmentParams& params, const std::string& key, const ParamValue& value) {
  set_with(segment_table(), params, key, value);
}
void set_parameter(RecognitionParams& params, const std::string& key, const ParamValue& value) {
  set_with(recognition_table(), params, key, value);
}

std::string format_parameter(const ParamValue& value) {
  return std::visit(
      [](const auto& v) -> std::string {
        using T = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<T, bool>)
          return v ? "true" : "false";
        else if constexpr (std::is_same_v<T, std::string>)
          return v;
        else if constexpr (std::is_same_v<T, double>)
          return number_text(v);
        else
          return std::to_string(v);
      },
      value);
}

ParamValue parse_parameter(const Parameter& row, const std::string& text) {
  auto fail = [&]() -> ParamValue {
    throw InputError(row.key() + ": expected " + type_expected(row) + ", got \"" + text + "\"");
  };
  switch (row.type) {
    case ParamType::kBool:
      if (text == "true" || text == "1" || text == "on" || text == "yes") return true;
      if (text == "false" || text == "0" || text == "off" || text == "no") return false;
      return fail();
    case ParamType::kInt:
    case ParamType::kUnsigned: {
      if (text.empty() || (row.type == ParamType::kUnsigned && text[0] == '-')) return fail();
      errno = 0;
      char* end = nullptr;
      if (row.type == ParamType::kUnsigned) {
        const unsigned long long v = std::strtoull(text.c_str(), &end, 10);
        if (errno || *end) return fail();
        return static_cast<std::uint64_t>(v);
      }
      const long long v = std::strtoll(text.c_str(), &end, 10);
      if (errno || *end || v < std::numeric_limits<int>::min() ||
          v > std::numeric_limits<int>::max())
        return fail();
      return static_cast<int>(v);
    }
    case ParamType::kReal: {
      errno = 0;
      char* end = nullptr;
      const double v = std::strtod(text.c_str(), &end);
      if (text.empty() || *end || std::isnan(v) || (!errno && std::isinf(v))) return fail();
      // Out of a double's range: a subnormal is still a number (the range check judges it), an
      // overflow or an underflow to zero is named as such, not as "not a number".
      if (errno == ERANGE && (std::isinf(v) || v == 0))
        throw InputError(row.key() + ": expected " + type_expected(row) + ", got \"" + text +
                         "\" (" +
                         (v == 0 ? "too small for a double: it rounds to 0"
                                 : "too large for a double: at most 1.8e308") +
                         ")");
      if (errno && errno != ERANGE) return fail();
      return v;
    }
    case ParamType::kChoice:
      if (std::find(row.choices.begin(), row.choices.end(), text) == row.choices.end()) {
        const std::string near = closest_name(text, row.choices);
        throw InputError(row.key() + ": expected " + type_expected(row) + ", got \"" + text + "\"" +
                         (near.empty() ? "" : " (did you mean " + near + "?)"));
      }
      return text;
  }
  return fail();
}

bool in_range(const Parameter& row, const ParamValue& value) {
  if (row.type == ParamType::kBool || row.type == ParamType::kChoice) return true;
  double v = 0;
  if (const int* i = std::get_if<int>(&value)) v = *i;
  if (const std::uint64_t* u = std::get_if<std::uint64_t>(&value)) v = static_cast<double>(*u);
  if (const double* d = std::get_if<double>(&value)) v = *d;
  if (!std::isfinite(v)) return false;
  if (row.zero_off && v == 0) return true;
  const bool low = row.min_open ? v > row.min : v >= row.min;
  const bool high = row.max_open ? v < row.max : v <= row.max;
  return low && high;
}

std::string closest_name(const std::string& name, const std::vector<std::string>& candidates) {
  std::string best;
  std::size_t best_distance = std::numeric_limits<std::size_t>::max();
  for (const std::string& c : candidates) {
    const std::size_t d = edit_distance(name, c);
    if (d < best_distance) best_distance = d, best = c;
  }
  // A likely typo: at most a third of the letters, or the one name that contains the other.
  if (best_distance <= std::max<std::size_t>(1, name.size() / 3)) return best;
  for (const std::string& c : candidates)
    if (name.size() >= 4 && c.find(name) != std::string::npos) return c;
  return "";
}

}  // namespace proxseg
