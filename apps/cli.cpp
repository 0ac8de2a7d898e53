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

void describe_app(CLI::App& app) {
  app.name("proxseg");
  app.description("proxseg: unsupervised RGB-D segmentation and object recognition");
  // The docs/*.md that the help texts name, where an installed proxseg has them.
  app.footer("Documentation (the docs/*.md named above, the API references): "
             "/usr/share/doc/proxseg-doc (Debian package proxseg-doc), or share/doc/proxseg-doc "
             "under the install prefix; man proxseg.");
  app.set_version_flag("--version", std::string("proxseg ") + proxseg::version() + " (commit " +
                                        proxseg::git_commit() + ")");
  app.require_subcommand(1);
  // Also after the command (`proxseg segment -q ...`): the commands pass what they do not know
  // to the program's options.
  app.fallthrough();
  app.add_flag_callback(
      "-q,--quiet", [] { set_verbosity(Verbosity::kQuiet); },
      "Say only warnings and errors on stderr (no notes, no progress)");
  app.add_flag_callback(
      "-v,--verbose", [] { set_verbosity(Verbosity::kVerbose); },
      "Say also the steps behind a result (recognition's trials)");
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

// "proxseg: error: WHAT" and where the help is, on stderr.
void say_usage_error(CLI::App& app, const CLI::ParseError& e) {
  CLI::App* cmd = chosen_command(app);
  std::string path = cmd->get_name();
  for (const CLI::App* p = cmd->get_parent(); p; p = p->get_parent())
    path = p->get_name() + " " + path;
  std::cerr << "proxseg: error: " << not_understood(app, cmd, e) << "\n"
            << "Run `" << path << " --help` for the options.\n";
}

}  // namespace

int run_app(CLI::App& app, int argc, char** argv, const std::function<int()>& dispatch) {
  try {
    app.parse(argc, argv);
    return dispatch();
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

std::string input_name(const SegmentOptions& o) {
  if (!o.batch.empty()) return o.batch.front();
  return o.input.empty() ? o.colour : o.input;
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

void add_scene_options(CLI::App* cmd, SegmentOptions& o, bool recognition) {
  cmd->add_option("--colour", o.colour, "Colour image (PNG/JPG) of an RGB-D pair");
  cmd->add_option("--color", o.colour)->group("");  // the other spelling
  cmd->add_option("--depth", o.depth, "16-bit depth PNG of an RGB-D pair");
  cmd->add_option("--intrinsics", o.intrinsics,
                  "JSON with fx, fy, cx, cy, depth_scale (units per metre)");
  cmd->add_option("--meta", o.meta, "YCB-Video meta JSON (intrinsic_matrix, factor_depth)");
  cmd->add_option("--preset", o.preset,
                  "Base parameters: default (best measured) or paper (the paper's settings)")
      ->check(CLI::IsMember({"default", "paper"}));
  add_parameter_flags(cmd, o.params, recognition);
}

// Preset < --config < the parameter flags.
proxseg::SegmentParams segment_params(const SegmentOptions& o, proxseg::SegmentParams p) {
  apply_parameter_flags(o.params, p, nullptr);
  proxseg::validate(p);
  return p;
}

proxseg::Frame read_input(const SegmentOptions& o) {
  if (!o.input.empty()) return proxseg::read_point_cloud(o.input);
  const proxseg::Intrinsics k =
      o.meta.empty() ? proxseg::read_intrinsics(o.intrinsics) : proxseg::read_ycb_meta(o.meta);
  return proxseg::read_rgbd(o.colour, o.depth, k);
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
}

void check_scene_options(const SegmentOptions& o, const std::vector<std::string>& outputs) {
  const bool rgbd = !o.colour.empty() || !o.depth.empty();
  if (o.input.empty() == !rgbd)
    throw CLI::ValidationError("give either INPUT or --color and --depth");
  if (rgbd && (o.colour.empty() || o.depth.empty()))
    throw CLI::ValidationError("--color and --depth go together");
  if (rgbd && o.intrinsics.empty() == o.meta.empty())
    throw CLI::ValidationError("an RGB-D pair needs exactly one of --intrinsics or --meta");
  for (const std::string& in : {o.input, o.colour, o.depth})
    for (const std::string& out : outputs)
      if (!in.empty() && std::filesystem::exists(in) && std::filesystem::exists(out) &&
          std::filesystem::equivalent(in, out))
        throw CLI::ValidationError("--output would overwrite the input " + in);
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
