// Reading a batch's summary log line by line (log_lines.hpp): each line parsed and checked
// against what batches write, a damaged one reported with its file and line.
#include "io/batch/log_lines.hpp"

#include <fstream>

namespace proxseg::detail {
namespace {

// What is wrong with a parsed line of a summary log, "" when nothing: a header or an end is an
// object; a frame's row names its frame with a string, its outputs as {file: bytes} and its
// error as a string.
std::string line_problem(const nlohmann::json& j) {
  if (!j.is_object()) return "not a JSON object";
  if (j.contains("header")) {
    const nlohmann::json& h = j["header"];
    if (!h.is_object()) return "\"header\" is not an object";
    for (const char* count : {"frames", "frames_all"})
      if (h.contains(count) && !h[count].is_number_unsigned())
        return "the header's \"" + std::string(count) + "\" is not a count";
    if (h.contains("shard") && !h["shard"].is_null() && !h["shard"].is_string())
      return "the header's \"shard\" is not a string";
    return "";
  }
  if (j.contains("end")) return j["end"].is_object() ? "" : "\"end\" is not an object";
  if (!j.contains("frame")) return "neither a header, a frame's row nor an end";
  if (!j["frame"].is_string()) return "\"frame\" is not a string";
  if (j.contains("error") && !j["error"].is_string()) return "\"error\" is not a string";
  if (j.contains("fingerprint") && !j["fingerprint"].is_string())
    return "\"fingerprint\" is not a string";
  // The inputs' sizes and times (resume compares them with the files'): whole numbers.
  for (const char* stamps : {"input_sizes", "input_mtimes_ns"})
    if (j.contains(stamps)) {
      if (!j[stamps].is_array()) return "\"" + std::string(stamps) + "\" is not an array";
      for (const auto& n : j[stamps])
        if (!n.is_number_integer())
          return "\"" + std::string(stamps) + "\" holds what is not a whole number";
    }
  if (j.contains("outputs")) {
    if (!j["outputs"].is_object()) return "\"outputs\" is not an object";
    for (const auto& [file, bytes] : j["outputs"].items())
      if (!bytes.is_number_unsigned()) return "\"outputs\" has a size that is no byte count";
  }
  return "";
}

// The frame a damaged line may have named: the JSON string after its first "frame": ("" when
// there is none to read). Scanned by hand: std::regex recurses per character, and a damaged line
// may be megabytes long.
std::string frame_named_in(const std::string& line) {
  const std::size_t key = line.find("\"frame\"");
  if (key == std::string::npos) return "";
  std::size_t i = line.find_first_not_of(" \t", key + 7);
  if (i == std::string::npos || line[i] != ':') return "";
  i = line.find_first_not_of(" \t", i + 1);
  if (i == std::string::npos || line[i] != '"') return "";
  std::size_t end = i + 1;
  while (end < line.size() && line[end] != '"') end += line[end] == '\\' ? 2 : 1;
  if (end >= line.size()) return "";
  const nlohmann::json id = nlohmann::json::parse(line.substr(i, end - i + 1), nullptr, false);
  return id.is_string() ? id.get<std::string>() : "";
}

}  // namespace

std::size_t for_each_log_line(
    const std::string& path, const std::function<void(nlohmann::json& line, std::size_t)>& visit,
    const std::function<void(const std::string& message, const std::string& frame)>& damaged) {
  std::ifstream in(path, std::ios::binary);
  std::size_t end = 0, number = 0;
  std::string line;
  while (std::getline(in, line)) {
    if (in.eof()) break;  // no newline after it: not whole
    ++number;
    end += line.size() + 1;
    nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
    const std::string problem = j.is_discarded() ? "not JSON" : line_problem(j);
    if (problem.empty())
      visit(j, number);
    else
      damaged(path + ":" + std::to_string(number) + ": damaged line (" + problem + ")",
              frame_named_in(line));
  }
  return end;
}

// A damaged line as a warning: what is done about it.
std::string skipped(const std::string& message, const std::string& frame) {
  return message + "; skipped" + (frame.empty() ? "" : ", frame " + frame + " is done again");
}

}  // namespace proxseg::detail
