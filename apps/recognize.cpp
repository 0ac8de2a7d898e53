// `proxseg recognize`: segment -> select -> recognise every candidate [paper 3.1-3.4], or
// recognise one already segmented cloud (--object), or every frame of a dataset (--batch,
// batch.cpp).
#include <proxseg/core/errors.hpp>
#include <proxseg/core/pipeline.hpp>
#include <proxseg/io/batch.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/output.hpp>
#include <proxseg/io/params.hpp>
#include <proxseg/recognition/database_io.hpp>
#include <proxseg/recognition/recognition.hpp>
#include <proxseg/recognition/recognize_frame.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>

#include "cli.hpp"

namespace cli {

using proxseg::InputError;

void add_recognize(CLI::App& app, RecognizeOptions& o) {
  auto* cmd = app.add_subcommand("recognize", tool_about("recognize"));
  add_input_options(cmd, o, "Scene point cloud");
  cmd->add_option("--object", o.object,
                  "Recognise this one already segmented cloud instead of a scene (- for "
                  "standard input)")
      ->group(group::kInput);
  cmd->add_option("--db", o.db, "Model database directory (proxseg db add/render)")
      ->required()
      ->group(group::kInput);
  cmd->add_option("-o,--output", o.output,
                  "Output prefix: writes PREFIX.json, PREFIX.png (picture with a legend) and, "
                  "for a scene, PREFIX.pcd (field `object`: the id of the object holding each "
                  "point); required for a scene unless --json or --outputs none (with --batch: a "
                  "folder); - prints the JSON report on stdout and writes nothing")
      ->group(group::kOutput);
  o.outputs_flag = cmd->add_option("--outputs", o.outputs,
                                   "What to write for a scene, comma-separated: labels "
                                   "(PREFIX.object.png, 16-bit object ids), pcd "
                                   "(binary_compressed), png, json, html (the 3D page, proxseg "
                                   "view); or all; or none (nothing written, the table printed)")
                       ->capture_default_str()
                       ->group(group::kOutput);
  cmd->add_flag("--json", o.json,
                "Print the JSON report on stdout (without -o: it alone, no file written)")
      ->group(group::kOutput);
  add_batch_options(cmd, o);
  add_parameter_options(cmd, o, o.config,
                        "JSON {\"segmentation\": {...}, \"recognition\": {...}} over the defaults "
                        "(same layout as the report's \"parameters\")",
                        true);
  help_last(cmd);
}

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

// Views recognition found damaged when it read them: the answers come from the others.
void warn_damaged(const std::vector<proxseg::SceneObject>& objects) {
  std::vector<std::string> said;
  for (const auto& obj : objects)
    for (const std::string& d : obj.recognition.damaged)
      if (std::find(said.begin(), said.end(), d) == said.end()) {
        said.push_back(d);
        std::cerr << "proxseg: warning: " << d << "; the view is left out (see proxseg db check)\n";
      }
}

// The objects' table: id (as in PREFIX.pcd's `object` field, the picture's legend and the
// report's "id"), the candidates of the segmentation it holds (their instance ids, as in the
// progress lines), and its recognition.
void print(const std::vector<proxseg::SceneObject>& objects) {
  std::printf("%-4s %-10s %-7s %-22s %-6s %-7s %-8s %-22s %s\n", "id", "candidates", "points",
              "name", "score", "fitness", "coverage", "runner-up", "score");
  for (const auto& o : objects) {
    const auto& r = o.recognition;
    std::string of;
    for (auto i : o.instances) of += (of.empty() ? "" : "+") + std::to_string(i);
    if (o.origin == proxseg::SceneObject::Origin::kSplit) of += " (part)";
    if (of.empty()) of = "-";
    std::printf("%-4d %-10s %-7zu %-22s %-6.3f %-7.3f %-8.3f %-22s %.3f\n", o.id, of.c_str(),
                o.points.size(), r.name.c_str(), r.best.score, r.best.fitness, r.best.coverage,
                r.runner_up.view >= 0 ? r.runner_up.object.c_str() : "-", r.runner_up.score);
  }
}

// Segments the frame and recognises every candidate, with a progress bar; the stage times in ms.
std::vector<proxseg::SceneObject> segment_and_recognize(const proxseg::Frame& frame,
                                                        const proxseg::SegmentParams& seg,
                                                        const proxseg::Database& db,
                                                        const proxseg::RecognitionParams& rec,
                                                        double& segment_ms, double& recognize_ms) {
  auto t = Clock::now();
  const proxseg::SegmentResult result = proxseg::segment(frame, seg);
  segment_ms = ms_since(t);
  std::size_t candidates = 0;
  for (const auto& c : result.selection.components) candidates += !c.background;
  Progress progress = progress_bar(candidates);
  t = Clock::now();
  // The bar counts the candidates; the trials of the split and merge passes are logged.
  std::size_t steps = 0;
  const auto scene = proxseg::recognize_scene(
      frame, result.selection, db, rec, [&](const proxseg::SceneObject& s) {
        std::string of;
        for (auto i : s.instances) of += (of.empty() ? "" : "+") + std::to_string(i);
        if (steps++ < candidates)
          progress.step("candidate " + of + ": " + s.recognition.name);
        else  // a trial: in the result only when it named its points better than before
          say(Verbosity::kVerbose)
              << "proxseg: trial: "
              << (s.origin == proxseg::SceneObject::Origin::kSplit ? "part of candidate "
                                                                   : "union of candidates ")
              << of << ": " << s.recognition.name << "\n";
      });
  recognize_ms = ms_since(t);
  return scene;
}

}  // namespace

