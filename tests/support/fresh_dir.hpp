// Scratch directories of a test process: ctest runs every test in its own process, several at
// once, so tests that build the same database must not share its directory. Each is named
// after the process and removed when the process ends.
#pragma once
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

namespace proxseg::test {

inline std::vector<std::string>& made_dirs() {
  static std::vector<std::string> dirs;
  return dirs;
}

struct RemoveMadeDirs : ::testing::Environment {
  void TearDown() override {
    for (const auto& d : made_dirs()) std::filesystem::remove_all(d);
  }
};
inline const auto* const kRemoveMadeDirs = ::testing::AddGlobalTestEnvironment(new RemoveMadeDirs);

// PROXSEG_TEST_TMP/NAME-PID, empty.
inline std::string fresh_dir(const std::string& name) {
  const std::string dir =
      std::string(PROXSEG_TEST_TMP) + "/" + name + "-" + std::to_string(::getpid());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  made_dirs().push_back(dir);
  return dir;
}

}  // namespace proxseg::test
