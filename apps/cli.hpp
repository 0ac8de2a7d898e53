// The commands of the proxseg CLI, one file each (segment.cpp, synth.cpp, eval.cpp, db.cpp,
// recognize.cpp; proxseg.cpp dispatches), and the pieces they share (cli.cpp).
#pragma once
#include <proxseg/core/frame.hpp>
#include <proxseg/core/pipeline.hpp>
#include <proxseg/core/recognition_types.hpp>
#include <proxseg/core/render.hpp>

#include <proxseg/io/frame_source.hpp>
#include <proxseg/io/output.hpp>
#include <proxseg/io/view_page.hpp>

#include <CLI/CLI.hpp>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "human_time.hpp"
#include "progress.hpp"

namespace cli {

// The batch flags of `segment` and `recognize` (batch.cpp, docs/batch.md).
struct BatchOptions {
  std::vector<std::string> batch;  // --batch SOURCE...: folders, list files, globs, clouds
  std::string shard;               // --shard I/N
  bool resume = false;
  proxseg::RgbdNaming naming;  // --color-pattern, --depth-pattern, --meta-pattern (+ --intrinsics)
};

// The parameter flags of a command, made from the parameter table (param_flags.cpp): what was
// given, in the order given, applied over the preset and --config by apply_parameter_flags.
struct ParamFlags {
  enum Table { kSegment, kRecognition };
  struct Given {
    Table table;
    std::string key;   // the row's key ("voxels.voxel_size")
    std::string text;  // the value as given ("true"/"false" for a bool's flag)
  };
  std::vector<Given> given;
  std::vector<std::string> sets;  // --set KEY=VALUE
};
// A flag for every row of the segmentation table that names one (and of recognition's when
// recognition), hidden aliases, and --set.
void add_parameter_flags(CLI::App* cmd, ParamFlags& out, bool recognition);
// Sets what flags holds in seg (and rec): a value that does not parse, or an unknown --set key,
// is a usage error naming the flag (with "did you mean"). Setting a parameter of stages 2-4
// (voxels, features, clustering, k-means, MRF) asks for the paper's labels, which it changes.
// The ranges are validate()'s, afterwards.
void apply_parameter_flags(const ParamFlags& flags, proxseg::SegmentParams& seg,
                           proxseg::RecognitionParams* rec);
// Logs each deprecation note of --config's old keys (proxseg::renamed_note) as a warning.
void warn_renamed(const std::vector<std::string>& notes);

// The headings of the commands' --help (CLI11 option groups): every option is under one, in this
// order where a command has them (the order in which a command adds its options).
namespace group {
inline constexpr const char* kInput = "Input";
inline constexpr const char* kOutput = "Output";
inline constexpr const char* kBatch = "Batch";
inline constexpr const char* kParameters = "Parameters";
inline constexpr const char* kSegmentation = "Segmentation parameters";
inline constexpr const char* kRecognition = "Recognition parameters";
inline constexpr const char* kResources = "Threads and memory";
inline constexpr const char* kMessages = "Messages";
inline constexpr const char* kHelp = "Help";
}  // namespace group
// Puts -h,--help last, under "Help": call after a command's other options.
void help_last(CLI::App* cmd);

// The scene input and the segmentation flags of `segment` and `recognize` (scene_io.cpp).
struct SegmentOptions : BatchOptions {
  std::string input, colour, depth, intrinsics, meta;
  std::string outputs = "pcd,png,json";       // --outputs
  const CLI::Option* outputs_flag = nullptr;  // --outputs, to tell it given from its default
  std::string preset = "default";
  ParamFlags params;
};
// INPUT (a cloud, or - for standard input) and the flags of an RGB-D pair, under "Input".
void add_input_options(CLI::App* cmd, SegmentOptions& o, const std::string& input_help);
// --preset, --config (its help: config_help) and the segmentation table's flags (and
// recognition's), under "Parameters" and the tables' headings.
void add_parameter_options(CLI::App* cmd, SegmentOptions& o, std::string& config,
                           const std::string& config_help, bool recognition);
// Usage checks: INPUT or an RGB-D pair, - (standard input) only as INPUT, and no output path equal
// to an input.
void check_scene_options(const SegmentOptions& o, const std::vector<std::string>& outputs);
// base (preset, config) < the parameter flags; validated.
proxseg::SegmentParams segment_params(const SegmentOptions& o, proxseg::SegmentParams base);
// INPUT (standard input for -) or the RGB-D pair.
proxseg::Frame read_input(const SegmentOptions& o);
// A cloud named on the command line: the file, or standard input for - (PCD or PLY by content).
proxseg::Frame read_cloud(const std::string& path);
// What messages and reports call that cloud: path, or "<stdin>" for -.
std::string cloud_name(const std::string& path);
// A usage error when value is - where standard input is not read: "FLAG takes a file here, not -
// (standard input): WHAT".
void no_stdin(const std::string& value, const std::string& flag, const std::string& what);

// Where one scene's results go, from -o, --outputs and --json (docs/cli.md).
struct SceneDestination {
  std::string prefix;  // the files' prefix; "" when no file is written
  proxseg::OutputSet files{false, false, false, false, false};  // written beside prefix
  bool report_to_stdout = false;                                // the JSON report on stdout
};
// -o PREFIX: the --outputs files beside PREFIX, and the report on stdout with --json. -o -: the
// JSON report on stdout and nothing else (an --outputs given may hold only json). No -o: the
// report on stdout with --json; nothing written with --outputs none; else a usage error when
// prefix_required ("--output is required ..."). A file kind asked for with -o - or without -o is
// a usage error that says why.
SceneDestination scene_destination(const SegmentOptions& o, const std::string& output, bool json,
                                   bool prefix_required);
// One line on stderr when the input has no colour and that takes feature blocks off the
// segmentation (colourless_note): "proxseg: INPUT has no colour: the colour and texture blocks
// are off". Nothing otherwise.
void print_colourless_note(const std::string& input, const proxseg::Frame& frame,
                           const proxseg::SegmentParams& params);
// How much the CLI says on stderr: -q/--quiet only warnings and errors, -v/--verbose also the
// steps behind a result (recognition's split and merge trials). Set once from the command line;
// process-wide like interrupted().
enum class Verbosity { kQuiet, kNormal, kVerbose };
void set_verbosity(Verbosity v);
Verbosity verbosity();
// std::cerr when the verbosity is at least `level`, else a stream that drops what it is given:
// for the CLI's notes and progress lines (warnings and errors always go to std::cerr).
std::ostream& say(Verbosity level = Verbosity::kNormal);
// A progress bar of total steps, silent under --quiet.
inline Progress progress_bar(std::size_t total) {
  return Progress(total, verbosity() == Verbosity::kQuiet);
}

// "1 object", "3 objects": n and the noun, plural unless n is 1.
std::string counted(std::size_t n, const std::string& noun);
// Creates the parent directory of path and checks that files can be made in it (InputError
// naming it if not): called before the input is read.
void make_parent(const std::string& path);

// --outputs: proxseg::parse_outputs, a usage error when the list is wrong.
proxseg::OutputSet outputs_option(const std::string& list);
// --batch and what goes with it (--shard, --resume, the RGB-D naming patterns).
void add_batch_options(CLI::App* cmd, BatchOptions& o);
// Usage checks of a batch: no single-scene input beside --batch, no - (standard input) in it, a
// well-formed --shard.
void check_batch_options(const SegmentOptions& o);
// A batch's -o: a folder (neither missing nor -).
void check_batch_output(const std::string& output);
// Runs job over the frames of o.batch (this shard's; with --resume, those not yet finished) in
// natural order, with a progress bar: each row goes to OUT/<summary>.jsonl as it is done, and the
// run's summary to OUT/<summary>.json (proxseg::summarize), also on stdout with --json. header
// holds the command's "command", "parameters" (and "database"); the rest is added here. An
// interrupt stops between frames. Returns the exit code: 0, 1 when a frame failed,
// kInterruptedExit. workers > 1: that many frames at once (each job then runs on one thread),
// their rows in the order they finish.
int run_batch(const SegmentOptions& o, const std::string& out_dir, bool json, nlohmann::json header,
              const std::function<nlohmann::json(const proxseg::FrameSource&)>& job,
              int workers = 1);

// Interrupts (SIGINT, SIGTERM) during batch work: after catch_interrupts(), the first one only
// sets interrupted(), so that the batch stops between items with whole output files and writes
// a summary of what was done; a second one ends the process at once (the default action).
void catch_interrupts();
bool interrupted();
// The commands that need recognition or evaluation (their libraries, SQLite, OpenMP): they are
// the program proxseg-tools, which `proxseg` runs in its own place (exec, same arguments), so
// that a process that segments loads none of them (docs/architecture.md). `proxseg --help` lists
// them with these descriptions.
struct ToolCommand {
  const char* name;
  const char* about;
};
inline constexpr ToolCommand kToolCommands[] = {
    {"db", "Build or inspect a model database (paper 3.4)"},
    {"recognize", "Name every candidate object of a scene from a model database (paper 3.4)"},
    {"eval-seg", "Score a segmentation against ground truth (docs/metrics.md), or a whole folder"},
    {"synth", "Write the built-in synthetic tabletop scene (with ground truth)"},
};
// The description of a tool command; "" for another name.
const char* tool_about(const std::string& name);

// Parses argv into app and runs the chosen command (dispatch returns its exit code): the help
// (exit 0), a usage error (2), InputError or another error, memory exhaustion included (1,
// "proxseg: error: ..." on stderr).
int run_app(CLI::App& app, int argc, char** argv, const std::function<int()>& dispatch);
// A program's main: runs it, and turns memory exhausted before or after run_app (building the
// command line's parser, loading libraries' state) into exit 1 with "proxseg: error: out of
// memory" instead of an abort.
int guarded_main(const std::function<int()>& main);
// What a command works on, for messages: its INPUT ("<stdin>" for -), the colour image of its
// pair, or "--batch"'s sources.
std::string input_name(const SegmentOptions& o);
// Runs command; memory exhausted in it becomes an InputError "INPUT: out of memory while
// DOING", another failure that is neither an InputError nor a usage error "INPUT: WHAT (while
// DOING)" (exit 1), so that the message names the frame.
int naming_input(const std::string& input, const char* doing, const std::function<int()>& command);
// The application both programs start from: its name, description and --version.
void describe_app(CLI::App& app);
// The main of both programs (proxseg, proxseg-tools), in guarded_main: the allocator settings for
// frame-after-frame work, the described app, `commands` adding the program's commands and
// returning what runs the parsed one, then run_app.
int program_main(int argc, char** argv,
                 const std::function<std::function<int()>(CLI::App&)>& commands);

// Exit code of a batch stopped by an interrupt (128 + SIGINT, the shell's convention).
constexpr int kInterruptedExit = 130;

// `proxseg segment`
struct SegmentCommand : SegmentOptions {
  std::string output, config, candidates_dir;
  bool json = false;
};
void add_segment(CLI::App& app, SegmentCommand& o);
int run_segment(const SegmentCommand& o);

// `proxseg summary OUT`: merges a batch's shard summaries
struct SummaryOptions {
  std::string output;
  bool json = false;
};
void add_summary(CLI::App& app, SummaryOptions& o);
int run_summary(const SummaryOptions& o);

// `proxseg params`: the parameter table
struct ParamsOptions {
  std::string table = "all";
  bool json = false, markdown = false;
};
void add_params(CLI::App& app, ParamsOptions& o);
int run_params(const ParamsOptions& o);

// `proxseg view`
struct ViewCommandOptions {
  std::string prefix, output, title;
  std::size_t max_points = proxseg::ViewOptions{}.max_points;
};
void add_view(CLI::App& app, ViewCommandOptions& o);
int run_view(const ViewCommandOptions& o);

// `proxseg synth`
struct SynthOptions {
  std::string output;
  unsigned seed = 1;
  double noise = proxseg::SynthParams{}.depth_noise;
  bool clutter = false;          // --clutter: proxseg::clutter_scene (docs/clutter.md)
  std::string kind = "clutter";  // --kind: proxseg::clutter_kind
  unsigned count = 0, first_seed = 1;
  std::string models;
};
void add_synth(CLI::App& app, SynthOptions& o);
int run_synth(const SynthOptions& o);

// `proxseg eval-seg`
struct EvalOptions {
  std::string truth, predicted, field, batch, pred_dir, output, config;
  std::string preset = "default";
  std::optional<int> threads;
  bool json = false;
};
void add_eval(CLI::App& app, EvalOptions& o);
int run_eval(const EvalOptions& o);

// `proxseg db add|render|info`
struct DbOptions {
  std::string dir, name, new_name, xyz, mesh, units = "m";
  std::vector<std::string> views;
  bool accumulate = false, json = false;
  int render_views = 8;
  double distance = 0, noise = 0;
  unsigned seed = 1;
  std::optional<double> voxel_size, normal_radius;
  std::vector<double> fpfh_radii;
  CLI::App *add = nullptr, *render = nullptr, *info = nullptr, *check = nullptr, *upgrade = nullptr,
           *remove = nullptr, *rename = nullptr;
};
void add_db(CLI::App& app, DbOptions& o);
int run_db(const DbOptions& o);

// `proxseg recognize`
struct RecognizeOptions : SegmentOptions {
  std::string db, output, object, config;
  bool json = false;
};
void add_recognize(CLI::App& app, RecognizeOptions& o);
int run_recognize(const RecognizeOptions& o);

}  // namespace cli
