// Shared pieces of the libFuzzer harnesses (fuzz/README.md): a private scratch directory,
// splitting one fuzz input into several files, and the rule that a reader may only answer
// with a result or an InputError.
#pragma once
#include <proxseg/core/errors.hpp>
#include <proxseg/core/frame.hpp>

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

namespace fuzz {

// Separates the files packed into one input (multi-file harnesses; make_seeds writes them).
inline constexpr std::string_view kPart = "\n@@proxseg-fuzz-part@@\n";

// A scratch directory of this process (tmpfs when there is one: the readers take paths), removed
// at exit.
inline std::filesystem::path make_scratch() {
  const std::filesystem::path base = std::filesystem::is_directory("/dev/shm")
                                         ? "/dev/shm"
                                         : std::filesystem::temp_directory_path();
  auto d = base / ("proxseg-fuzz-" + std::to_string(::getpid()));
  std::filesystem::create_directories(d);
  return d;
}
inline void remove_scratch();
inline const std::filesystem::path& scratch() {
  static const std::filesystem::path dir = make_scratch();
  // Registered after dir is constructed, so that it runs before dir is destroyed (registering it
  // inside dir's initialiser made it run after: a use after free at exit, found by ASan).
  [[maybe_unused]] static const bool cleanup = (std::atexit(remove_scratch), true);
  return dir;
}
inline void remove_scratch() {
  std::error_code ec;
  std::filesystem::remove_all(scratch(), ec);
}

inline std::string write(const std::string& name, std::string_view bytes) {
  const auto path = scratch() / name;
  std::filesystem::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(bytes.data(), bytes.size());
  return path.string();
}

// The parts of a packed input; missing parts are empty.
inline std::vector<std::string_view> split(const std::uint8_t* data, std::size_t size,
                                           std::size_t parts) {
  std::string_view rest(reinterpret_cast<const char*>(data), size);
  std::vector<std::string_view> out;
  while (out.size() + 1 < parts) {
    const auto at = rest.find(kPart);
    if (at == std::string_view::npos) break;
    out.push_back(rest.substr(0, at));
    rest.remove_prefix(at + kPart.size());
  }
  out.push_back(rest);
  out.resize(parts);
  return out;
}

// Runs a reader: a result or an InputError is an answer; anything else (another exception,
// which the CLI would print without naming the file or field) is a finding.
template <class F>
bool answers(const char* what, F&& read) {
  try {
    read();
    return true;
  } catch (const proxseg::InputError&) {
    return false;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: not an InputError: %s\n", what, e.what());
    std::abort();
  }
}

// A frame a reader returned must be consistent, or the stages after it would read garbage.
inline void check_frame(const proxseg::Frame& f) {
  const bool ok = f.width >= 0 && f.height >= 1 &&
                  static_cast<std::size_t>(f.width) * f.height == f.xyz.size() &&
                  (f.rgb.empty() || f.rgb.size() == f.xyz.size()) &&  // no colour, or one each
                  (f.label.empty() || f.label.size() == f.xyz.size()) && f.valid_count() > 0;
  if (!ok) {
    std::fprintf(stderr, "inconsistent frame: %dx%d, %zu points, %zu colours, %zu labels\n",
                 f.width, f.height, f.xyz.size(), f.rgb.size(), f.label.size());
    std::abort();
  }
}

}  // namespace fuzz
