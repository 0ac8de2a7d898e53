// The CLI's parameter flags, made from the parameter table (core/parameters.hpp): one flag per
// row that names one, its help with the default in effect and the paper's value, hidden
// aliases, and `--set KEY=VALUE` for every row.
#include <proxseg/core/errors.hpp>
#include <proxseg/core/parameters.hpp>

#include <iostream>
#include <set>
#include <sstream>

#include "cli.hpp"

namespace cli {

using proxseg::InputError;
using proxseg::Parameter;
using proxseg::ParamType;

namespace {

// "Voxel side [3.1] (default 0.02 m, as the paper)", "w_c ... (default 0.05; paper 0.275)"
std::string flag_help(const Parameter& row) {
  const std::string value = proxseg::format_parameter(row.default_value);
  if (row.type == ParamType::kBool) {
    const bool off_flag = row.flag.rfind("no-", 0) == 0;
    std::string help = row.help + (off_flag ? ": this flag switches it off (on by default"
                                            : ": this flag switches it on (off by default");
    if (!row.paper.empty())
      help += row.paper == value ? ", as the paper"
                                 : std::string("; paper: ") + (row.paper == "true" ? "on" : "off");
    return help + ")";
  }
  std::string help = row.help + " (default " + value + (row.unit.empty() ? "" : " " + row.unit);
  if (!row.paper.empty()) help += row.paper == value ? ", as the paper" : "; paper " + row.paper;
  return help + ")";
}

// The rows of the command's resources (threads, memory) rather than of the method.
bool resource_row(const Parameter& row) {
  return row.key() == "threads" || row.key() == "max_memory_mib";
}

// The --help heading of a row's flag.
const char* group_of(const Parameter& row, ParamFlags::Table table) {
  if (resource_row(row)) return group::kResources;
  return table == ParamFlags::kSegment ? group::kSegmentation : group::kRecognition;
}

void add_flag_of(CLI::App* cmd, const Parameter& row, ParamFlags::Table table, ParamFlags& out) {
  const auto record = [&out, table, key = row.key()](const std::string& text) {
    out.given.push_back({table, key, text});
  };
  const bool is_bool = row.type == ParamType::kBool;
  const std::string value = row.flag.rfind("no-", 0) == 0 ? "false" : "true";
  auto add = [&](const std::string& flag, bool hidden) {
    CLI::Option* opt =
        is_bool ? cmd->add_flag_callback(
                      "--" + flag, [record, value] { record(value); }, flag_help(row))
                : cmd->add_option_function<std::string>("--" + flag, record, flag_help(row));
    if (!is_bool) {
      opt->type_name(row.type == ParamType::kChoice ? "{" + row.range_text() + "}"
                     : row.type == ParamType::kReal ? "REAL"
                                                    : "INT");
    }
    opt->group(hidden ? "" : group_of(row, table));
  };
  add(row.flag, false);
  for (const std::string& alias : row.aliases) add(alias, true);
}

// parse_parameter's message without its leading "KEY: " (the flag says which).
std::string without_key(const Parameter& row, const std::string& message) {
  const std::string key = row.key() + ": ";
  return message.rfind(key, 0) == 0 ? message.substr(key.size()) : message;
}

// KEY=VALUE of --set, or a usage error.
std::pair<std::string, std::string> split_set(const std::string& item) {
  const auto eq = item.find('=');
  if (eq == std::string::npos || eq == 0)
    throw CLI::ValidationError("--set " + item + ": expected KEY=VALUE (e.g. voxel_size=0.01)");
  return {item.substr(0, eq), item.substr(eq + 1)};
}

// The stages whose parameters change the paper's labels (2-4): setting one asks for them.
bool changes_labels(const Parameter& row) {
  static const std::set<std::string> stages = {"voxels", "features", "clustering", "kmeans", "mrf"};
  return stages.count(row.section) > 0;
}

}  // namespace

void add_parameter_flags(CLI::App* cmd, ParamFlags& out, bool recognition) {
  // Under their headings in this order: segmentation, recognition, threads and memory.
  for (const Parameter& row : proxseg::segment_parameters())
    if (!row.flag.empty() && !resource_row(row)) add_flag_of(cmd, row, ParamFlags::kSegment, out);
  if (recognition)
    for (const Parameter& row : proxseg::recognition_parameters())
      if (!row.flag.empty()) add_flag_of(cmd, row, ParamFlags::kRecognition, out);
  for (const Parameter& row : proxseg::segment_parameters())
    if (!row.flag.empty() && resource_row(row)) add_flag_of(cmd, row, ParamFlags::kSegment, out);
  cmd->add_option("--set", out.sets,
                  std::string("Any parameter: KEY=VALUE, KEY as `proxseg params` lists it "
                              "(section.name, or the name alone when one section has it") +
                      (recognition ? "; recognition's too" : "") + "); repeatable")
      ->type_name("KEY=VALUE")
      ->group(group::kParameters);
}

void apply_parameter_flags(const ParamFlags& flags, proxseg::SegmentParams& seg,
                           proxseg::RecognitionParams* rec) {
  bool labels = false;
  auto set_seg = [&](const Parameter& row, const std::string& text, const std::string& what) {
    try {
      proxseg::set_parameter(seg, row.key(), proxseg::parse_parameter(row, text));
    } catch (const InputError& e) {
      throw CLI::ValidationError(what + ": " + without_key(row, e.what()));
    }
    labels = labels || changes_labels(row);
  };
  auto set_rec = [&](const Parameter& row, const std::string& text, const std::string& what) {
    try {
      proxseg::set_parameter(*rec, row.key(), proxseg::parse_parameter(row, text));
    } catch (const InputError& e) {
      throw CLI::ValidationError(what + ": " + without_key(row, e.what()));
    }
  };
  for (const ParamFlags::Given& g : flags.given) {
    const auto& table = g.table == ParamFlags::kSegment ? proxseg::segment_parameters()
                                                        : proxseg::recognition_parameters();
    const Parameter& row = proxseg::require_parameter(table, g.key);
    const std::string what = "--" + row.flag;
    if (g.table == ParamFlags::kSegment) {
      set_seg(row, g.text, what);
      // One --threads for the whole command.
      if (rec && row.key() == "threads") set_rec(row, g.text, what);
    } else if (rec) {
      set_rec(row, g.text, what);
    }
  }
  for (const std::string& item : flags.sets) {
    auto [key, text] = split_set(item);
    const std::string what = "--set " + item;
    // recognize: "segmentation." or "recognition." may say which table.
    bool only_seg = false, only_rec = false;
    if (rec && key.rfind("segmentation.", 0) == 0) key = key.substr(13), only_seg = true;
    if (rec && key.rfind("recognition.", 0) == 0) key = key.substr(12), only_rec = true;
    const Parameter* s =
        only_rec ? nullptr : proxseg::find_parameter(proxseg::segment_parameters(), key);
    const Parameter* r = !rec || only_seg
                             ? nullptr
                             : proxseg::find_parameter(proxseg::recognition_parameters(), key);
    if (!s && !r) {
      std::string owners;  // a bare name that several sections have
      for (const Parameter& row : proxseg::segment_parameters())
        if (row.name == key) owners += (owners.empty() ? "" : ", ") + row.key();
      if (!owners.empty())
        throw CLI::ValidationError(what + ": " + key + " is in several sections: give one of " +
                                   owners);
      std::vector<Parameter> both = proxseg::segment_parameters();
      if (rec)
        both.insert(both.end(), proxseg::recognition_parameters().begin(),
                    proxseg::recognition_parameters().end());
      const std::string near = proxseg::nearest_parameter(both, key);
      throw CLI::ValidationError(what + ": unknown parameter " + key +
                                 (near.empty() ? "" : " (did you mean " + near + "?)") +
                                 "; `proxseg params` lists them");
    }
    if (s) set_seg(*s, text, what);
    if (r) set_rec(*r, text, what);
    if (const std::string note = s ? proxseg::renamed_note(*s, key) : ""; !note.empty())
      std::cerr << "proxseg: warning: --set " << note << "\n";
  }
  if (labels) seg.paper_labels = true;
}

void warn_renamed(const std::vector<std::string>& notes) {
  for (const std::string& note : notes) std::cerr << "proxseg: warning: " << note << "\n";
}

}  // namespace cli
