// proxseg-tools: the commands of the proxseg CLI that need recognition or evaluation (cli.hpp,
// kToolCommands), linked with those libraries. `proxseg` runs it for them with its own arguments
// (proxseg.cpp), so its messages and help read as proxseg's.
#include <CLI/CLI.hpp>

#include "cli.hpp"

using namespace cli;

int main(int argc, char** argv) {
  DbOptions db;
  RecognizeOptions recognize;
  EvalOptions eval;
  SynthOptions synth;
  return program_main(argc, argv, [&](CLI::App& app) -> std::function<int()> {
    add_db(app, db);
    add_recognize(app, recognize);
    add_eval(app, eval);
    add_synth(app, synth);
    return [&] {
      if (app.got_subcommand("synth")) return run_synth(synth);
      if (app.got_subcommand("eval-seg")) return run_eval(eval);
      if (app.got_subcommand("db")) return run_db(db);
      if (app.got_subcommand("recognize"))
        return naming_input(
            recognize.object.empty() ? input_name(recognize) : cloud_name(recognize.object),
            "recognising it", [&] { return run_recognize(recognize); });
      return 2;
    };
  });
}
