// Memory of the proxseg CLI as a user runs it (docs/robustness.md, "Memory"): peak resident set
// of one 640x480 frame segmented, of one scene recognised against a 64-view database (8 LINEMOD
// objects x 8 rendered views), and the resident set after each of 100 frames of a batch, which
// after one cycle of its scenes must not grow; segment_memory_mib's estimate (--max-memory) against
// the peaks of frames of 1x, 2x and 3x the size; and an address-space sweep (ulimit -v,
// --sweep-from to --sweep-to in
// --sweep-step MiB) of one scene, one recognition and a 5-frame batch, where every run must end
// with exit 0 or 1 and a message, never a signal. Each measurement is its own process (peak RSS
// from wait4). Writes a markdown section for docs/results.md and exits 1 if the batch grows by
// more than --max-growth, an estimate falls below its peak or a run of the sweep ends otherwise.
#include <proxseg/core/pipeline.hpp>
#include <proxseg/io/cloud_io.hpp>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "bench_main.hpp"
#include "bench_util.hpp"

namespace fs = std::filesystem;

namespace {

struct Run {
  double peak_mib = 0, seconds = 0;
  int status = 0;  // as wait4 gives it
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Runs the CLI with args (stdout and stderr to log), under an address-space limit of limit_mib
// when > 0; its peak RSS from the kernel's accounting.
Run launch(const std::string& cli, const std::vector<std::string>& args, const fs::path& log,
           double limit_mib = 0) {
  std::vector<char*> argv = {const_cast<char*>(cli.c_str())};
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const auto start = std::chrono::steady_clock::now();
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    std::freopen(log.c_str(), "w", stdout);
    std::freopen(log.c_str(), "a", stderr);
    if (limit_mib > 0) {
      const rlim_t bytes = static_cast<rlim_t>(limit_mib * (1 << 20));
      const rlimit limit{bytes, bytes};
      ::setrlimit(RLIMIT_AS, &limit);
    }
    ::execv(cli.c_str(), argv.data());
    std::_Exit(127);
  }
  int status = 0;
  rusage usage{};
  ::wait4(pid, &status, 0, &usage);
  return {usage.ru_maxrss / 1024.0,
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), status};
}

// launch() of a run that must succeed (std::runtime_error with its output otherwise).
Run run(const std::string& cli, const std::vector<std::string>& args, const fs::path& log) {
  const Run r = launch(cli, args, log);
  if (!WIFEXITED(r.status) || WEXITSTATUS(r.status) != 0)
    throw std::runtime_error("proxseg " + args.front() + " failed:\n" + slurp(log));
  return r;
}

// How a run of the sweep ended: "exit N" or "signal N".
std::string ending(int status) {
  return WIFEXITED(status) ? "exit " + std::to_string(WEXITSTATUS(status))
                           : "signal " + std::to_string(WTERMSIG(status));
}

// The last line of a run's output that says what went wrong ("" when none).
std::string error_line(const std::string& output) {
  std::string last;
  std::istringstream in(output);
  for (std::string line; std::getline(in, line);)
    if (line.find("error") != std::string::npos) last = line;
  return last;
}

// frame with every pixel repeated k x k times, the copies 0.5 mm apart: a k-times finer sensor.
proxseg::Frame upsampled(const proxseg::Frame& f, int k) {
  proxseg::Frame g;
  g.width = f.width * k;
  g.height = f.height * k;
  for (int r = 0; r < g.height; ++r)
    for (int c = 0; c < g.width; ++c) {
      const std::size_t i = static_cast<std::size_t>(r / k) * f.width + c / k;
      g.xyz.push_back(f.xyz[i] + Eigen::Vector3f(0.0005f * (c % k), 0.0005f * (r % k), 0));
      g.rgb.push_back(f.rgb[i]);
    }
  return g;
}

std::string fixed(double v, int digits = 0) {
  return proxseg::bench::fixed(v, digits);
}

struct Options {
  std::string cli, data, out, json_out;
  int frames = 100;
  double max_growth = 0.10;
  double sweep_from = 400, sweep_to = 900, sweep_step = 20;
};

void add_options(CLI::App& app, Options& o) {
  app.add_option("--cli", o.cli, "The proxseg executable")->required();
  app.add_option("--data", o.data, "../shared/data")->required();
  app.add_option("--out", o.out, "Markdown section to write")->required();
  app.add_option("--json", o.json_out, "Also write the measurements as JSON");
  app.add_option("--frames", o.frames, "Frames in the batch");
  app.add_option("--max-growth", o.max_growth,
                 "Fail if the RSS after the last frame exceeds that after the first cycle of the "
                 "distinct scenes by this share");
  app.add_option("--sweep-from", o.sweep_from, "Smallest address-space limit of the sweep, MiB");
  app.add_option("--sweep-to", o.sweep_to, "Largest address-space limit of the sweep, MiB");
  app.add_option("--sweep-step", o.sweep_step, "Step of the sweep, MiB")
      ->check(CLI::PositiveNumber);
}

