// Memory of the proxseg CLI as a user runs it (docs/robustness.md, "Memory"): peak resident set
// of one 640x480 frame segmented, of one scene recognised against a 64-view database (8 LINEMOD
// objects x 8 rendered views), and the resident set after each of 100 frames of a batch, which
// must not grow. Each measurement is its own process (peak RSS from wait4). Writes a markdown
// section for docs/results.md and exits 1 if the batch grows by more than --max-growth.
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
};

// Runs the CLI with args (stdout and stderr to log); its peak RSS from the kernel's accounting.
Run run(const std::string& cli, const std::vector<std::string>& args, const fs::path& log) {
  std::vector<char*> argv = {const_cast<char*>(cli.c_str())};
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const auto start = std::chrono::steady_clock::now();
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    std::freopen(log.c_str(), "w", stdout);
    std::freopen(log.c_str(), "a", stderr);
    ::execv(cli.c_str(), argv.data());
    std::_Exit(127);
  }
  int status = 0;
  rusage usage{};
  ::wait4(pid, &status, 0, &usage);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::ifstream in(log);
    std::stringstream s;
    s << in.rdbuf();
    throw std::runtime_error("proxseg " + args.front() + " failed:\n" + s.str());
  }
  return {usage.ru_maxrss / 1024.0,
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()};
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
                 "Fail if the RSS after the last frame exceeds that after frame 10 by this share");
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
    const double at10 = rss[std::min(9, frames - 1)], last = rss.back();
    const double growth = (last - at10) / at10;
    const double max_rss = *std::max_element(rss.begin(), rss.end());

    std::ostringstream md;
    md << "## Memory\n\nPeak resident set of the `proxseg` process (Linux `wait4`), and the "
          "resident "
          "set after each frame of a batch (`segment --batch`, the rows of its `summary.jsonl`). "
       << "`make bench` fails if the batch grows by more than " << fixed(100 * max_growth)
       << " % from frame 10 to frame " << frames << ".\n\n"
       << "| run | peak RSS (MiB) |\n|---|---:|\n"
       << "| `segment` one 640x480 frame (mOSD learn0) | " << fixed(segment.peak_mib) << " |\n"
       << "| `recognize` learn0 against 64 views (8 LINEMOD objects x 8) | "
       << fixed(recognize.peak_mib) << " |\n"
       << "| `segment --batch` " << frames << " frames (mOSD learn, cycled) | "
       << fixed(batch.peak_mib) << " |\n\n"
       << "Resident set during the batch (MiB): after frame 1 " << fixed(rss.front())
       << ", frame 10 " << fixed(at10) << ", frame " << frames / 2 << " "
       << fixed(rss[frames / 2 - 1]) << ", frame " << frames << " " << fixed(last) << ", highest "
       << fixed(max_rss) << "; growth from frame 10 to " << frames << ": " << fixed(100 * growth, 1)
       << " %.\n";
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
  } catch (const std::exception& e) {
    std::cerr << "mem_bench: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
