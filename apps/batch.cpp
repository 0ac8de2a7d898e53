// `segment --batch` and `recognize --batch`: the frames of a dataset, sharded and resumable,
// logged frame by frame (docs/batch.md); and `proxseg summary`, which merges shard summaries.
#include <proxseg/core/errors.hpp>
#include <proxseg/io/batch.hpp>
#include <proxseg/io/batch_start.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/memory.hpp>
#include <proxseg/io/output.hpp>

#include <CLI/CLI.hpp>

#include <atomic>
#include <exception>
#include <filesystem>
#include <iostream>
#include <mutex>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "cli.hpp"

namespace cli {

namespace fs = std::filesystem;
using proxseg::InputError;

proxseg::OutputSet outputs_option(const std::string& list) {
  try {
    return proxseg::parse_outputs(list);
  } catch (const InputError& e) {
    throw CLI::ValidationError(e.what());
  }
}

void add_batch_options(CLI::App* cmd, BatchOptions& o) {
  cmd->add_option("--batch", o.batch,
                  "Work through a dataset: folders (recursive), list files, globs (quoted) or "
                  ".pcd/.ply files; frames are clouds and RGB-D pairs. -o is then a folder: "
                  "OUT/<frame>.* per frame, OUT/summary.jsonl (one line per frame, as done) "
                  "and OUT/summary.json")
      ->group(group::kBatch);
  cmd->add_option("--shard", o.shard,
                  "Only shard I of N (e.g. 2/3; by a hash of the frame's name, stable as the "
                  "dataset grows); its summary is OUT/summary.shard-I-of-N.*; `proxseg summary "
                  "OUT` merges the shards'")
      ->group(group::kBatch);
  cmd->add_flag("--resume", o.resume,
                "Skip the frames an earlier run into OUT finished (outputs whole, as its "
                "summary recorded them, and inputs of the same size and time); a killed run's "
                "other frames, and those whose input changed, are done again")
      ->group(group::kBatch);
  cmd->add_option("--colour-pattern", o.naming.colour,
                  "RGB-D pairs in a batch: colour image name, {id} = the frame's name")
      ->capture_default_str()
      ->group(group::kBatch);
  cmd->add_option("--color-pattern", o.naming.colour)->group("");  // the other spelling
  cmd->add_option("--depth-pattern", o.naming.depth, "RGB-D pairs: depth image name")
      ->capture_default_str()
      ->group(group::kBatch);
  cmd->add_option("--meta-pattern", o.naming.meta,
                  "RGB-D pairs: per-frame camera JSON (YCB-Video meta or intrinsics), used when "
                  "present; else --intrinsics")
      ->capture_default_str()
      ->group(group::kBatch);
}

namespace {

// "I/N" -> {I, N}; a usage error otherwise.
std::pair<int, int> parse_shard(const std::string& shard) {
  if (shard.empty()) return {1, 1};
  // Two numbers of 1 to 6 digits around one slash (no sign, no space).
  auto number = [](const std::string& digits, int& out) {
    if (digits.empty() || digits.size() > 6) return false;
    for (char c : digits)
      if (c < '0' || c > '9') return false;
    out = std::stoi(digits);
    return true;
  };
  const std::size_t slash = shard.find('/');
  int i = 0, n = 0;
  if (slash != std::string::npos && number(shard.substr(0, slash), i) &&
      number(shard.substr(slash + 1), n) && i >= 1 && i <= n)
    return {i, n};
  throw CLI::ValidationError("--shard " + shard + ": expected I/N with 1 <= I <= N, e.g. 2/3");
}

// The progress bar's rate and time left, from the frames finished well so far (a failed frame is
// often quick: counting it would tell of a rate no frame is done at); "" before the first.
std::string rate_and_eta(std::size_t ok, std::size_t done, std::size_t total, double seconds) {
  if (ok == 0 || seconds <= 0) return "";
  const double rate = ok / seconds;
  char text[32];
  std::snprintf(text, sizeof text, "%.2f frames/s", rate);
  return text + (", ETA " + human_time((total - done) / rate));
}

}  // namespace

void check_batch_options(const SegmentOptions& o) {
  if (o.batch.empty()) {
    if (!o.shard.empty() || o.resume)
      throw CLI::ValidationError("--shard and --resume go with --batch");
    return;
  }
  if (!o.input.empty() || !o.colour.empty() || !o.depth.empty() || !o.meta.empty())
    throw CLI::ValidationError(
        "--batch takes the frames instead of INPUT or --colour/--depth/--meta");
  for (const std::string& source : o.batch)
    no_stdin(source, "--batch",
             "a batch reads folders, list files, globs and clouds by name; - is for one cloud, "
             "INPUT");
  parse_shard(o.shard);
}

void check_batch_output(const std::string& output) {
  if (output.empty())
    throw CLI::ValidationError("--output is required: with --batch, the folder of the outputs");
  if (output == "-")
    throw CLI::ValidationError(
        "-o -: a batch writes a folder (one report per frame and a summary), not stdout; give "
        "-o OUT (--json prints the summary on stdout)");
}

namespace {

// The frames, the summary log and what the user is told before the first frame.
proxseg::BatchStart start(const SegmentOptions& o, const std::string& out_dir,
                          nlohmann::json header) {
  proxseg::BatchPlan plan;
  plan.sources = o.batch;
  plan.naming = o.naming;
  plan.naming.intrinsics = o.intrinsics;
  std::tie(plan.shard, plan.shards) = parse_shard(o.shard);
  plan.resume = o.resume;
  proxseg::BatchStart b;
  try {
    b = proxseg::start_batch(plan, out_dir, std::move(header));
  } catch (const proxseg::OutputFolderError& e) {
    throw CLI::ValidationError(e.what());
  }
  for (const std::string& d : b.damaged) std::cerr << "proxseg: warning: " << d << "\n";
  if (b.redone > 0)
    say() << "proxseg: note: " << out_dir << " holds " << counted(b.redone, "frame")
          << " an earlier run finished; doing them again (--resume skips them)\n";
  if (b.changed > 0)
    say() << "proxseg: note: " << counted(b.changed, "frame")
          << " whose input changed (size or time) since an earlier run finished them; doing "
          << (b.changed == 1 ? "it" : "them") << " again\n";
  if (b.unproven > 0)
    say() << "proxseg: note: " << counted(b.unproven, "frame")
          << " logged without their inputs' size and time or the settings' fingerprint (an "
             "older proxseg's log); doing "
          << (b.unproven == 1 ? "it" : "them") << " again\n";
  const std::string shard_name = std::to_string(plan.shard) + "/" + std::to_string(plan.shards);
  say() << "proxseg: " << counted(b.frames.size(), "frame")
        << (plan.shards > 1 ? " in shard " + shard_name + " of " + std::to_string(b.frames_all)
                            : "")
        << (o.resume ? ", " + std::to_string(b.frames.size() - b.todo.size()) + " done before" : "")
        << "\n";
  return b;
}

// Runs the job on the frames to do, `workers` frames side by side; each row is logged as its
// frame finishes. Returns the frames that failed.
std::size_t run_frames(proxseg::BatchStart& b,
                       const std::function<nlohmann::json(const proxseg::FrameSource&)>& job,
                       int workers) {
  const std::vector<proxseg::FrameSource>& todo = b.todo;
  Progress progress = progress_bar(todo.size());
  const auto start = std::chrono::steady_clock::now();
  std::size_t failed = 0, done = 0;
  // Workers take the next frame until none is left.
  std::atomic<std::size_t> next{0};
  std::mutex logging;
  std::exception_ptr error;
  auto work = [&] {
    try {
      for (std::size_t i; !interrupted() && (i = next++) < todo.size();) {
        const proxseg::FrameSource& f = todo[i];
        const nlohmann::json row = job(f);
        const std::lock_guard<std::mutex> lock(logging);
        if (error) return;
        b.log->append(row);
        ++done;
        if (row.contains("error")) {
          ++failed;
          std::cerr << "proxseg: error: " << row["error"].get<std::string>() << "\n";
        }
        const double s =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        progress.step(f.id + (row.contains("error")
                                  ? " (failed)"
                                  : "  " + rate_and_eta(done - failed, done, todo.size(), s)));
      }
    } catch (...) {
      const std::lock_guard<std::mutex> lock(logging);
      if (!error) error = std::current_exception();
      next = todo.size();  // the others stop after their frame
    }
  };
  const int n = std::max(1, std::min<int>(workers, static_cast<int>(todo.size())));
  if (n == 1) {
    work();
  } else {
    std::vector<std::thread> threads;
    for (int k = 0; k < n; ++k) threads.emplace_back(work);
    for (auto& t : threads) t.join();
  }
  if (error) std::rethrow_exception(error);
  return failed;
}

}  // namespace

int run_batch(const SegmentOptions& o, const std::string& out_dir, bool json, nlohmann::json header,
              const std::function<nlohmann::json(const proxseg::FrameSource&)>& job, int workers) {
  proxseg::BatchStart b = start(o, out_dir, std::move(header));
  catch_interrupts();
  const std::size_t failed = run_frames(b, job, workers);
  b.log->close(interrupted(), proxseg::peak_resident_mib());

  const auto [shard, shards] = parse_shard(o.shard);
  const nlohmann::json summary = proxseg::summarize({b.log->path()}, shards == 1);
  const std::string summary_json =
      (fs::path(out_dir) / (proxseg::summary_name(shard, shards) + ".json")).string();
  proxseg::write_file_atomic(summary_json, proxseg::json_text(summary, 2) + "\n");
  if (json)
    std::cout << proxseg::json_text(summary, 2) << "\n";
  else
    std::cout << summary_json << ": " << summary["frames_done"].get<std::size_t>() << " of "
              << counted(b.frames.size(), "frame") << " done"
              << (failed ? ", " + std::to_string(failed) + " failed" : "")
              << (interrupted() ? " (interrupted)" : "") << "\n";
  if (interrupted()) return kInterruptedExit;
  return summary["frames_failed"].get<std::size_t>() > 0 ? 1 : 0;
}

void add_summary(CLI::App& app, SummaryOptions& o) {
  auto* cmd = app.add_subcommand(
      "summary",
      "Merge the summaries of a batch's shards (OUT/summary*.jsonl) into OUT/summary.json");
  cmd->add_option("output", o.output, "The batch's output folder")->required();
  cmd->add_flag("--json", o.json, "Print the merged summary on stdout")->group(group::kOutput);
  help_last(cmd);
}

int run_summary(const SummaryOptions& o) {
  std::error_code ec;
  if (!fs::is_directory(o.output, ec))
    throw proxseg::FileError(o.output + ": not a folder (expected a batch's output folder)");
  const nlohmann::json summary = proxseg::summarize(proxseg::summary_logs(o.output), true);
  for (const auto& d : summary["damaged_lines"])
    std::cerr << "proxseg: warning: " << d.get<std::string>() << "\n";
  const std::string path = (fs::path(o.output) / "summary.json").string();
  proxseg::write_file_atomic(path, proxseg::json_text(summary, 2) + "\n");
  if (o.json)
    std::cout << proxseg::json_text(summary, 2) << "\n";
  else
    std::cout << path << ": " << counted(summary["shards"].size(), "log") << ", "
              << summary["frames_done"].get<std::size_t>() << " of "
              << counted(summary["frames_total"].get<std::size_t>(), "frame") << " done, "
              << summary["frames_failed"].get<std::size_t>() << " failed, "
              << summary["frames_missing"].get<std::size_t>() << " missing\n";
  return summary["frames_failed"].get<std::size_t>() +
                     summary["frames_missing"].get<std::size_t>() >
                 0
             ? 1
             : 0;
}

}  // namespace cli
