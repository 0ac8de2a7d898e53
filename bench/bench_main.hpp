// The start and the end every benchmark program shares: its main (allocator settings, options,
// exit codes as the CLI's) and the writing of its results.
#pragma once
#include <proxseg/core/errors.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/memory.hpp>

#include <CLI/CLI.hpp>
#include <exception>
#include <filesystem>
#include <functional>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

namespace proxseg::bench {

// The output folder `dir`, made when missing; an InputError when it cannot be.
inline std::filesystem::path output_folder(const std::string& dir) {
  const std::filesystem::path out(dir);
  std::error_code ec;
  std::filesystem::create_directories(out, ec);
  if (ec || !std::filesystem::is_directory(out))
    throw InputError(dir + ": cannot create the output folder (" + ec.message() + ")");
  return out;
}

// Writes each (file name, text) into `out`, atomically, then prints the summary: its JSON with
// --json, else the markdown report. Returns the exit code, 0.
inline int finish(const std::filesystem::path& out,
                  const std::vector<std::pair<std::string, std::string>>& files,
                  const nlohmann::json& summary, const std::string& markdown, bool json) {
  for (const auto& [name, text] : files) write_file_atomic((out / name).string(), text);
  if (json)
    std::cout << summary.dump(2) << "\n";
  else
    std::cout << markdown;
  return 0;
}

// An option checked against [lo, hi], its default shown in --help.
template <class T, class R>
CLI::Option* add_ranged(CLI::App& app, const std::string& flag, T& value, const std::string& help,
                        R lo, R hi) {
  return app.add_option(flag, value, help)->check(CLI::Range(lo, hi))->capture_default_str();
}

// A benchmark's main: the CLI's allocator settings (so that times compare with the CLI's and the
// other benchmarks'), the options parsed into `app`, then `run`. Help exits 0, a usage error 2
// (also one `run` finds, thrown as a CLI::ParseError), any other error 1 with "NAME: error:
// MESSAGE" (an InputError: bad models, config or output).
inline int main_of(const char* name, CLI::App& app, int argc, char** argv,
                   const std::function<int()>& run) {
  keep_freed_memory();
  try {
    app.parse(argc, argv);
    return run();
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);  // prints the help (code 0) or the usage error
    return code == 0 ? 0 : 2;
  } catch (const std::exception& e) {
    std::cerr << name << ": error: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace proxseg::bench
