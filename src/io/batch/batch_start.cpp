// The start of a batch run (batch_start.hpp).
#include <proxseg/io/batch_start.hpp>
#include <proxseg/io/output.hpp>

#include <algorithm>
#include <set>

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
  // An earlier run's finished frames: skipped on resume, else counted (they are done again).
  const std::set<std::string> finished = finished_frames(out_dir, &b.damaged);
  for (const FrameSource& f : b.frames) {
    const bool done = finished.count(f.id) > 0;
    if (done && plan.resume) continue;
    b.redone += done;
    b.todo.push_back(f);
  }
  if (!plan.resume) b.damaged.clear();  // nothing of the earlier logs is used
  b.log = std::make_unique<SummaryLog>(out_dir, summary_name(plan.shard, plan.shards), header,
                                       plan.resume);  // locked: this shard is ours
  if (plan.resume) remove_stale_temporaries(out_dir, b.todo);
  return b;
}

}  // namespace proxseg
