// The pieces shared by the commands of the proxseg CLI (cli.hpp).
#include <proxseg/core/errors.hpp>
#include <proxseg/core/parameters.hpp>
#include <proxseg/core/pipeline.hpp>
#include <proxseg/core/version.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/memory.hpp>
#include <proxseg/io/output.hpp>
#include <proxseg/io/params.hpp>

#include <sys/resource.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "cli.hpp"

namespace cli {

using proxseg::InputError;

const char* tool_about(const std::string& name) {
  for (const ToolCommand& c : kToolCommands)
    if (name == c.name) return c.about;
  return "";
}

namespace {
// CLI11's help with one blank line between the headings of the option groups, not two.
class HelpFormatter : public CLI::Formatter {
 public:
  std::string make_help(const CLI::App* app, std::string name,
                        CLI::AppFormatMode mode) const override {
    std::string text = CLI::Formatter::make_help(app, std::move(name), mode);
    for (std::size_t at; (at = text.find("\n\n\n")) != std::string::npos;) text.erase(at, 1);
    return text;
  }
};
}  // namespace

void describe_app(CLI::App& app) {
  app.name("proxseg");
  app.formatter(std::make_shared<HelpFormatter>());  // the commands added later take it too
  app.description("proxseg: unsupervised RGB-D segmentation and object recognition");
  // The docs/*.md that the help texts name, where an installed proxseg has them.
  app.footer(
      "Documentation (the docs/*.md named above, the API references): "
      "/usr/share/doc/proxseg-doc (Debian package proxseg-doc), or share/doc/proxseg-doc "
      "under the install prefix; man proxseg.");
  app.require_subcommand(1);
  // Also after the command (`proxseg segment -q ...`): the commands pass what they do not know
  // to the program's options.
  app.fallthrough();
  app.add_flag_callback(
         "-q,--quiet", [] { set_verbosity(Verbosity::kQuiet); },
         "Say only warnings and errors on stderr (no notes, no progress)")
      ->group(group::kMessages);
  app.add_flag_callback(
         "-v,--verbose", [] { set_verbosity(Verbosity::kVerbose); },
         "Say also the steps behind a result (recognition's trials)")
      ->group(group::kMessages);
  // Under "Help", after them: the headings come in the order of their first options.
  app.set_version_flag("--version", std::string("proxseg ") + proxseg::version() + " (commit " +
                                        proxseg::git_commit() + ")")
      ->group(group::kHelp);
  help_last(&app);
}

void help_last(CLI::App* cmd) {
  // CLI11 lists the groups in the order of their first options, and adds the help flag first.
  cmd->set_help_flag();
  cmd->set_help_flag("-h,--help", "Print this help message and exit")->group(group::kHelp);
}

namespace {
// Without allocating: there may be no memory left for a message.
void say_out_of_memory() {
  const char msg[] = "proxseg: error: out of memory\n";
  [[maybe_unused]] const ssize_t w = ::write(STDERR_FILENO, msg, sizeof msg - 1);
}
// The deepest command given ("proxseg segment"), for "Run ... --help".
CLI::App* chosen_command(CLI::App& app) {
  CLI::App* cmd = &app;
  for (;;) {
    const auto subs = cmd->get_subcommands();
    if (subs.empty()) return cmd;
    cmd = subs.front();
  }
}

// "proxseg db add": the command and the commands it is under.
std::string path_of(const CLI::App* cmd) {
  std::string path = cmd->get_name();
  for (const CLI::App* p = cmd->get_parent(); p; p = p->get_parent())
    path = p->get_name() + " " + path;
  return path;
}

// What was not understood, for the message: the first unknown flag, or an unknown command.
std::string not_understood(CLI::App& app, CLI::App* cmd, const CLI::ParseError& e) {
  std::vector<std::string> extras = cmd->remaining();
  for (const std::string& x : app.remaining()) extras.push_back(x);
  std::vector<std::string> flags, commands;
  for (const CLI::Option* opt : cmd->get_options())
    if (!opt->get_group().empty())
      for (const std::string& name : opt->get_lnames()) flags.push_back("--" + name);
  for (const CLI::App* sub : cmd->get_subcommands([](const CLI::App*) { return true; }))
    commands.push_back(sub->get_name());
  auto did_you_mean = [](const std::string& near) {
    return near.empty() ? std::string() : " (did you mean " + near + "?)";
  };
  for (const std::string& x : extras)
    if (x.rfind("-", 0) == 0) {
      const std::string word = x.substr(0, x.find('='));
      return "unknown option " + word + did_you_mean(proxseg::closest_name(word, flags));
    }
  if (cmd == &app && !extras.empty())
    return "unknown command " + extras.front() +
           did_you_mean(proxseg::closest_name(extras.front(), commands));
  const std::string what = e.what();
  if (what.rfind("The following argument", 0) == 0)  // "... was not expected: X" (or were)
    return "unexpected argument " + what.substr(what.find(": ") + 2);
  return what;
}

// A command of commands (proxseg, proxseg db) given none and nothing else it did not know.
bool lacks_its_command(CLI::App& app, CLI::App* cmd, const CLI::ParseError& e) {
  return dynamic_cast<const CLI::RequiredError*>(&e) && cmd->get_subcommands().empty() &&
         !cmd->get_subcommands([](const CLI::App*) { return true; }).empty() &&
         cmd->remaining().empty() && app.remaining().empty();
}

// "proxseg: error: WHAT" and where the help is, on stderr; the help itself, for a command of
// commands given none (`proxseg`, `proxseg db`).
void say_usage_error(CLI::App& app, const CLI::ParseError& e) {
  CLI::App* cmd = chosen_command(app);
  if (lacks_its_command(app, cmd, e)) {
    // The root's help: it delegates to the command given, and names it by its whole path.
    std::cerr << app.help() << "proxseg: error: give a command: `" << path_of(cmd)
              << " COMMAND --help` for its options\n";
    return;
  }
  std::cerr << "proxseg: error: " << not_understood(app, cmd, e) << "\n"
            << "Run `" << path_of(cmd) << " --help` for the options.\n";
}

}  // namespace

int run_app(CLI::App& app, int argc, char** argv, const std::function<int()>& dispatch) {
  try {
    app.parse(argc, argv);
    const int code = dispatch();
    // What went to stdout must have arrived (a full disk, a closed pipe's reader gone): else the
    // results are lost and the exit code must say so.
    if (!std::cout.flush())
      throw proxseg::FileError("<stdout>: write error (the results printed there are lost)");
    return code;
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    say_usage_error(app, e);
    return 2;
  } catch (const InputError& e) {
    std::cerr << "proxseg: error: " << e.what() << "\n";
    return 1;
  } catch (const std::bad_alloc&) {
    say_out_of_memory();
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "proxseg: error: " << e.what() << "\n";
    return 1;
  }
}

int guarded_main(const std::function<int()>& main) {
  try {
    return main();
  } catch (const std::bad_alloc&) {
    say_out_of_memory();
    return 1;
  }
}

int program_main(int argc, char** argv,
                 const std::function<std::function<int()>(CLI::App&)>& commands) {
  return guarded_main([&] {
    proxseg::keep_freed_memory();  // batch commands reuse each frame's buffers
    CLI::App app;
    describe_app(app);
    const std::function<int()> dispatch = commands(app);
    return run_app(app, argc, argv, dispatch);
  });
}

int naming_input(const std::string& input, const char* doing, const std::function<int()>& command) {
  try {
    return command();
  } catch (const InputError&) {
    throw;  // names its file already
  } catch (const CLI::Error&) {
    throw;  // a usage error
  } catch (const std::bad_alloc&) {
    // What the failed step held is freed by now: the message has room.
    throw InputError(input + ": out of memory while " + doing +
                     " (the process could not allocate more; a smaller input, fewer --threads "
                     "or more memory)");
  } catch (const std::exception& e) {  // the system refused something else (a thread, ...)
    throw InputError(input + ": " + e.what() + " (while " + doing + ")");
  }
}

void print_colourless_note(const std::string& input, const proxseg::Frame& frame,
                           const proxseg::SegmentParams& params) {
  if (const std::string off = proxseg::colourless_note(frame, params.features); !off.empty())
    say() << "proxseg: " << input << " has no colour: " << off << "\n";
}

namespace {
Verbosity& verbosity_setting() {
  static Verbosity v = Verbosity::kNormal;
  return v;
}
}  // namespace

void set_verbosity(Verbosity v) {
  verbosity_setting() = v;
}

Verbosity verbosity() {
  return verbosity_setting();
}

std::ostream& say(Verbosity level) {
  static std::ostream dropped(nullptr);  // no buffer: every output is discarded
  return verbosity() >= level ? std::cerr : dropped;
}

std::string counted(std::size_t n, const std::string& noun) {
  return std::to_string(n) + " " + noun + (n == 1 ? "" : "s");
}

void make_parent(const std::string& path) {
  const auto parent = std::filesystem::path(path).parent_path();
  std::error_code ec;
  if (!parent.empty()) std::filesystem::create_directories(parent, ec);
  if (ec)
    throw InputError(parent.string() + ": cannot create output directory (" + ec.message() + ")");
  // A folder that exists but takes no file (read-only) fails here too, before the input is read.
  proxseg::check_writable_folder(parent.string());
}

namespace {
// The one piece of process state a signal handler may touch (async-signal-safe).
volatile std::sig_atomic_t interrupt_signal = 0;

extern "C" void on_interrupt(int sig) {
  interrupt_signal = sig;
  std::signal(sig, SIG_DFL);  // a second interrupt ends the process at once
  const char msg[] =
      "\nproxseg: interrupted: finishing the current item (interrupt again to abort)\n";
  [[maybe_unused]] const ssize_t w = ::write(STDERR_FILENO, msg, sizeof msg - 1);
}
}  // namespace

void catch_interrupts() {
  std::signal(SIGINT, on_interrupt);
  std::signal(SIGTERM, on_interrupt);
}

bool interrupted() {
  return interrupt_signal != 0;
}

}  // namespace cli
