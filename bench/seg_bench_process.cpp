// seg_bench's whole-process times (seg_bench.hpp): `proxseg segment` and bench/lccp_process as
// child processes, one process per frame and one per set, wall and CPU from wait4().
#include <proxseg/core/errors.hpp>
#include <proxseg/core/frame.hpp>
#include <proxseg/eval/scene_names.hpp>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <fcntl.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "bench_util.hpp"
#include "seg_bench.hpp"

extern char** environ;

namespace proxseg::bench::segbench {
namespace {

namespace fs = std::filesystem;

// Runs args[0] with args (no shell), stdin, stdout and stderr on /dev/null, and waits for it
// (wait4, for its CPU time). std::runtime_error if it cannot start or exits other than with
// `expected_exit`.
ProcessCost run_process(const std::vector<std::string>& args, int expected_exit = 0) {
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  const auto start = std::chrono::steady_clock::now();
  pid_t pid = 0;
  const int err = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (err != 0) throw std::runtime_error(args[0] + ": cannot start (" + std::strerror(err) + ")");
  int status = 0;
  struct rusage usage {};
  while (wait4(pid, &status, 0, &usage) < 0)
    if (errno != EINTR) throw std::runtime_error(args[0] + ": wait4: " + std::strerror(errno));
  auto secs = [](const timeval& t) { return t.tv_sec + t.tv_usec * 1e-6; };
  const ProcessCost cost{seconds_since(start), secs(usage.ru_utime) + secs(usage.ru_stime)};
  if (!WIFEXITED(status) || WEXITSTATUS(status) != expected_exit) {
    std::string cmd;
    for (const auto& a : args) cmd += (cmd.empty() ? "" : " ") + a;
    throw std::runtime_error(
        cmd + (WIFEXITED(status) ? ": exit status " + std::to_string(WEXITSTATUS(status))
                                 : ": killed by signal " + std::to_string(WTERMSIG(status))));
  }
  return cost;
}

// A fresh directory under the system's temporary directory, removed with everything in it.
struct TempDir {
  std::filesystem::path path;
  TempDir() {
    std::string t = (std::filesystem::temp_directory_path() / "seg_bench-XXXXXX").string();
    if (!mkdtemp(t.data())) throw std::runtime_error(t + ": " + std::strerror(errno));
    path = t;
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
};

// The two tools' command lines, and the temporary directory their outputs go to.
struct Tools {
  const Options& o;
  const TempDir& tmp;
  std::vector<std::string> thread_args;

  ProcessCost proxseg(const fs::path& scene, const std::string& prefix) const {
    std::vector<std::string> args = {o.proxseg_cli, "segment", scene.string(), "-o", prefix};
    args.insert(args.end(), thread_args.begin(), thread_args.end());
    return run_process(args);
  }
  ProcessCost lccp(const fs::path& scene) const {
    return run_process({o.lccp_process, scene.string(), "-o", tmp.path.string()});
  }
  void clear() const {
    for (const auto& e : fs::directory_iterator(tmp.path)) fs::remove_all(e.path());
  }
};

// One process per frame, alternating which tool goes first.
ProcessTimes one_per_frame(const Tools& t, const SceneSet& set,
                           const std::vector<fs::path>& files) {
  const int n = static_cast<int>(files.size());
  ProcessTimes single{set.name, "one process per frame", n, {}, {}};
  for (int i = 0; i < n; ++i) {
    const auto& f = files[i];
    auto run_proxseg = [&] {
      single.proxseg += t.proxseg(f, (t.tmp.path / ("p-" + f.stem().string())).string());
    };
    auto run_lccp = [&] { single.lccp += t.lccp(f); };
    if (i % 2 == 0) {  // alternating which tool goes first
      run_proxseg();
      run_lccp();
    } else {
      run_lccp();
      run_proxseg();
    }
    t.clear();
    std::cerr << "[process " << i + 1 << "/" << n << "] " << set.name << ": "
              << f.filename().string() << " proxseg " << fixed(single.proxseg.wall / (i + 1), 3)
              << " s, lccp_process " << fixed(single.lccp.wall / (i + 1), 3)
              << " s per frame (wall)\n";
  }
  return single;
}

// One process for the n frames: proxseg's --batch takes a folder, so a folder of links. `first`:
// proxseg goes first.
ProcessTimes one_for_all(const Tools& t, const SceneSet& set, const std::vector<fs::path>& files,
                         bool first) {
  const int n = static_cast<int>(files.size());
  ProcessTimes batch{set.name, "one process for " + std::to_string(n) + " frames", n, {}, {}};
  const fs::path in = t.tmp.path / "in";
  fs::create_directory(in);
  std::vector<std::string> lccp_args = {t.o.lccp_process};
  for (const auto& f : files) {
    fs::create_symlink(fs::absolute(f), in / f.filename());
    lccp_args.push_back(f.string());
  }
  lccp_args.insert(lccp_args.end(), {"-o", (t.tmp.path / "l-batch").string()});
  std::vector<std::string> proxseg_args = {
      t.o.proxseg_cli, "segment", "--batch", in.string(), "-o", (t.tmp.path / "p-batch").string()};
  proxseg_args.insert(proxseg_args.end(), t.thread_args.begin(), t.thread_args.end());
  if (first) {
    batch.proxseg = run_process(proxseg_args);
    batch.lccp = run_process(lccp_args);
  } else {
    batch.lccp = run_process(lccp_args);
    batch.proxseg = run_process(proxseg_args);
  }
  t.clear();
  std::cerr << "[process batch] " << set.name << ": proxseg " << fixed(batch.proxseg.wall / n, 3)
            << " s, lccp_process " << fixed(batch.lccp.wall / n, 3) << " s per frame (wall)\n";
  return batch;
}

Processes measure(const Options& o, const std::vector<SceneSet>& sets) {
  Processes p;
  const TempDir tmp;
  const Tools t{o, tmp,
                o.threads > 0 ? std::vector<std::string>{"--threads", std::to_string(o.threads)}
                              : std::vector<std::string>{}};
  // Start-up alone: the help text, and lccp_process without arguments (usage, exit 2).
  for (int i = 0; i < 5; ++i) {
    p.startup_proxseg += run_process({o.proxseg_cli, "--help"});
    p.startup_lccp += run_process({o.lccp_process}, 2);
  }
  for (std::size_t si = 0; si < sets.size(); ++si) {
    std::vector<fs::path> files = scene_files(sets[si].dir);
    if (static_cast<int>(files.size()) > o.process_scenes) files.resize(o.process_scenes);
    // Both tools find the files in the page cache: each is read once first.
    for (const auto& f : files)
      std::ifstream(f, std::ios::binary).ignore(std::numeric_limits<std::streamsize>::max());
    // One untimed run of each.
    t.proxseg(files.front(), (tmp.path / "warm").string());
    t.lccp(files.front());
    t.clear();
    p.times.push_back(one_per_frame(t, sets[si], files));
    p.times.push_back(one_for_all(t, sets[si], files, si % 2 == 0));
  }
  return p;
}

}  // namespace

Processes measure_processes(const Options& o, const std::vector<SceneSet>& sets) {
  if (o.process_scenes <= 0) return {};
  try {
    return measure(o, sets);
  } catch (const std::exception& e) {  // a tool failed, or the temporary directory
    throw InputError(std::string("whole-process timing: ") + e.what());
  }
}

}  // namespace proxseg::bench::segbench