int run_recognize(const RecognizeOptions& o) {
  const bool object = !o.object.empty();
  check_batch_options(o);
  if (object && (!o.input.empty() || !o.colour.empty() || !o.depth.empty() || !o.batch.empty()))
    throw CLI::ValidationError("--object takes one segmented cloud instead of a scene");
  const SceneDestination to =
      o.batch.empty() ? scene_destination(o, o.output, o.json, !object) : SceneDestination{};
  if (!o.batch.empty()) check_batch_output(o.output);
  if (!object && o.batch.empty())
    check_scene_options(o, proxseg::output_files(to.prefix, to.files, true));
  proxseg::SegmentParams seg = proxseg::preset(o.preset);
  proxseg::RecognitionParams rec;
  std::vector<std::string> renamed;
  if (!o.config.empty())
    std::tie(seg, rec) = proxseg::read_recognize_params(o.config, seg, rec, &renamed);
  warn_renamed(renamed);
  apply_parameter_flags(o.params, seg, &rec);
  proxseg::validate(seg);
  proxseg::validate(rec);
  if (!to.prefix.empty()) make_parent(to.prefix);  // before the work: an unwritable output fails

  const auto start = Clock::now();
  const proxseg::Database db = proxseg::load_database(o.db);
  if (db.views.empty()) throw InputError(o.db + ": the database has no views");
  const double load_ms = ms_since(start);
  say() << "proxseg: database " << o.db << ": " << counted(db.objects().size(), "object") << ", "
        << counted(db.views.size(), "view") << " (" << human_ms(load_ms) << ")\n";
  for (const std::string& d : db.damaged)
    std::cerr << "proxseg: warning: " << d << "; the view is left out (see proxseg db check)\n";
  if (!o.batch.empty()) {
    const proxseg::OutputSet outputs = outputs_option(o.outputs);
    const proxseg::RecognizeJob job{o.output, outputs, seg, rec, o.db, load_ms};
    return run_batch(
        o, o.output, o.json,
        {{"command", "recognize"},
         {"outputs", proxseg::to_string(outputs)},
         {"database", o.db},
         {"parameters",
          {{"segmentation", proxseg::to_json(seg)}, {"recognition", proxseg::to_json(rec)}}}},
        [&](const proxseg::FrameSource& f) { return proxseg::recognize_frame(f, job, db); });
  }

  proxseg::Frame frame;
  std::vector<proxseg::SceneObject> objects;
  double segment_ms = 0, recognize_ms = 0;
  if (object) {
    const auto t = Clock::now();
    frame = read_cloud(o.object);
    objects.push_back(proxseg::recognize_object(frame, db, rec));
    recognize_ms = ms_since(t);
  } else {
    frame = read_input(o);
    say() << "proxseg: " << frame.valid_count() << " valid points (" << frame.width << "x"
          << frame.height << ")\n";
    print_colourless_note(input_name(o), frame, seg);
    proxseg::check_memory(frame, seg, input_name(o));
    objects = segment_and_recognize(frame, seg, db, rec, segment_ms, recognize_ms);
  }

  warn_damaged(objects);
  nlohmann::json report =
      proxseg::recognition_report(object ? cloud_name(o.object) : input_name(o), o.db, db, rec,
                                  object ? nullptr : &seg, objects);
  report["times_ms"] = {{"load_database", load_ms},
                        {"segment", segment_ms},
                        {"recognize", recognize_ms},
                        {"total", ms_since(start)}};
  // PREFIX.pcd (a scene), PREFIX.png and PREFIX.json: all made in memory, then all or none.
  if (!to.prefix.empty())
    report = proxseg::write_recognition(to.prefix, frame, objects, db, std::move(report), !object,
                                        to.files);
  if (to.report_to_stdout)
    std::cout << proxseg::json_text(report, 2) << "\n";
  else
    print(objects);
  return 0;
}

}  // namespace cli
