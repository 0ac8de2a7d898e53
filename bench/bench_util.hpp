// Small helpers shared by the benchmarks' report headers.
#pragma once
#include <cstdio>
#include <string>

namespace proxseg::bench {

// The short commit of the working tree the benchmark runs in ("unknown" outside git).
inline std::string git_commit() {
  FILE* p = popen("git rev-parse --short HEAD 2>/dev/null", "r");
  if (!p) return "unknown";
  char buf[64] = {0};
  const bool ok = std::fgets(buf, sizeof buf, p) != nullptr;
  pclose(p);
  std::string s = ok ? buf : "unknown";
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
  return s;
}

}  // namespace proxseg::bench
