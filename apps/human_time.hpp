// Durations as people read them, for every time the CLI prints for a person (its summary lines,
// notes and progress bars; JSON reports keep the raw numbers): three significant digits below a
// minute ("0.42 ms", "51.6 ms", "516 ms", "1.23 s", "12.3 s"), then minutes and seconds
// ("2 min 05 s"), then hours and minutes ("1 h 02 min").
#pragma once

#include <cmath>
#include <cstdio>
#include <string>

namespace cli {

inline std::string human_time(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  char text[48];
  const double ms = seconds * 1e3;
  // Each range ends where its rounding would print the next range's first value ("1000 ms").
  if (ms < 9.995)
    std::snprintf(text, sizeof text, "%.2f ms", ms);
  else if (ms < 99.95)
    std::snprintf(text, sizeof text, "%.1f ms", ms);
  else if (ms < 999.5)
    std::snprintf(text, sizeof text, "%.0f ms", ms);
  else if (seconds < 9.995)
    std::snprintf(text, sizeof text, "%.2f s", seconds);
  else if (seconds < 59.95)
    std::snprintf(text, sizeof text, "%.1f s", seconds);
  else if (const long s = std::lround(seconds); s < 3600)
    std::snprintf(text, sizeof text, "%ld min %02ld s", s / 60, s % 60);
  else if (const long m = std::lround(seconds / 60); m < 60 * 1000000L)
    std::snprintf(text, sizeof text, "%ld h %02ld min", m / 60, m % 60);
  else
    return "over a million hours";
  return text;
}

// The same for a duration in milliseconds (the reports' "times_ms").
inline std::string human_ms(double ms) {
  return human_time(ms / 1e3);
}

}  // namespace cli
