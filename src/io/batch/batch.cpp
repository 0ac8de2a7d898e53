// Batch work over a dataset: one frame's job and the JSON-lines summary (batch.hpp).
#include <proxseg/core/errors.hpp>
#include <proxseg/io/batch.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/memory.hpp>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <unordered_map>

#include "io/batch/batch_settings.hpp"
#include "io/batch/log_lines.hpp"
#include "util/shown_names.hpp"
#include "util/stopwatch.hpp"

namespace proxseg {
namespace fs = std::filesystem;
using detail::for_each_log_line;
using detail::skipped;
namespace {

void write_all(int fd, const std::string& bytes, const std::string& path) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw FileError(path + ": cannot write (" + std::strerror(errno) + ")");
    done += static_cast<std::size_t>(n);
  }
}

// The inputs' sizes and modification times (ns) as a frame's row records them: {"input_sizes",
// "input_mtimes_ns"}, or null when an input cannot be examined (its frame then fails).
nlohmann::json input_stamps(const std::vector<std::string>& files) {
  nlohmann::json sizes = nlohmann::json::array(), times = nlohmann::json::array();
  for (const std::string& file : files) {
    struct stat st;
    if (::stat(file.c_str(), &st) != 0) return nullptr;
    sizes.push_back(static_cast<std::uint64_t>(st.st_size));
    times.push_back(static_cast<std::int64_t>(st.st_mtim.tv_sec) * 1000000000 + st.st_mtim.tv_nsec);
  }
  return {{"input_sizes", sizes}, {"input_mtimes_ns", times}};
}

}  // namespace

std::string output_stem(const std::string& id) {
  const bool clashes = id == "summary" || id.rfind("summary.", 0) == 0;
  return clashes ? id + "-frame" : id;
}

// OUT_DIR/<stem>, its folder made.
std::string output_prefix(const std::string& out_dir, const std::string& id) {
  const fs::path prefix = fs::path(out_dir) / output_stem(id);
  std::error_code ec;
  fs::create_directories(prefix.parent_path(), ec);
  if (ec)
    throw FileError(prefix.parent_path().string() + ": cannot create the output folder (" +
                    ec.message() + ")");
  return prefix.string();
}

// {file relative to out_dir: bytes} of the files just written.
nlohmann::json file_sizes(const std::string& out_dir, const std::vector<std::string>& files) {
  nlohmann::json sizes = nlohmann::json::object();
  for (const auto& f : files)
    sizes[shown_name(fs::path(f).lexically_relative(out_dir).generic_string())] = fs::file_size(f);
  return sizes;
}

// A frame's row around its work: inputs, then the work's fields or its error, time and memory.
nlohmann::json frame_row(const FrameSource& frame,
                         const std::function<void(nlohmann::json& row)>& work) {
  const detail::Stopwatch watch;
  // Names as shown (util/shown_names.hpp): the log reads them back to their bytes.
  nlohmann::json inputs = nlohmann::json::array();
  for (const std::string& file : frame.files()) inputs.push_back(shown_name(file));
  nlohmann::json start = {{"frame", shown_name(frame.id)}, {"inputs", inputs}};
  // Taken before the frame is read: an input replaced during the work is seen as changed later.
  if (const nlohmann::json stamps = input_stamps(frame.files()); !stamps.is_null())
    start.update(stamps);
  nlohmann::json row = start;
  // A frame that fails leaves a row with its error, whatever failed: the batch goes on.
  const auto failed = [&](const std::string& error) {
    row = start;
    row["error"] = error;
  };
  try {
    work(row);
  } catch (const InputError& e) {
    failed(e.what());
  } catch (const std::bad_alloc&) {
    failed(frame.files().front() + ": out of memory (the frame needs more memory than the " +
           "process could allocate)");
  } catch (const std::exception& e) {
    failed(frame.files().front() + ": " + e.what());
  }
  row["ms"] = watch.ms();
  // Memory after each frame: a batch must not grow (docs/robustness.md).
  row["rss_mib"] = resident_mib();
  return row;
}

