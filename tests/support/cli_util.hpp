// Running the proxseg CLI from a test: exit code, stdout, stderr (test_cli, test_robustness;
// test_rec_bench runs bench/rec_bench the same way).
#pragma once
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <utility>

namespace cli_test {

namespace fs = std::filesystem;
inline const std::string kData = PROXSEG_DATA_DIR;
inline const std::string kCli = PROXSEG_CLI;

struct CliRun {
  int code;
  std::string out, err;
};

inline std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Runs `proxseg ARGS` (or another executable: bench/rec_bench in test_rec_bench) with its output
// captured in files under tmp.
inline CliRun run_in(const fs::path& tmp, const std::string& args, const std::string& exe = kCli) {
  fs::create_directories(tmp);
  // ctest runs test cases in parallel processes: one pair of capture files per test case.
  const std::string name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
  const std::string out = (tmp / (name + ".stdout")).string(),
                    err = (tmp / (name + ".stderr")).string();
  const int status = std::system((exe + " " + args + " >" + out + " 2>" + err).c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(out), slurp(err)};
}

// A program a test file runs (bench/rec_bench in test_rec_bench, ...): run(ARGS) runs it with its
// output captured under `tmp`, PROXSEG_TEST_TMP/NAME.
struct Program {
  Program(std::string exe, const std::string& name)
      : exe(std::move(exe)), tmp(fs::path(PROXSEG_TEST_TMP) / name) {}
  CliRun operator()(const std::string& args) const { return run_in(tmp, args, exe); }
  // A run that writes its files into OUT (made afresh) and prints its summary as JSON: ARGS plus
  // `--json -o OUT`, which must exit 0; the summary it printed.
  nlohmann::json json(const std::string& args, const fs::path& out) const {
    fs::remove_all(out);
    const CliRun r = (*this)(args + " --json -o " + out.string());
    EXPECT_EQ(r.code, 0) << r.err;
    return nlohmann::json::parse(r.out);
  }
  std::string exe;
  fs::path tmp;
};

inline std::string learn0() {
  const std::string p = kData + "/mosd/learn/learn0.pcd";
  if (!fs::exists(p)) ADD_FAILURE() << "missing real data: " << p;
  return p;
}

// Exit 1, one line on stderr naming `name`, and none of PREFIX.{pcd,png,json} written.
inline void expect_input_error(const CliRun& r, const std::string& name, const fs::path& prefix) {
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find(name), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  for (const char* ext : {".pcd", ".png", ".json"})
    EXPECT_FALSE(fs::exists(prefix.string() + ext)) << ext;
}

}  // namespace cli_test
