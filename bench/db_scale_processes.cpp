// db_scale_bench's database file as a user meets it, one process per question
// (db_scale_bench.hpp): opening it in a fresh process, and `proxseg recognize --object` on test
// views (wall, CPU, peak RSS, answers).
#include <proxseg/core/errors.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/recognition/database_io.hpp>
#include <proxseg/recognition/recognition.hpp>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include <fcntl.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "bench_util.hpp"
#include "db_scale_bench.hpp"

namespace proxseg::bench::dbscale {
namespace {

namespace fs = std::filesystem;

struct ProcessRun {
  int code = -1;
  double wall_s = 0, cpu_s = 0;
  std::string out;
};

// Runs argv (stdout to out_file, stderr discarded): wall from spawn to exit, the child's CPU
// (user + system) from wait4().
ProcessRun run_process(const std::vector<std::string>& argv, const std::string& out_file) {
  posix_spawn_file_actions_t files;
  posix_spawn_file_actions_init(&files);
  posix_spawn_file_actions_addopen(&files, 1, out_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&files, 2, "/dev/null", O_WRONLY, 0);
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  ProcessRun r;
  pid_t pid = 0;
  const auto t0 = Clock::now();
  const int failed = posix_spawn(&pid, args[0], &files, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&files);
  if (failed) throw InputError(argv[0] + ": cannot run (" + std::strerror(failed) + ")");
  int status = 0;
  rusage usage{};
  ::wait4(pid, &status, 0, &usage);
  r.wall_s = ms_since(t0) / 1000;
  r.cpu_s = usage.ru_utime.tv_sec + usage.ru_stime.tv_sec +
            (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec) / 1e6;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream in(out_file);
  r.out.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return r;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : (v[v.size() / 2 - 1] + v[v.size() / 2]) / 2;
}

// This process's peak resident set (VmHWM: of this program's memory since its exec). A parent's
// wait4() cannot tell it: Linux carries the RSS peak of the memory that spawned a child into the
// child's ru_maxrss.
double peak_rss_mb() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind("VmHWM:", 0) == 0) return std::stol(line.substr(6)) / 1024.0;
  return 0;
}

}  // namespace

int open_only(const std::string& dir, const std::string& object) {
  const auto t0 = Clock::now();
  const Database db = load_database(dir);
  const double ms = ms_since(t0);
  nlohmann::json out = {{"views", db.views.size()}, {"ms", ms}, {"rss_mb", peak_rss_mb()}};
  if (!object.empty()) {
    const SceneObject o = recognize_object(read_point_cloud(object), db, {});
    out["object"] = {{"name", o.recognition.name}, {"rss_mb", peak_rss_mb()}};
  }
  std::cout << out.dump() << "\n";
  return 0;
}

ProcessRow measure_processes(const std::string& self, const std::string& tools,
                             const std::string& dir, const std::string& first_dir,
                             const std::vector<std::string>& test_files,
                             const std::vector<std::string>& truths, double min_score,
                             const fs::path& scratch) {
  ProcessRow row;
  std::error_code ec;
  row.file_mb = fs::file_size(fs::path(dir) / kDatabaseFile, ec) / 1e6;
  std::vector<double> open_ms;
  for (int i = 0; i < 5; ++i) {
    const ProcessRun r = run_process({self, "--open", dir}, (scratch / "open.json").string());
    if (r.code != 0) throw InputError(dir + ": opening it in a child process failed");
    const nlohmann::json j = nlohmann::json::parse(r.out);
    row.views = j["views"];
    open_ms.push_back(j["ms"]);
    row.open_rss_mb = std::max(row.open_rss_mb, j["rss_mb"].get<double>());
  }
  row.open_ms = median(open_ms);
  std::vector<double> wall, cpu, wall_ratio, cpu_ratio;
  const auto object = [&](const std::string& db, const std::string& test) {
    return run_process(
        {tools, "recognize", "--object", test, "--db", db, "--json", "--threads", "2"},
        (scratch / "object.json").string());
  };
  for (std::size_t i = 0; i < test_files.size(); ++i) {
    const ProcessRun first = first_dir.empty() ? ProcessRun{} : object(first_dir, test_files[i]);
    const ProcessRun r = object(dir, test_files[i]);
    if (r.code != 0) throw InputError(tools + " recognize --object " + test_files[i] + " failed");
    const nlohmann::json j = nlohmann::json::parse(r.out);
    const nlohmann::json& c = j["candidates"][0];
    ++row.tests;
    row.tp += c["name"] == truths[i] && c["score"].get<double>() >= min_score;
    wall.push_back(r.wall_s);
    cpu.push_back(r.cpu_s);
    if (!first_dir.empty()) {
      wall_ratio.push_back(r.wall_s / first.wall_s);
      cpu_ratio.push_back(r.cpu_s / first.cpu_s);
    }
    const ProcessRun peak = run_process({self, "--open", dir, "--object", test_files[i]},
                                        (scratch / "object-rss.json").string());
    if (peak.code != 0) throw InputError(dir + ": recognising in a child process failed");
    row.rss_mb =
        std::max(row.rss_mb, nlohmann::json::parse(peak.out)["object"]["rss_mb"].get<double>());
  }
  row.wall_s = median(wall);
  row.cpu_s = median(cpu);
  if (!first_dir.empty()) {
    row.wall_ratio = median(wall_ratio);
    row.cpu_ratio = median(cpu_ratio);
  }
  return row;
}

}  // namespace proxseg::bench::dbscale
