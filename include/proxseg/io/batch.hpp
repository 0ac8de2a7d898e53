// Batch work over a dataset (docs/batch.md): one frame's job (segment; recognise is
// proxseg/recognition/recognize_frame.hpp), and the JSON-lines summary that makes a batch
// resumable, shardable and spreadable over many processes. The CLI's `--batch` and the Dask runner
// (python/proxseg/dask.py) are both built from these, so that they write the same files.
#pragma once
#include <proxseg/core/errors.hpp>
#include <proxseg/core/pipeline.hpp>
#include <proxseg/io/frame_source.hpp>
#include <proxseg/io/output.hpp>

#include <functional>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

namespace proxseg {

// What a segmentation batch does with each frame.
struct SegmentJob {
  std::string out_dir;   // outputs go to OUT_DIR/<frame id>.* (folders made as needed)
  OutputSet outputs;     // which files (write_segmentation)
  SegmentParams params;  // the segmentation's parameters (echoed in every report)
  // Threads for each frame's segmentation, when frames run side by side; 0 = params.threads.
  int frame_threads = 0;
};

// One frame of a batch, start to end: reads it, segments it, writes its outputs (all or none).
// Returns its summary row: {"frame": id, "inputs": [files], "input_sizes": [bytes],
// "input_mtimes_ns": [times] (the inputs' as the frame starts: --resume compares them),
// "outputs": {file relative to out_dir: bytes}, "k", "candidates", "ms", "rss_mib"}. A failure (a
// frame that cannot be read or written, memory exhausted, ...) does not propagate: the row then has
// "error" (the message, which names the file) instead of outputs, and nothing of the frame is
// written.
nlohmann::json segment_frame(const FrameSource& frame, const SegmentJob& job);
// The pieces a frame's job is made of (segment_frame, recognize_frame in
// proxseg/recognition/recognize_frame.hpp): OUT_DIR/<output_stem(id)> with its folder made
// (FileError when it cannot be); {file relative to out_dir: bytes} of the files just written; the
// row around the work: "frame", "inputs" (with "input_sizes" and "input_mtimes_ns", taken before
// the work), then what work adds or "error" (an exception's message,
// naming the frame's first input; "out of memory" for std::bad_alloc), "ms" and "rss_mib".
std::string output_prefix(const std::string& out_dir, const std::string& id);
// The name of a frame's outputs in out_dir: its id, except where the outputs would take the
// batch's own names (summary.json, summary.jsonl, summary.shard-I-of-N.*): a frame named
// "summary" or "summary.<anything>" at the top writes "<id>-frame.*" instead.
std::string output_stem(const std::string& id);
nlohmann::json file_sizes(const std::string& out_dir, const std::vector<std::string>& files);
nlohmann::json frame_row(const FrameSource& frame,
                         const std::function<void(nlohmann::json& row)>& work);

// An output folder that a batch's inputs rule out (check_output_folder): the CLI reports it as
// a usage error (exit code 2), like its other option checks.
struct OutputFolderError : InputError {
  using InputError::InputError;
};

// The outputs must stay out of the inputs and apart: OutputFolderError when out_dir is inside a
// source folder (a later batch would take its outputs for frames) or holds an input file, or when
// two frames would write the same outputs (a frame "summary" beside one "summary-frame").
void check_output_folder(const std::vector<std::string>& sources,
                         const std::vector<FrameSource>& frames, const std::string& out_dir);

// The name of a batch's summary in its output folder: "summary" for the whole batch,
// "summary.shard-I-of-N" for a shard (so that shards never write one file).
std::string summary_name(int shard_index = 1, int shard_count = 1);

// The streamed summary of a run, OUT/<name>.jsonl: a line {"header": {...}} when a run starts,
// then one line per frame (segment_frame's row) as soon as it is done, then {"end": {...}} when
// the run ends. Each line is written by one write() to a file opened for appending, so that a
// killed run loses no finished frame. The header and every frame's row carry the settings'
// fingerprint (settings_fingerprint). The file is locked (flock) while open: a second process
// given the same output folder and shard gets an InputError instead of interleaving lines.
class SummaryLog {
 public:
  // Opens OUT/<name>.jsonl and writes header. resume = false: the file starts anew. resume =
  // true: its whole lines are kept (a half-written last line, from a killed run, is cut off),
  // after checking that its last header has the same "command", "outputs", "parameters" and
  // "database" as header (InputError naming the first difference otherwise: the outputs of two
  // settings must not be mixed in one folder).
  SummaryLog(const std::string& out_dir, const std::string& name, const nlohmann::json& header,
             bool resume);
  ~SummaryLog();
  SummaryLog(const SummaryLog&) = delete;
  SummaryLog& operator=(const SummaryLog&) = delete;
  // Writes a line; a frame's row (one with "frame") gets the settings' "fingerprint".
  void append(const nlohmann::json& row);
  // Writes {"end": {"interrupted", "peak_rss_mib"}} and closes the file.
  void close(bool interrupted, double peak_rss_mib);
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::string fingerprint_;  // settings_fingerprint(header), written in each frame's row
  int fd_ = -1;
};

// The frames of earlier runs into out_dir whose outputs are whole: those whose last row, in any
// OUT/summary*.jsonl, has no error and whose output files all exist with the sizes it recorded.
// A damaged line (not JSON, or not a header, row or end as batches write them) is skipped: the
// frame it may have named is not finished (done again), and a message per line ("LOG:LINE:
// damaged line (why); skipped, frame ID is done again") goes to *damaged when given.
std::set<std::string> finished_frames(const std::string& out_dir,
                                      std::vector<std::string>* damaged = nullptr);

// What --resume may skip of the given frames: those finished as above whose row was made with
// the settings of this fingerprint (settings_fingerprint) from inputs of the sizes and times
// (ns) the files have now. A frame finished otherwise is done again and counted: `changed` when
// an input's size or time differs, `unproven` when its row has no fingerprint or input stamps
// (an older proxseg's log) or another fingerprint.
struct FinishedFrames {
  std::set<std::string> done;
  std::size_t changed = 0, unproven = 0;
};
FinishedFrames finished_frames(const std::string& out_dir, const std::vector<FrameSource>& frames,
                               const std::string& fingerprint,
                               std::vector<std::string>* damaged = nullptr);

// The fingerprint of a batch's settings, the "command", "outputs", "parameters" and "database" of
// its header: 16 hex digits of FNV-1a (64 bits) over their canonical JSON text (keys sorted, no
// spaces, numbers as their shortest round trip), the same on every machine and run. SummaryLog
// writes it in its header and in every frame's row.
std::string settings_fingerprint(const nlohmann::json& header);

// Removes what a killed run left of the given frames' outputs in out_dir: the hidden temporary
// files of write_files_atomic (".NAME.tmp.PID.N" beside each output). Only these frames': another
// process may be writing other frames there. Returns how many were removed.
std::size_t remove_stale_temporaries(const std::string& out_dir,
                                     const std::vector<FrameSource>& frames);

// The summary of the runs logged in the given .jsonl files: {"command", "sources", "shards" (each
// log's "I/N" or null), "logs" (their file names), "frames_total", "frames_done",
// "frames_failed", "frames_missing" (total - done - failed), "interrupted" (a log whose last run
// did not end), "peak_rss_mib", "bytes_written" (by the frames' last rows), "failed" (the last
// row of each failed frame, in natural order of ids), "damaged_lines" (finished_frames' messages
// for the logs' damaged lines, which are skipped; a frame whose last row is damaged counts as
// missing), "proxseg", "parameters", "outputs", "database"}. Every frame's row stays in the logs
// (frame_rows reads them): the summary's size and the memory it takes do not grow with the frames
// done. whole_batch = false (one shard's own summary): frames_total counts the logs' frames. true
// (`proxseg summary`, merging shards): the whole batch's frames, and "shards_missing" lists the
// shards without a log. InputError when the logs' headers disagree on the command, outputs,
// parameters or database, or a log has no header.
nlohmann::json summarize(const std::vector<std::string>& logs, bool whole_batch);
// Every OUT/summary*.jsonl, sorted.
std::vector<std::string> summary_logs(const std::string& out_dir);
// The last row of each frame in OUT/summary*.jsonl, in natural order of ids: all of them in
// memory (a few KiB a frame: docs/batch.md has the figures), for a batch's per-frame
// figures; a reader of the .jsonl lines one at a time needs none of it.
nlohmann::json frame_rows(const std::string& out_dir);

}  // namespace proxseg