// Where the runs work and what they read.
struct Paths {
  fs::path work, log, db;
  std::string scene;            // mOSD learn0
  std::vector<fs::path> learn;  // every mOSD learn scene, sorted
};

// The resident set after each frame of the batch, and how it grew after one cycle of the scenes.
struct Batch {
  Run run;
  std::vector<double> rss;
  int cycle = 0;
  double at_cycle = 0, last = 0, growth = 0, max_rss = 0;
};

struct Estimate {
  std::string frame;
  bool paper;
  double estimate, peak;
};

struct Job {
  std::string name;
  std::vector<std::string> args;
};

// The address-space sweep: per job, per limit, how the run ended ("0", "1: message", "127", or
// the signal).
struct Sweep {
  std::vector<Job> jobs;
  std::vector<double> limits;
  std::vector<std::vector<std::string>> endings;
  bool signalled = false;
};

Paths paths(const Options& o) {
  Paths p;
  p.work = fs::path(o.out).parent_path() / "mem-work";
  fs::remove_all(p.work);
  fs::create_directories(p.work);
  p.log = p.work / "log.txt";
  p.scene = o.data + "/mosd/learn/learn0.pcd";
  p.db = p.work / "db";
  for (const auto& e : fs::directory_iterator(o.data + "/mosd/learn"))
    if (e.path().extension() == ".pcd") p.learn.push_back(e.path());
  std::sort(p.learn.begin(), p.learn.end());
  return p;
}

// The 64-view database, then learn0 recognised against it.
Run recognize_64(const Options& o, const Paths& p) {
  std::cerr << "mem_bench: a 64-view database\n";
  const std::vector<std::string> ids = {"01", "05", "06", "08", "09", "10", "11", "12"};
  for (const auto& id : ids)
    run(o.cli,
        {"db", "render", p.db.string(), "--name", "obj_" + id,
         o.data + "/lmo/models/obj_0000" + id + ".ply", "--views", "8", "--units", "mm"},
        p.log);
  return run(o.cli, {"recognize", p.scene, "--db", p.db.string(), "-o", (p.work / "rec").string()},
             p.log);
}

Batch batch(const Options& o, const Paths& p) {
  std::cerr << "mem_bench: a batch of " << o.frames << " frames\n";
  const fs::path in = p.work / "batch-in";
  fs::create_directories(in);
  if (p.learn.empty()) throw std::runtime_error(o.data + "/mosd/learn: no scenes");
  for (int i = 0; i < o.frames; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "frame%03d.pcd", i);
    fs::create_symlink(fs::absolute(p.learn[i % p.learn.size()]), in / name);
  }
  Batch b;
  b.run =
      run(o.cli, {"segment", "--batch", in.string(), "-o", (p.work / "batch-out").string()}, p.log);
  // The frames' rows of the batch's summary.jsonl (one run: one row a frame, in order).
  std::ifstream sin(p.work / "batch-out" / "summary.jsonl");
  for (std::string line; std::getline(sin, line);)
    if (const auto row = nlohmann::json::parse(line); row.contains("frame"))
      b.rss.push_back(row["rss_mib"].get<double>());
  if (static_cast<int>(b.rss.size()) != o.frames)
    throw std::runtime_error("batch summary has " + std::to_string(b.rss.size()) + " frames");
  // The frames cycle through the distinct scenes; the heap keeps what the largest needed
  // (keep_freed_memory), so the resident set rises until every scene has been seen once.
  // Growth after that cycle would be a leak.
  b.cycle = std::min(o.frames, static_cast<int>(p.learn.size()));
  b.at_cycle = b.rss[b.cycle - 1];
  b.last = b.rss.back();
  b.growth = (b.last - b.at_cycle) / b.at_cycle;
  b.max_rss = *std::max_element(b.rss.begin(), b.rss.end());
  return b;
}

