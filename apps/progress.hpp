// A progress bar on stderr for batch work (the CLI's batch commands, bench/rec_bench): redrawn in
// place on a terminal, one line per step otherwise (logs stay readable in CI).
#pragma once

#include <unistd.h>

#include <algorithm>
#include <cstddef>
#include <iostream>
#include <string>

namespace cli {

class Progress {
 public:
  // quiet: counts the steps, draws nothing (the CLI's --quiet).
  explicit Progress(std::size_t total, bool quiet = false)
      : total_(total), tty_(isatty(STDERR_FILENO)), quiet_(quiet) {}
  void step(const std::string& what) {
    ++done_;
    if (quiet_) return;
    if (tty_) {
      const int width = 30,
                filled = static_cast<int>(width * done_ / std::max<std::size_t>(total_, 1));
      std::cerr << "\r[" << std::string(filled, '#') << std::string(width - filled, ' ') << "] "
                << done_ << "/" << total_ << " " << what << "\033[K" << std::flush;
      if (done_ == total_) std::cerr << "\n";
    } else if (total_ <= 200 || done_ % ((total_ + 199) / 200) == 0 || done_ == total_) {
      // At most about 200 lines in a log, whatever the batch size.
      std::cerr << "[" << done_ << "/" << total_ << "] " << what << "\n";
    }
  }

 private:
  std::size_t total_, done_ = 0;
  bool tty_, quiet_;
};

}  // namespace cli
