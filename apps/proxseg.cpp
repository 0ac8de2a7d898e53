// proxseg command-line tool: proxseg <command> [options]. Logs on stderr, results on stdout or
// files. Exit codes: 0 success, 1 bad input, 2 usage. One file per command (cli.hpp).
#include <proxseg/core/frame.hpp>
#include <proxseg/core/memory.hpp>
#include <proxseg/core/version.hpp>

#include <CLI/CLI.hpp>

#include <exception>
#include <iostream>
#include <string>

#include "cli.hpp"

using namespace cli;
using proxseg::InputError;

int main(int argc, char** argv) {
  proxseg::keep_freed_memory();  // batch commands reuse each frame's buffers
  CLI::App app{"proxseg: unsupervised RGB-D segmentation and object recognition"};
  app.set_version_flag("--version", std::string("proxseg ") + proxseg::version() + " (commit " +
                                        proxseg::git_commit() + ")");
  app.require_subcommand(1);
  SegmentCommand segment;
  add_segment(app, segment);
  DbOptions db;
  add_db(app, db);
  RecognizeOptions recognize;
  add_recognize(app, recognize);
  EvalOptions eval;
  add_eval(app, eval);
  SynthOptions synth;
  add_synth(app, synth);
  SummaryOptions summary;
  add_summary(app, summary);
  try {
    app.parse(argc, argv);
    if (app.got_subcommand("segment")) return run_segment(segment);
    if (app.got_subcommand("synth")) return run_synth(synth);
    if (app.got_subcommand("eval-seg")) return run_eval(eval);
    if (app.got_subcommand("db")) return run_db(db);
    if (app.got_subcommand("recognize")) return run_recognize(recognize);
    if (app.got_subcommand("summary")) return run_summary(summary);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);  // prints help (code 0) or the usage error
    return code == 0 ? 0 : 2;
  } catch (const InputError& e) {
    std::cerr << "proxseg: error: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "proxseg: error: " << e.what() << "\n";
    return 1;
  }
  return 2;
}