nlohmann::json segment_frame(const FrameSource& source, const SegmentJob& job) {
  return frame_row(source, [&](nlohmann::json& row) {
    const std::string prefix = output_prefix(job.out_dir, source.id);
    const Frame frame = read_frame(source);
    check_memory(frame, job.params, source.files().front());
    SegmentParams params = job.params;
    if (job.frame_threads > 0) params.threads = job.frame_threads;
    const SegmentResult result = segment(frame, params);
    const nlohmann::json report =
        write_segmentation(prefix, frame, job.params, result, job.outputs);
    row["outputs"] = file_sizes(job.out_dir, output_files(prefix, job.outputs, false));
    row["k"] = result.k();
    row["candidates"] = report["selection"]["candidates"];
  });
}

namespace {

// Whether path lies in folder (or is it), by their canonical forms.
bool inside(const fs::path& path, const fs::path& folder) {
  std::error_code ec;
  const fs::path p = fs::weakly_canonical(path, ec), f = fs::weakly_canonical(folder, ec);
  auto a = f.begin(), b = p.begin();
  for (; a != f.end() && b != p.end(); ++a, ++b)
    if (*a != *b) return false;
  return a == f.end();
}

}  // namespace

void check_output_folder(const std::vector<std::string>& sources,
                         const std::vector<FrameSource>& frames, const std::string& out_dir) {
  for (const std::string& s : sources) {
    std::error_code ec;
    if (fs::is_directory(s, ec) && inside(out_dir, s))
      throw OutputFolderError("output folder " + out_dir + " is inside the input folder " + s +
                              " (a later batch would take its outputs for frames)");
  }
  std::map<std::string, std::string> stems;  // output stem -> frame id
  for (const auto& f : frames) {
    for (const std::string& file : f.files())
      if (inside(file, out_dir))
        throw OutputFolderError("output folder " + out_dir + " holds the input " + file);
    const auto [it, fresh] = stems.emplace(output_stem(f.id), f.id);
    if (!fresh)
      throw OutputFolderError("frames " + it->second + " and " + f.id + " would both write " +
                              (fs::path(out_dir) / it->first).string() +
                              ".* (expected one frame per output name; rename one)");
  }
}

std::string summary_name(int shard_index, int shard_count) {
  if (shard_count <= 1) return "summary";
  return "summary.shard-" + std::to_string(shard_index) + "-of-" + std::to_string(shard_count);
}

SummaryLog::SummaryLog(const std::string& out_dir, const std::string& name,
                       const nlohmann::json& header, bool resume)
    : path_((fs::path(out_dir) / (name + ".jsonl")).string()),
      fingerprint_(settings_fingerprint(header)) {
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) throw FileError(out_dir + ": cannot create the output folder (" + ec.message() + ")");
  fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd_ < 0) throw FileError(path_ + ": cannot open the summary (" + std::strerror(errno) + ")");
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    ::close(fd_);
    throw InputError(path_ +
                     ": another batch is writing this summary (expected one process per output "
                     "folder and shard)");
  }
  try {
    nlohmann::json earlier;  // the last run's header
    // Damaged lines stay (finished_frames reports them); a half-written last one goes.
    const std::size_t whole = resume ? for_each_log_line(
                                           path_,
                                           [&](nlohmann::json& line, std::size_t) {
                                             if (line.contains("header"))
                                               earlier = std::move(line["header"]);
                                           },
                                           [](const std::string&, const std::string&) {})
                                     : 0;
    if (!earlier.is_null())
      if (const std::string diff = detail::settings_difference(earlier, header, "earlier", "now");
          !diff.empty())
        throw InputError(path_ + ": the earlier run differs in " + diff +
                         " (expected the same settings to resume: give another -o folder, or "
                         "the same settings)");
    if (::ftruncate(fd_, static_cast<off_t>(whole)) != 0)
      throw FileError(path_ + ": cannot write (" + std::strerror(errno) + ")");
    nlohmann::json stamped = header;  // the settings' fingerprint, as each row carries it
    stamped["fingerprint"] = fingerprint_;
    write_all(fd_, dump_shown(nlohmann::json{{"header", stamped}}) + "\n", path_);
  } catch (...) {
    ::close(fd_);
    throw;
  }
}

SummaryLog::~SummaryLog() {
  if (fd_ >= 0) ::close(fd_);
}

void SummaryLog::append(const nlohmann::json& row) {
  if (!row.is_object() || !row.contains("frame"))
    return write_all(fd_, dump_shown(row) + "\n", path_);
  // Each frame's row names the settings it was made with: `proxseg summary` refuses a log that
  // mixes two, --resume a row made with others.
  nlohmann::json stamped = row;
  stamped["fingerprint"] = fingerprint_;
  write_all(fd_, dump_shown(stamped) + "\n", path_);
}

