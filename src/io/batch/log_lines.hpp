// Reading a batch's summary log (OUT/summary*.jsonl) line by line, each line parsed and checked,
// damaged ones reported and skipped (docs/batch.md). Private to the library.
#pragma once
#include <cstddef>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

namespace proxseg::detail {

// Visits the whole lines of a summary log, parsed and checked, in order: visit(line, number) for
// each good one, damaged(message, frame) for one that is not (its file and number, what is wrong,
// and the frame it may have named, "" when none can be read); reading goes on after it. Only a
// last line without its newline (the half-written row of a killed run) is not whole: it is left
// out without a word. One line at a time: a log of a million frames is never all in memory.
// Returns where the whole lines end.
std::size_t for_each_log_line(
    const std::string& path, const std::function<void(nlohmann::json& line, std::size_t)>& visit,
    const std::function<void(const std::string& message, const std::string& frame)>& damaged);

// A damaged line as a warning: what is done about it.
std::string skipped(const std::string& message, const std::string& frame);

}  // namespace proxseg::detail