// The estimate of --max-memory against the peaks of learn0 at 1x, 2x, 3x the size.
std::vector<Estimate> estimates(const Options& o, const Paths& p) {
  std::cerr << "mem_bench: the estimate of --max-memory against frames of 1x, 2x, 3x the size\n";
  std::vector<Estimate> out;
  const proxseg::Frame learn0 = proxseg::read_pcd(p.scene);
  for (int k = 1; k <= 3; ++k) {
    const fs::path big = p.work / ("learn0-x" + std::to_string(k) + ".pcd");
    const proxseg::Frame f = upsampled(learn0, k);
    proxseg::write_pcd(big.string(), f, {});
    for (const bool paper : {false, true}) {
      proxseg::SegmentParams params = proxseg::preset("default");
      params.paper_labels = paper;
      std::vector<std::string> args = {"segment", big.string(), "-o", (p.work / "big").string()};
      if (paper) args.push_back("--paper-labels");
      const Run r = run(o.cli, args, p.log);
      out.push_back({std::to_string(f.width) + "x" + std::to_string(f.height), paper,
                     proxseg::segment_memory_mib(f, params), r.peak_mib});
    }
  }
  return out;
}

// How one run under an address-space limit of `mib` ended.
std::string sweep_one(const Options& o, const Paths& p, const Job& job, double mib,
                      bool& signalled) {
  fs::remove_all(p.work / "lim-batch");
  const Run r = launch(o.cli, job.args, p.log, mib);
  const std::string output = slurp(p.log);
  const bool ok = WIFEXITED(r.status) && WEXITSTATUS(r.status) == 0;
  const bool failed =
      WIFEXITED(r.status) && WEXITSTATUS(r.status) == 1 && !error_line(output).empty();
  // Below what its shared libraries need, the dynamic loader stops before main: exit 127.
  const bool unloaded = WIFEXITED(r.status) && WEXITSTATUS(r.status) == 127 &&
                        output.find("error while loading shared libraries") != std::string::npos;
  if (unloaded) return "127";
  if (!ok && !failed) {
    signalled = true;
    std::cerr << "mem_bench: " << job.name << " at " << mib << " MiB: " << ending(r.status) << "\n"
              << output;
  }
  std::string e = ok ? "0" : failed ? "1" : ending(r.status);
  if (failed && !ok) e += ": " + error_line(output);
  return e;
}

Sweep sweep(const Options& o, const Paths& p) {
  std::cerr << "mem_bench: address-space limits " << o.sweep_from << "-" << o.sweep_to << " MiB\n";
  const fs::path five = p.work / "batch-5";
  fs::create_directories(five);
  for (int i = 0; i < 5; ++i)
    fs::create_symlink(fs::absolute(p.learn[i % p.learn.size()]),
                       five / ("frame" + std::to_string(i) + ".pcd"));
  Sweep s;
  s.jobs = {
      {"`segment` learn0", {"segment", p.scene, "-o", (p.work / "lim").string()}},
      {"`segment --paper-labels --threads 4` learn0",
       {"segment", p.scene, "--paper-labels", "--threads", "4", "-o", (p.work / "lim").string()}},
      {"`segment --batch` 5 frames, 2 at once",
       {"segment", "--batch", five.string(), "--threads", "2", "-o",
        (p.work / "lim-batch").string()}},
      {"`recognize` learn0, 64 views",
       {"recognize", p.scene, "--db", p.db.string(), "-o", (p.work / "lim-rec").string()}}};
  for (double mib = o.sweep_from; mib <= o.sweep_to + 1e-9; mib += o.sweep_step)
    s.limits.push_back(mib);
  s.endings.resize(s.jobs.size());
  for (std::size_t j = 0; j < s.jobs.size(); ++j)
    for (const double mib : s.limits)
      s.endings[j].push_back(sweep_one(o, p, s.jobs[j], mib, s.signalled));
  return s;
}

void md_peaks(std::ostream& md, const Options& o, const Paths& p, const Run& segment,
              const Run& recognize, const Batch& b) {
  const int frames = o.frames;
  md << "## Memory\n\nPeak resident set of the `proxseg` process (Linux `wait4`), and the "
        "resident "
        "set after each frame of a batch (`segment --batch`, the rows of its `summary.jsonl`). "
     << "`make bench` fails if the batch grows by more than " << fixed(100 * o.max_growth)
     << " % from frame " << b.cycle << " (each of the " << p.learn.size()
     << " scenes seen once: the heap keeps what the largest needed) to frame " << frames << ".\n\n"
     << "| run | peak RSS (MiB) |\n|---|---:|\n"
     << "| `segment` one 640x480 frame (mOSD learn0) | " << fixed(segment.peak_mib) << " |\n"
     << "| `recognize` learn0 against 64 views (8 LINEMOD objects x 8) | "
     << fixed(recognize.peak_mib) << " |\n"
     << "| `segment --batch` " << frames << " frames (mOSD learn, cycled) | "
     << fixed(b.run.peak_mib) << " |\n\n"
     << "Resident set during the batch (MiB): after frame 1 " << fixed(b.rss.front())
     << ", frame 10 " << fixed(b.rss[std::min(9, frames - 1)]) << ", frame " << b.cycle << " "
     << fixed(b.at_cycle) << ", frame " << frames / 2 << " " << fixed(b.rss[frames / 2 - 1])
     << ", frame " << frames << " " << fixed(b.last) << ", highest " << fixed(b.max_rss)
     << "; growth from frame " << b.cycle << " to " << frames << ": " << fixed(100 * b.growth, 1)
     << " %.\n";
}

