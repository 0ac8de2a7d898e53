// `segment --batch` and `recognize --batch`: the frames of a dataset, sharded and resumable,
// logged frame by frame (docs/batch.md); and `proxseg summary`, which merges shard summaries.
#include <proxseg/core/memory.hpp>
#include <proxseg/io/batch.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/output.hpp>

#include <CLI/CLI.hpp>

#include <atomic>
#include <exception>
#include <filesystem>
#include <iostream>
#include <mutex>
#include <regex>
#include <string>
#include <thread>
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
                  "and OUT/summary.json");
  cmd->add_option("--shard", o.shard,
                  "Only shard I of N (e.g. 2/3; by a hash of the frame's name, stable as the "
                  "dataset grows); its summary is OUT/summary.shard-I-of-N.*; `proxseg summary "
                  "OUT` merges the shards'");
  cmd->add_flag("--resume", o.resume,
                "Skip the frames an earlier run into OUT finished (outputs whole, as its "
                "summary recorded them); a killed run's other frames are done again");
  cmd->add_option("--colour-pattern", o.naming.color,
                  "RGB-D pairs in a batch: colour image name, {id} = the frame's name")
      ->capture_default_str();
  cmd->add_option("--color-pattern", o.naming.color)->group("");  // the other spelling
  cmd->add_option("--depth-pattern", o.naming.depth, "RGB-D pairs: depth image name")
      ->capture_default_str();
  cmd->add_option("--meta-pattern", o.naming.meta,
                  "RGB-D pairs: per-frame camera JSON (YCB-Video meta or intrinsics), used when "
                  "present; else --intrinsics")
      ->capture_default_str();
}

namespace {

// "I/N" -> {I, N}; a usage error otherwise.
std::pair<int, int> parse_shard(const std::string& shard) {
  if (shard.empty()) return {1, 1};
  std::smatch m;
  if (std::regex_match(shard, m, std::regex(R"(([0-9]{1,6})/([0-9]{1,6}))"))) {
    const int i = std::stoi(m[1]), n = std::stoi(m[2]);
    if (i >= 1 && i <= n) return {i, n};
  }
  throw CLI::ValidationError("--shard " + shard + ": expected I/N with 1 <= I <= N, e.g. 2/3");
}

// A progress bar with the rate and the time left.
std::string rate_and_eta(std::size_t done, std::size_t total, double seconds) {
  if (done == 0 || seconds <= 0) return "";
  const double rate = done / seconds;
  const long left = static_cast<long>((total - done) / rate + 0.5);
  char text[64];
  std::snprintf(text, sizeof text, "%.2f frames/s, ETA %ld:%02ld:%02ld", rate, left / 3600,
                left / 60 % 60, left % 60);
  return text;
}

}  // namespace

void check_batch_options(const SegmentOptions& o) {
  if (o.batch.empty()) {
    if (!o.shard.empty() || o.resume)
      throw CLI::ValidationError("--shard and --resume go with --batch");
    return;
  }
  if (!o.input.empty() || !o.color.empty() || !o.depth.empty() || !o.meta.empty())
    throw CLI::ValidationError(
        "--batch takes the frames instead of INPUT or --color/--depth/--meta");
  parse_shard(o.shard);
}

int run_batch(const SegmentOptions& o, const std::string& out_dir, bool json, nlohmann::json header,
              const std::function<nlohmann::json(const proxseg::FrameSource&)>& job, int workers) {
  const auto [shard, shards] = parse_shard(o.shard);
  proxseg::RgbdNaming naming = o.naming;
  naming.intrinsics = o.intrinsics;
  const auto all = proxseg::discover_frames(o.batch, naming);
  try {
    proxseg::check_output_folder(o.batch, all, out_dir);
  } catch (const InputError& e) {
    throw CLI::ValidationError(e.what());
  }
  const auto frames = proxseg::shard_frames(all, shard, shards);
  header["sources"] = o.batch;
  const std::string shard_name = std::to_string(shard) + "/" + std::to_string(shards);
  header["shard"] = shards > 1 ? nlohmann::json(shard_name) : nlohmann::json();
  header["frames"] = frames.size();
  header["frames_all"] = all.size();
  header["proxseg"] = proxseg::build_info();
  header["runner"] = "cli";
  std::vector<std::string> damaged;  // lines of the earlier logs that could not be read
  const std::set<std::string> finished =
      o.resume ? proxseg::finished_frames(out_dir, &damaged) : std::set<std::string>{};
  for (const std::string& d : damaged) std::cerr << "proxseg: warning: " << d << "\n";
  if (!o.resume) {
    // An earlier run's finished frames are done again: say so before they are overwritten.
    std::vector<std::string> ignored;
    std::size_t before = 0;
    for (const std::string& id : proxseg::finished_frames(out_dir, &ignored))
      before += std::any_of(frames.begin(), frames.end(),
                            [&](const proxseg::FrameSource& f) { return f.id == id; });
    if (before > 0)
      say() << "proxseg: note: " << out_dir << " holds " << counted(before, "frame")
            << " an earlier run finished; doing them again (--resume skips them)\n";
  }
  std::vector<proxseg::FrameSource> todo;
  for (const auto& f : frames)
    if (!finished.count(f.id)) todo.push_back(f);
  const std::string name = proxseg::summary_name(shard, shards);
  proxseg::SummaryLog log(out_dir, name, header, o.resume);  // locked: this shard is ours
  if (o.resume) proxseg::remove_stale_temporaries(out_dir, todo);
  say() << "proxseg: " << counted(frames.size(), "frame")
        << (shards > 1 ? " in shard " + shard_name + " of " + std::to_string(all.size()) : "")
        << (o.resume ? ", " + std::to_string(frames.size() - todo.size()) + " done before" : "")
        << "\n";

  catch_interrupts();
  Progress progress = progress_bar(todo.size());
  const auto start = std::chrono::steady_clock::now();
  std::size_t failed = 0, done = 0;
  // Workers take the next frame until none is left; a row is logged as its frame finishes.
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
        log.append(row);
        ++done;
        if (row.contains("error")) {
          ++failed;
          std::cerr << "proxseg: error: " << row["error"].get<std::string>() << "\n";
        }
        const double s =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        progress.step(f.id + (row.contains("error") ? " (failed)" : "") + "  " +
                      rate_and_eta(done, todo.size(), s));
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
  log.close(interrupted(), proxseg::peak_resident_mib());

  const nlohmann::json summary = proxseg::summarize({log.path()}, shards == 1);
  const std::string summary_json = (fs::path(out_dir) / (name + ".json")).string();
  proxseg::write_file_atomic(summary_json, summary.dump(2) + "\n");
  if (json)
    std::cout << summary.dump(2) << "\n";
  else
    std::cout << summary_json << ": " << summary["frames_done"].get<std::size_t>() << " of "
              << counted(frames.size(), "frame") << " done"
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
  cmd->add_flag("--json", o.json, "Print the merged summary on stdout");
}

int run_summary(const SummaryOptions& o) {
  std::error_code ec;
  if (!fs::is_directory(o.output, ec))
    throw proxseg::FileError(o.output + ": not a folder (expected a batch's output folder)");
  const nlohmann::json summary = proxseg::summarize(proxseg::summary_logs(o.output), true);
  for (const auto& d : summary["damaged_lines"])
    std::cerr << "proxseg: warning: " << d.get<std::string>() << "\n";
  const std::string path = (fs::path(o.output) / "summary.json").string();
  proxseg::write_file_atomic(path, summary.dump(2) + "\n");
  if (o.json)
    std::cout << summary.dump(2) << "\n";
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