void SummaryLog::close(bool interrupted, double peak_rss_mib) {
  write_all(fd_,
            nlohmann::json{{"end", {{"interrupted", interrupted}, {"peak_rss_mib", peak_rss_mib}}}}
                    .dump() +
                "\n",
            path_);
  ::close(fd_);
  fd_ = -1;
}

std::vector<std::string> summary_logs(const std::string& out_dir) {
  std::vector<std::string> logs;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(out_dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name.rfind("summary", 0) == 0 && e.path().extension() == ".jsonl")
      logs.push_back(e.path().string());
  }
  std::sort(logs.begin(), logs.end());
  return logs;
}

namespace {

// What resuming needs of a frame's last row: its files and sizes (none for an error), and the
// settings and inputs it was made from ("" and null when the row does not say).
struct LastRow {
  std::vector<std::pair<std::string, std::uintmax_t>> files;
  std::string fingerprint;
  nlohmann::json stamps;  // {"input_sizes", "input_mtimes_ns"}
};

// Each frame's last row in out_dir's logs (small, however long the logs); a frame named by a
// damaged line has an empty one (the line may have been its last row: done again).
std::map<std::string, LastRow> last_rows(const std::string& out_dir,
                                         std::vector<std::string>* damaged) {
  std::map<std::string, LastRow> last;
  for (const std::string& log : summary_logs(out_dir))
    for_each_log_line(
        log,
        [&](const nlohmann::json& line, std::size_t) {
          if (!line.contains("frame")) return;
          // Names not UTF-8 were written shown (\xFF): their bytes, to match the frames'.
          LastRow& row = last[name_from_shown(line["frame"].get<std::string>())];
          row = LastRow();
          if (line.contains("error") || !line.contains("outputs")) return;
          for (const auto& [file, bytes] : line["outputs"].items())
            row.files.emplace_back(name_from_shown(file), bytes.get<std::uintmax_t>());
          row.fingerprint = line.value("fingerprint", "");
          if (line.contains("input_sizes") && line.contains("input_mtimes_ns"))
            row.stamps = {{"input_sizes", line["input_sizes"]},
                          {"input_mtimes_ns", line["input_mtimes_ns"]}};
        },
        [&](const std::string& message, const std::string& frame) {
          if (!frame.empty()) last[name_from_shown(frame)] = LastRow();
          if (damaged) damaged->push_back(skipped(message, frame));
        });
  return last;
}

// Whether a row's files all exist with the sizes it recorded (none: an error, not finished).
bool outputs_whole(const std::string& out_dir, const LastRow& row) {
  bool whole = !row.files.empty();
  for (const auto& [file, bytes] : row.files) {
    std::error_code ec;
    whole = whole && fs::file_size(fs::path(out_dir) / file, ec) == bytes && !ec;
  }
  return whole;
}

}  // namespace

std::set<std::string> finished_frames(const std::string& out_dir,
                                      std::vector<std::string>* damaged) {
  std::set<std::string> done;
  for (const auto& [id, row] : last_rows(out_dir, damaged))
    if (outputs_whole(out_dir, row)) done.insert(id);
  return done;
}

FinishedFrames finished_frames(const std::string& out_dir, const std::vector<FrameSource>& frames,
                               const std::string& fingerprint, std::vector<std::string>* damaged) {
  const std::map<std::string, LastRow> last = last_rows(out_dir, damaged);
  FinishedFrames finished;
  for (const FrameSource& frame : frames) {
    const auto it = last.find(frame.id);
    if (it == last.end() || !outputs_whole(out_dir, it->second)) continue;
    const LastRow& row = it->second;
    // A row that cannot tell its settings or inputs proves nothing: done again (docs/batch.md).
    if (row.fingerprint != fingerprint || row.stamps.is_null())
      ++finished.unproven;
    else if (row.stamps != input_stamps(frame.files()))
      ++finished.changed;
    else
      finished.done.insert(frame.id);
  }
  return finished;
}

