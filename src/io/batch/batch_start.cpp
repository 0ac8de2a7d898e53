// The start of a batch run (batch_start.hpp).
#include <proxseg/io/batch_start.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/output.hpp>

#include <algorithm>
#include <filesystem>
#include <set>

#include "io/batch/batch_settings.hpp"

namespace proxseg {

BatchStart start_batch(const BatchPlan& plan, const std::string& out_dir, nlohmann::json header) {
  BatchStart b;
  const std::vector<FrameSource> all = discover_frames(plan.sources, plan.naming);
  check_output_folder(plan.sources, all, out_dir);
  b.frames_all = all.size();
  b.frames = shard_frames(all, plan.shard, plan.shards);
  header["sources"] = plan.sources;
  header["shard"] =
      plan.shards > 1
          ? nlohmann::json(std::to_string(plan.shard) + "/" + std::to_string(plan.shards))
          : nlohmann::json();
  header["frames"] = b.frames.size();
  header["frames_all"] = all.size();
  header["proxseg"] = build_info();
  header["runner"] = plan.runner;
  // Before any frame is read: a folder that takes no file fails now, not after the work.
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) throw FileError(out_dir + ": cannot create the output folder (" + ec.message() + ")");
  check_writable_folder(out_dir);
  // From here until this run's header is in its log, no other batch starts in the folder: of
  // two started together with other settings, the second sees the first's header and stops.
  const detail::FolderGate gate(out_dir);
  const std::string log_name = summary_name(plan.shard, plan.shards);
  detail::check_folder_settings(out_dir, log_name + ".jsonl", header, plan.resume);
  // An earlier run's finished frames: skipped on resume when their settings and inputs are
  // this run's, else counted (they are done again).
  FinishedFrames finished =
      finished_frames(out_dir, b.frames, settings_fingerprint(header), &b.damaged);
  for (const FrameSource& f : b.frames) {
    const bool done = finished.done.count(f.id) > 0;
    if (done && plan.resume) continue;
    b.todo.push_back(f);
  }
  if (plan.resume) {
    b.changed = finished.changed;
    b.unproven = finished.unproven;
  } else {
    b.redone = finished.done.size() + finished.changed + finished.unproven;
    b.damaged.clear();  // nothing of the earlier logs is used
  }
  b.log = std::make_unique<SummaryLog>(out_dir, log_name, header,
                                       plan.resume);  // locked: this shard is ours
  if (plan.resume) remove_stale_temporaries(out_dir, b.todo);
  return b;
}

}  // namespace proxseg
