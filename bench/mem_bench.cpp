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
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Peak and per-frame memory of proxseg (docs/robustness.md)"};
  std::string cli, data, out, json_out;
  int frames = 100;
  double max_growth = 0.10;
  app.add_option("--cli", cli, "The proxseg executable")->required();
  app.add_option("--data", data, "../shared/data")->required();
  app.add_option("--out", out, "Markdown section to write")->required();
  app.add_option("--json", json_out, "Also write the measurements as JSON");
  app.add_option("--frames", frames, "Frames in the batch");
  app.add_option("--max-growth", max_growth,
                 "Fail if the RSS after the last frame exceeds that after the first cycle of the "
                 "distinct scenes by this share");
  double sweep_from = 400, sweep_to = 900, sweep_step = 20;
  app.add_option("--sweep-from", sweep_from, "Smallest address-space limit of the sweep, MiB");
  app.add_option("--sweep-to", sweep_to, "Largest address-space limit of the sweep, MiB");
  app.add_option("--sweep-step", sweep_step, "Step of the sweep, MiB")->check(CLI::PositiveNumber);
  CLI11_PARSE(app, argc, argv);
  try {
    const fs::path work = fs::path(out).parent_path() / "mem-work";
    fs::remove_all(work);
    fs::create_directories(work);
    const fs::path log = work / "log.txt";
    const std::string scene = data + "/mosd/learn/learn0.pcd";

    std::cerr << "mem_bench: one 640x480 frame\n";
    const Run segment = run(cli, {"segment", scene, "-o", (work / "seg").string()}, log);

    std::cerr << "mem_bench: a 64-view database\n";
    const fs::path db = work / "db";
    const std::vector<std::string> ids = {"01", "05", "06", "08", "09", "10", "11", "12"};
    for (const auto& id : ids)
      run(cli,
          {"db", "render", db.string(), "--name", "obj_" + id,
           data + "/lmo/models/obj_0000" + id + ".ply", "--views", "8", "--units", "mm"},
          log);
    const Run recognize =
        run(cli, {"recognize", scene, "--db", db.string(), "-o", (work / "rec").string()}, log);

    std::cerr << "mem_bench: a batch of " << frames << " frames\n";
    const fs::path in = work / "batch-in";
    fs::create_directories(in);
    std::vector<fs::path> learn;
    for (const auto& e : fs::directory_iterator(data + "/mosd/learn"))
      if (e.path().extension() == ".pcd") learn.push_back(e.path());
    std::sort(learn.begin(), learn.end());
    if (learn.empty()) throw std::runtime_error(data + "/mosd/learn: no scenes");
    for (int i = 0; i < frames; ++i) {
      char name[32];
      std::snprintf(name, sizeof name, "frame%03d.pcd", i);
      fs::create_symlink(fs::absolute(learn[i % learn.size()]), in / name);
    }
    const Run batch =
        run(cli, {"segment", "--batch", in.string(), "-o", (work / "batch-out").string()}, log);
    // The frames' rows of the batch's summary.jsonl (one run: one row a frame, in order).
    std::vector<double> rss;
    std::ifstream sin(work / "batch-out" / "summary.jsonl");
    for (std::string line; std::getline(sin, line);)
      if (const auto row = nlohmann::json::parse(line); row.contains("frame"))
        rss.push_back(row["rss_mib"].get<double>());
    if (static_cast<int>(rss.size()) != frames)
      throw std::runtime_error("batch summary has " + std::to_string(rss.size()) + " frames");
    // The frames cycle through the distinct scenes; the heap keeps what the largest needed
    // (keep_freed_memory), so the resident set rises until every scene has been seen once.
    // Growth after that cycle would be a leak.
    const int cycle = std::min(frames, static_cast<int>(learn.size()));
    const double at_cycle = rss[cycle - 1], last = rss.back();
    const double growth = (last - at_cycle) / at_cycle;
    const double max_rss = *std::max_element(rss.begin(), rss.end());

    std::cerr << "mem_bench: the estimate of --max-memory against frames of 1x, 2x, 3x the size\n";
    struct Estimate {
      std::string frame;
      bool paper;
      double estimate, peak;
    };
    std::vector<Estimate> estimates;
    bool under = false;
    const proxseg::Frame learn0 = proxseg::read_pcd(scene);
    for (int k = 1; k <= 3; ++k) {
      const fs::path big = work / ("learn0-x" + std::to_string(k) + ".pcd");
      const proxseg::Frame f = upsampled(learn0, k);
      proxseg::write_pcd(big.string(), f, {});
      for (const bool paper : {false, true}) {
        proxseg::SegmentParams p = proxseg::preset("default");
        p.paper_labels = paper;
        std::vector<std::string> args = {"segment", big.string(), "-o", (work / "big").string()};
        if (paper) args.push_back("--paper-labels");
        const Run r = run(cli, args, log);
        estimates.push_back({std::to_string(f.width) + "x" + std::to_string(f.height), paper,
                             proxseg::segment_memory_mib(f, p), r.peak_mib});
        under = under || estimates.back().estimate < r.peak_mib;
      }
    }

    std::cerr << "mem_bench: address-space limits " << sweep_from << "-" << sweep_to << " MiB\n";
    const fs::path five = work / "batch-5";
    fs::create_directories(five);
    for (int i = 0; i < 5; ++i)
      fs::create_symlink(fs::absolute(learn[i % learn.size()]),
                         five / ("frame" + std::to_string(i) + ".pcd"));
    struct Job {
      std::string name;
      std::vector<std::string> args;
    };
    const std::vector<Job> jobs = {
        {"`segment` learn0", {"segment", scene, "-o", (work / "lim").string()}},
        {"`segment --paper-labels --threads 4` learn0",
         {"segment", scene, "--paper-labels", "--threads", "4", "-o", (work / "lim").string()}},
        {"`segment --batch` 5 frames, 2 at once",
         {"segment", "--batch", five.string(), "--threads", "2", "-o",
          (work / "lim-batch").string()}},
        {"`recognize` learn0, 64 views",
         {"recognize", scene, "--db", db.string(), "-o", (work / "lim-rec").string()}}};
    std::vector<std::vector<std::string>> sweep(jobs.size());  // per job, per limit: its ending
    std::vector<double> limits;
    bool signalled = false;
    for (double mib = sweep_from; mib <= sweep_to + 1e-9; mib += sweep_step) limits.push_back(mib);
    for (std::size_t j = 0; j < jobs.size(); ++j)
      for (const double mib : limits) {
        fs::remove_all(work / "lim-batch");
        const Run r = launch(cli, jobs[j].args, log, mib);
        const std::string output = slurp(log);
        const bool ok = WIFEXITED(r.status) && WEXITSTATUS(r.status) == 0;
        const bool failed =
            WIFEXITED(r.status) && WEXITSTATUS(r.status) == 1 && !error_line(output).empty();
        // Below what its shared libraries need, the dynamic loader stops before main: exit 127.
        const bool unloaded =
            WIFEXITED(r.status) && WEXITSTATUS(r.status) == 127 &&
            output.find("error while loading shared libraries") != std::string::npos;
        if (unloaded) {
          sweep[j].push_back("127");
          continue;
        }
        if (!ok && !failed) {
          signalled = true;
          std::cerr << "mem_bench: " << jobs[j].name << " at " << mib
                    << " MiB: " << ending(r.status) << "\n"
                    << output;
        }
        sweep[j].push_back(ok ? "0" : failed ? "1" : ending(r.status));
        if (failed && !ok) sweep[j].back() += ": " + error_line(output);
      }

    std::ostringstream md;
    md << "## Memory\n\nPeak resident set of the `proxseg` process (Linux `wait4`), and the "
          "resident "
          "set after each frame of a batch (`segment --batch`, the rows of its `summary.jsonl`). "
       << "`make bench` fails if the batch grows by more than " << fixed(100 * max_growth)
       << " % from frame " << cycle << " (each of the " << learn.size()
       << " scenes seen once: the heap keeps what the largest needed) to frame " << frames
       << ".\n\n"
       << "| run | peak RSS (MiB) |\n|---|---:|\n"
       << "| `segment` one 640x480 frame (mOSD learn0) | " << fixed(segment.peak_mib) << " |\n"
       << "| `recognize` learn0 against 64 views (8 LINEMOD objects x 8) | "
       << fixed(recognize.peak_mib) << " |\n"
       << "| `segment --batch` " << frames << " frames (mOSD learn, cycled) | "
       << fixed(batch.peak_mib) << " |\n\n"
       << "Resident set during the batch (MiB): after frame 1 " << fixed(rss.front())
       << ", frame 10 " << fixed(rss[std::min(9, frames - 1)]) << ", frame " << cycle << " "
       << fixed(at_cycle) << ", frame " << frames / 2 << " " << fixed(rss[frames / 2 - 1])
       << ", frame " << frames << " " << fixed(last) << ", highest " << fixed(max_rss)
       << "; growth from frame " << cycle << " to " << frames << ": " << fixed(100 * growth, 1)
       << " %.\n";
    md << "\n### The estimate behind --max-memory\n\n`segment_memory_mib()` (an estimate from the "
          "frame's size, checked before a frame starts) against the peak resident set of "
          "`proxseg segment` on learn0 and learn0 upsampled 2x and 3x:\n\n"
       << "| frame | paper labels | estimate (MiB) | peak RSS (MiB) | estimate / peak |\n"
       << "|---|---|---:|---:|---:|\n";
    for (const Estimate& e : estimates)
      md << "| " << e.frame << " | " << (e.paper ? "yes" : "no") << " | " << fixed(e.estimate)
         << " | " << fixed(e.peak) << " | " << fixed(e.estimate / e.peak, 2) << " |\n";
    md << "\n### Address-space limits\n\nEach run under `ulimit -v` (RLIMIT_AS) from "
       << fixed(sweep_from) << " to " << fixed(sweep_to) << " MiB in steps of " << fixed(sweep_step)
       << " MiB: 0 = done, 1 = stopped with a message (the first is quoted), 127 = the dynamic "
          "loader could not map the program's libraries (before proxseg runs), anything else (a "
          "signal) is a failure of the benchmark.\n\n"
       << "| run | limits | exit 0 | exit 1 | exit 127 | other | first message |\n"
       << "|---|---:|---:|---:|---:|---:|---|\n";
    for (std::size_t j = 0; j < jobs.size(); ++j) {
      std::size_t done = 0, stopped = 0, unloaded = 0;
      std::string first;
      for (const std::string& e : sweep[j]) {
        done += e == "0";
        unloaded += e == "127";
        stopped += e == "1" || e.rfind("1: ", 0) == 0;
        if (first.empty() && e.rfind("1: ", 0) == 0) first = e.substr(3);
      }
      md << "| " << jobs[j].name << " | " << limits.size() << " | " << done << " | " << stopped
         << " | " << unloaded << " | " << limits.size() - done - stopped - unloaded << " | "
         << first << " |\n";
    }
    std::ofstream(out) << md.str();
    if (!json_out.empty())
      std::ofstream(json_out) << nlohmann::json{
          {"segment_peak_mib", segment.peak_mib},
          {"recognize_64_views_peak_mib", recognize.peak_mib},
          {"batch_peak_mib", batch.peak_mib},
          {"batch_rss_mib", rss},
          {"batch_growth", growth}}.dump(2);
    std::cout << md.str();
    if (growth > max_growth) {
      std::cerr << "mem_bench: the batch grew by " << fixed(100 * growth, 1) << " %\n";
      return 1;
    }
    if (under) {
      std::cerr << "mem_bench: an estimate of --max-memory is below the peak it estimates\n";
      return 1;
    }
    if (signalled) {
      std::cerr << "mem_bench: a run under an address-space limit ended by a signal\n";
      return 1;
    }
  } catch (const std::exception& e) {
    std::cerr << "mem_bench: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