std::size_t remove_stale_temporaries(const std::string& out_dir,
                                     const std::vector<FrameSource>& frames) {
  // The temporaries of OUT/<id>.ext are OUT/<dir of id>/.<name of id>.ext.tmp.*
  std::set<std::pair<std::string, std::string>> mine;  // (folder, ".<name>.")
  std::set<std::string> folders;
  for (const FrameSource& f : frames) {
    const fs::path prefix = fs::path(out_dir) / output_stem(f.id);
    mine.emplace(prefix.parent_path().string(), "." + prefix.filename().string() + ".");
    folders.insert(prefix.parent_path().string());
  }
  std::size_t removed = 0;
  for (const std::string& folder : folders) {
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(folder, ec)) {
      const std::string name = e.path().filename().string();
      const auto tmp = name.find(".tmp.");
      const auto dot = name.find('.', 1);
      if (name[0] != '.' || tmp == std::string::npos || dot == std::string::npos) continue;
      // ".<name>.<ext...>.tmp.PID.N": the frame's name is up to an extension dot; try each.
      for (auto d = dot; d != std::string::npos && d < tmp; d = name.find('.', d + 1))
        if (mine.count({folder, name.substr(0, d + 1)})) {
          std::error_code ignore;
          removed += fs::remove(e.path(), ignore);
          break;
        }
    }
  }
  return removed;
}

namespace {

// What summarize keeps of a frame however long the logs: its last row's bytes written and, when
// that row is an error, the row.
struct FrameState {
  std::uintmax_t bytes = 0;
  nlohmann::json error_row;  // null unless the frame's last row failed
};

std::uintmax_t bytes_of(const nlohmann::json& row) {
  std::uintmax_t bytes = 0;
  if (row.contains("outputs"))
    for (const auto& [file, size] : row["outputs"].items()) bytes += size.get<std::uintmax_t>();
  return bytes;
}

// What summarize gathers from the logs, one after another.
struct Merged {
  nlohmann::json first;  // the first header: the settings every log must share
  std::string first_where, fingerprint, fingerprint_where;  // LOG:LINE they were first seen at
  std::unordered_map<std::string, FrameState> states;
  std::size_t total = 0, batch_total = 0;
  std::set<std::string> shard_names;
  int shard_count = 1;
  bool interrupted = false;
  double peak = 0;
  nlohmann::json shards = nlohmann::json::array(), log_names = nlohmann::json::array(),
                 damaged_lines = nlohmann::json::array();
};

// The batch's settings as a log's header or row gives them, where they are first seen (LOG:LINE);
// every other line of every log must agree: one set of settings per batch folder.
void check_settings(Merged& m, const std::string& where, const nlohmann::json* header,
                    const std::string& fingerprint) {
  const std::string expected =
      " (expected one set of settings per batch folder: the frames of "
      "two settings are not one batch)";
  if (header && m.first.is_null()) m.first = *header;
  if (header && m.first_where.empty()) m.first_where = where;
  if (header)
    if (const std::string d =
            detail::settings_difference(m.first, *header, "at " + m.first_where, "here");
        !d.empty())
      throw InputError(where + ": a run with other settings than " + m.first_where + "'s: " + d +
                       expected);
  if (m.fingerprint.empty()) {
    m.fingerprint = fingerprint;
    m.fingerprint_where = where;
  } else if (fingerprint != m.fingerprint) {
    throw InputError(where + ": " + (header ? "a run" : "a frame") +
                     " made with settings of fingerprint " + fingerprint + ", not " +
                     m.fingerprint + " as at " + m.fingerprint_where + expected);
  }
}

// Adds one log (a shard's summary*.jsonl) to m.
void merge_log(const std::string& log, Merged& m) {
  nlohmann::json header;
  bool ended = false;
  for_each_log_line(
      log,
      [&](nlohmann::json& line, std::size_t number) {
        if (line.contains("header")) {
          header = line["header"];
          ended = false;
          check_settings(m, log + ":" + std::to_string(number), &header,
                         settings_fingerprint(header));
        } else if (line.contains("end")) {
          ended = true;
          const nlohmann::json& end = line["end"];
          m.interrupted =
              m.interrupted || (end.contains("interrupted") && end["interrupted"] != false);
          if (end.contains("peak_rss_mib") && end["peak_rss_mib"].is_number())
            m.peak = std::max(m.peak, end["peak_rss_mib"].get<double>());
        } else if (line.contains("frame")) {
          if (line.contains("fingerprint"))  // rows of an older proxseg have none
            check_settings(m, log + ":" + std::to_string(number), nullptr,
                           line["fingerprint"].get<std::string>());
          FrameState& state = m.states[line["frame"].get<std::string>()];
          state.bytes = bytes_of(line);
          state.error_row = line.contains("error") ? std::move(line) : nlohmann::json();
        }
      },
      [&](const std::string& message, const std::string& frame) {
        // A frame whose last row was damaged has no row: missing (done again by --resume).
        if (!frame.empty()) m.states.erase(frame);
        m.damaged_lines.push_back(skipped(message, frame));
      });
  if (header.is_null()) throw InputError(log + ": no header line (expected a batch summary)");
  m.interrupted = m.interrupted || !ended;  // killed, or still running
  m.total += header.value("frames", std::size_t{0});
  m.batch_total = std::max(m.batch_total, header.value("frames_all", std::size_t{0}));
  const nlohmann::json shard = header.value("shard", nlohmann::json());
  m.shards.push_back(shard);
  m.log_names.push_back(fs::path(log).filename().string());
  if (shard.is_string()) {
    m.shard_names.insert(shard.get<std::string>());
    const std::string s = shard;
    m.shard_count = std::max(m.shard_count, std::atoi(s.c_str() + s.find('/') + 1));
  }
}

}  // namespace