void md_estimates(std::ostream& md, const std::vector<Estimate>& estimates) {
  md << "\n### The estimate behind --max-memory\n\n`segment_memory_mib()` (an estimate from the "
        "frame's size, checked before a frame starts) against the peak resident set of "
        "`proxseg segment` on learn0 and learn0 upsampled 2x and 3x:\n\n"
     << "| frame | paper labels | estimate (MiB) | peak RSS (MiB) | estimate / peak |\n"
     << "|---|---|---:|---:|---:|\n";
  for (const Estimate& e : estimates)
    md << "| " << e.frame << " | " << (e.paper ? "yes" : "no") << " | " << fixed(e.estimate)
       << " | " << fixed(e.peak) << " | " << fixed(e.estimate / e.peak, 2) << " |\n";
}

void md_sweep(std::ostream& md, const Options& o, const Sweep& s) {
  md << "\n### Address-space limits\n\nEach run under `ulimit -v` (RLIMIT_AS) from "
     << fixed(o.sweep_from) << " to " << fixed(o.sweep_to) << " MiB in steps of "
     << fixed(o.sweep_step)
     << " MiB: 0 = done, 1 = stopped with a message (the first is quoted), 127 = the dynamic "
        "loader could not map the program's libraries (before proxseg runs), anything else (a "
        "signal) is a failure of the benchmark.\n\n"
     << "| run | limits | exit 0 | exit 1 | exit 127 | other | first message |\n"
     << "|---|---:|---:|---:|---:|---:|---|\n";
  for (std::size_t j = 0; j < s.jobs.size(); ++j) {
    std::size_t done = 0, stopped = 0, unloaded = 0;
    std::string first;
    for (const std::string& e : s.endings[j]) {
      done += e == "0";
      unloaded += e == "127";
      stopped += e == "1" || e.rfind("1: ", 0) == 0;
      if (first.empty() && e.rfind("1: ", 0) == 0) first = e.substr(3);
    }
    md << "| " << s.jobs[j].name << " | " << s.limits.size() << " | " << done << " | " << stopped
       << " | " << unloaded << " | " << s.limits.size() - done - stopped - unloaded << " | "
       << first << " |\n";
  }
}

// 1 with the reason when the batch grew, an estimate fell below its peak or a run of the sweep
// ended by a signal.
int verdict(const Options& o, const Batch& b, const std::vector<Estimate>& estimates,
            const Sweep& s) {
  bool under = false;
  for (const Estimate& e : estimates) under = under || e.estimate < e.peak;
  if (b.growth > o.max_growth) {
    std::cerr << "mem_bench: the batch grew by " << fixed(100 * b.growth, 1) << " %\n";
    return 1;
  }
  if (under) {
    std::cerr << "mem_bench: an estimate of --max-memory is below the peak it estimates\n";
    return 1;
  }
  if (s.signalled) {
    std::cerr << "mem_bench: a run under an address-space limit ended by a signal\n";
    return 1;
  }
  return 0;
}

int run_all(const Options& o) {
  const Paths p = paths(o);
  std::cerr << "mem_bench: one 640x480 frame\n";
  const Run segment = run(o.cli, {"segment", p.scene, "-o", (p.work / "seg").string()}, p.log);
  const Run recognize = recognize_64(o, p);
  const Batch b = batch(o, p);
  const std::vector<Estimate> e = estimates(o, p);
  const Sweep s = sweep(o, p);
  std::ostringstream md;
  md_peaks(md, o, p, segment, recognize, b);
  md_estimates(md, e);
  md_sweep(md, o, s);
  std::ofstream(o.out) << md.str();
  if (!o.json_out.empty())
    std::ofstream(o.json_out) << nlohmann::json{
        {"segment_peak_mib", segment.peak_mib},
        {"recognize_64_views_peak_mib", recognize.peak_mib},
        {"batch_peak_mib", b.run.peak_mib},
        {"batch_rss_mib", b.rss},
        {"batch_growth", b.growth}}.dump(2);
  std::cout << md.str();
  return verdict(o, b, e, s);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Peak and per-frame memory of proxseg (docs/robustness.md)"};
  Options o;
  add_options(app, o);
  return proxseg::bench::main_of("mem_bench", app, argc, argv, [&] { return run_all(o); });
}
