// Reads parameter_rows.txt, the rows of the parameter table, compiled in as a string.
#include "parameter_rows.hpp"

#include <cstdlib>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace proxseg::detail {
namespace {

const char* const kRowsText =
#include "parameter_rows.txt"
    ;

[[noreturn]] void bad_line(const std::string& line, const std::string& why) {
  throw std::logic_error("parameter_rows.txt: " + why + ": " + line);
}

std::string trimmed(const std::string& s) {
  const std::size_t a = s.find_first_not_of(' '), b = s.find_last_not_of(' ');
  return a == std::string::npos ? "" : s.substr(a, b - a + 1);
}

double number(const std::string& text, const std::string& line) {
  char* end = nullptr;
  const std::string t = trimmed(text);
  const double v = std::strtod(t.c_str(), &end);
  if (t.empty() || *end) bad_line(line, "not a number in the range");
  return v;
}

// "> a", ">= a", "< b", "<= b", "[a, b]" with ( or ) for an open end, "0 or RANGE", "".
void read_range(std::string r, Parameter& row, const std::string& line) {
  if (r.rfind("0 or ", 0) == 0) row.zero_off = true, r = r.substr(5);
  if (r.empty()) return;
  if (r[0] == '[' || r[0] == '(') {
    const std::size_t comma = r.find(',');
    if (comma == std::string::npos || (r.back() != ']' && r.back() != ')'))
      bad_line(line, "expected [a, b]");
    row.min = number(r.substr(1, comma - 1), line);
    row.max = number(r.substr(comma + 1, r.size() - comma - 2), line);
    row.min_open = r[0] == '(';
    row.max_open = r.back() == ')';
  } else if (r[0] == '>' || r[0] == '<') {
    const bool closed = r.size() > 1 && r[1] == '=';
    const double v = number(r.substr(closed ? 2 : 1), line);
    (r[0] == '>' ? row.min : row.max) = v;
    (r[0] == '>' ? row.min_open : row.max_open) = !closed;
  } else {
    bad_line(line, "expected a range");
  }
}

Parameter read_row(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream in(line);
  for (std::string cell; std::getline(in, cell, '|');) cells.push_back(trimmed(cell));
  if (cells.size() != 7) bad_line(line, "expected 7 columns");
  Parameter row;
  const std::size_t dot = cells[0].rfind('.');
  row.section = dot == std::string::npos ? "" : cells[0].substr(0, dot);
  row.name = cells[0].substr(dot == std::string::npos ? 0 : dot + 1);
  row.min = -std::numeric_limits<double>::infinity();
  row.max = std::numeric_limits<double>::infinity();
  row.unit = cells[1];
  read_range(cells[2], row, line);
  std::stringstream flags(cells[3]);
  for (std::string flag; flags >> flag;) {
    if (row.flag.empty())
      row.flag = flag;
    else
      row.aliases.push_back(flag);
  }
  row.paper = cells[4];
  row.old_key = cells[5];
  row.help = cells[6];
  return row;
}

}  // namespace

std::vector<Parameter> table_rows(const std::string& table) {
  std::vector<Parameter> rows;
  std::stringstream text(kRowsText);
  std::string current;
  for (std::string line; std::getline(text, line);) {
    if (line.empty() || line[0] == '#') continue;
    if (line[0] == '[')
      current = line.substr(1, line.find(']') - 1);
    else if (current == table)
      rows.push_back(read_row(line));
  }
  if (rows.empty()) throw std::logic_error("parameter_rows.txt: no table " + table);
  return rows;
}

}  // namespace proxseg::detail
