// The start of a batch run (docs/batch.md), one function for the CLI's `--batch` and the Dask
// runner (python/proxseg/dask.py), so that both find, shard, resume and log frames alike.
#pragma once
#include <proxseg/io/batch.hpp>
#include <proxseg/io/frame_source.hpp>

#include <cstddef>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace proxseg {

// What a batch runs over.
struct BatchPlan {
  std::vector<std::string> sources;  // folders, list files, globs, cloud files (discover_frames)
  RgbdNaming naming;                 // how RGB-D pairs are named, their camera
  int shard = 1, shards = 1;         // this run does shard `shard` of `shards` (shard_frames)
  bool resume = false;               // skip the frames an earlier run into the folder finished
  std::string runner = "cli";        // who runs it, recorded in the summary's header
};

// A batch run, ready for its first frame.
struct BatchStart {
  std::size_t frames_all = 0;        // frames in the sources, all shards
  std::vector<FrameSource> frames;   // this shard's frames
  std::vector<FrameSource> todo;     // those left to do: all of them, or (resume) the unfinished
  std::vector<std::string> damaged;  // resume: earlier logs' damaged lines (finished_frames)
  std::size_t redone = 0;            // no resume: frames an earlier run finished, done again
  // resume: finished frames done again, as an input's size or time changed since (changed) or
  // as their rows cannot tell the settings and inputs they were made from (unproven)
  std::size_t changed = 0, unproven = 0;
  std::unique_ptr<SummaryLog> log;  // OUT/<summary_name(shard, shards)>.jsonl, header written
};

// Finds the frames (discover_frames), checks the output folder against them
// (check_output_folder: OutputFolderError), takes this shard's, completes `header` (sources,
// shard, frames, frames_all, proxseg, runner; the caller gives command, outputs, parameters and
// database), makes the output folder and checks that files can be made in it
// (check_writable_folder), all before any frame is read. Then, under the folder's lock
// (OUT/.proxseg-batch.lock, held until this run's header is written), refuses settings other
// than those of the folder's logs (InputError naming the first difference: one folder, one set
// of settings; shards of one set share it), reads what earlier runs finished (finished_frames),
// opens the summary log (SummaryLog: locked) and, on resume, removes what a killed run left of
// the frames to do (remove_stale_temporaries).
BatchStart start_batch(const BatchPlan& plan, const std::string& out_dir, nlohmann::json header);

}  // namespace proxseg