nlohmann::json summarize(const std::vector<std::string>& logs, bool whole_batch) {
  Merged m;
  for (const std::string& log : logs) merge_log(log, m);
  if (m.first.is_null()) throw InputError("no batch summaries (summary*.jsonl) to merge");
  nlohmann::json missing = nlohmann::json::array();
  if (whole_batch) {
    m.total = std::max(m.total, m.batch_total);
    if (!m.shard_names.empty())
      for (int i = 1; i <= m.shard_count; ++i)
        if (!m.shard_names.count(std::to_string(i) + "/" + std::to_string(m.shard_count)))
          missing.push_back(std::to_string(i) + "/" + std::to_string(m.shard_count));
  }
  std::size_t done = 0;
  std::uintmax_t bytes = 0;
  std::vector<std::string> failed_ids;
  for (const auto& [id, state] : m.states) {
    if (state.error_row.is_null())
      ++done;
    else
      failed_ids.push_back(id);
    bytes += state.bytes;
  }
  std::sort(failed_ids.begin(), failed_ids.end(), natural_less);
  nlohmann::json failed = nlohmann::json::array();
  for (const std::string& id : failed_ids) failed.push_back(std::move(m.states[id].error_row));
  const std::size_t counted = done + failed_ids.size();
  nlohmann::json& first = m.first;  // not const: operator[] gives null for a missing key
  nlohmann::json summary = {{"command", first["command"]},
                            {"sources", first["sources"]},
                            {"shards", m.shards},
                            {"logs", m.log_names},
                            {"frames_total", m.total},
                            {"frames_done", done},
                            {"frames_failed", failed_ids.size()},
                            {"frames_missing", m.total > counted ? m.total - counted : 0},
                            {"interrupted", m.interrupted},
                            {"peak_rss_mib", m.peak},
                            {"bytes_written", bytes},
                            {"failed", failed},
                            {"damaged_lines", m.damaged_lines},
                            {"proxseg", first["proxseg"]},
                            {"outputs", first["outputs"]},
                            {"database", first.value("database", nlohmann::json())},
                            {"parameters", first["parameters"]}};
  if (whole_batch && !m.shard_names.empty()) summary["shards_missing"] = missing;
  return summary;
}

nlohmann::json frame_rows(const std::string& out_dir) {
  std::map<std::string, nlohmann::json, bool (*)(const std::string&, const std::string&)> rows(
      natural_less);
  for (const std::string& log : summary_logs(out_dir))
    for_each_log_line(
        log,
        [&](nlohmann::json& line, std::size_t) {
          if (!line.contains("frame")) return;
          const std::string id = line["frame"];  // before the move below (C++17 order)
          rows[id] = std::move(line);
        },
        [&](const std::string&, const std::string& frame) {
          if (!frame.empty()) rows.erase(frame);
        });
  nlohmann::json out = nlohmann::json::array();
  for (auto& [id, row] : rows) out.push_back(std::move(row));
  return out;
}

}  // namespace proxseg
