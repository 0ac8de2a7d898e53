// proxseg command-line tool: proxseg <command> [options]. Logs on stderr, results on stdout or
// files. Exit codes: 0 success, 1 bad input, 2 usage. One file per command (cli.hpp).
// This program segments (segment, summary) and loads only proxseg's core and io libraries; the
// commands of kToolCommands run in proxseg-tools (proxseg_tools.cpp), which it executes in its
// own place with the same arguments, so that a segmenting process loads neither.

#include <unistd.h>
#include <CLI/CLI.hpp>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <string>
#include <system_error>

#include "cli.hpp"

namespace fs = std::filesystem;
using namespace cli;

namespace {

// proxseg-tools beside this program (the build tree) or in ../libexec/proxseg (an install).
fs::path tools_program() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  const fs::path dir = ec ? fs::path(".") : self.parent_path();
  for (const fs::path& p : {dir / "proxseg-tools", dir / "../libexec/proxseg/proxseg-tools"})
    if (fs::exists(p, ec)) return p;
  return dir / "../libexec/proxseg/proxseg-tools";
}

// Replaces this process with proxseg-tools; returns only when that fails (exit code 1).
int run_tools(char** argv, const std::string& command) {
  const fs::path tools = tools_program();
  ::execv(tools.c_str(), argv);
  std::cerr << "proxseg: error: cannot run " << tools.string() << " for `" << command
            << "`: " << std::strerror(errno) << "\n";
  return 1;
}

// The command given: the first argument that is not an option. The program's own options
// (-q, -v: flags, taking no value) may come before it, as in git (`proxseg -q db info DB`).
std::string command_of(int argc, char** argv) {
  for (int i = 1; i < argc; ++i)
    if (argv[i][0] != '-' || argv[i][1] == '\0') return argv[i];
  return "";
}

}  // namespace

int main(int argc, char** argv) {
  if (const std::string command = command_of(argc, argv); tool_about(command)[0] != '\0')
    return run_tools(argv, command);
  SegmentCommand segment;
  SummaryOptions summary;
  ParamsOptions params;
  ViewCommandOptions view;
  return program_main(argc, argv, [&](CLI::App& app) -> std::function<int()> {
    add_segment(app, segment);
    // Listed in the help; never parsed here (run_tools above).
    for (const ToolCommand& c : kToolCommands) app.add_subcommand(c.name, c.about);
    add_summary(app, summary);
    add_params(app, params);
    add_view(app, view);
    return [&] {
      if (app.got_subcommand("segment"))
        return naming_input(input_name(segment), "segmenting it",
                            [&] { return run_segment(segment); });
      if (app.got_subcommand("summary")) return run_summary(summary);
      if (app.got_subcommand("params")) return run_params(params);
      if (app.got_subcommand("view")) return run_view(view);
      return 2;
    };
  });
}
