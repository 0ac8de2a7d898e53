// The files a segmentation or recognition writes beside PREFIX: the labelled PCD, the 16-bit
// label PNGs and the JSON report, made in memory and written all or none (write_files_atomic),
// and which of them --outputs asks for. The pictures among them are drawn by pictures.cpp.
#include <proxseg/core/errors.hpp>
#include <proxseg/core/version.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/output.hpp>
#include <proxseg/io/params.hpp>
#include <proxseg/io/view_page.hpp>

#include <algorithm>
#include <filesystem>
#include <limits>
#include <stdexcept>

#include "io/formats/image_io.hpp"
#include "io/report/pictures.hpp"
#include "util/parallel_for.hpp"
#include "util/shown_names.hpp"

namespace proxseg {

std::string label_png(const Frame& frame, const std::vector<std::uint32_t>& labels) {
  const std::size_t n = frame.size();
  if (labels.size() != n)
    throw std::invalid_argument("label_png: " + std::to_string(labels.size()) + " labels for " +
                                std::to_string(n) + " points");
  if (n == 0 || frame.width < 1 || frame.height < 1 ||
      static_cast<std::size_t>(frame.width) * static_cast<std::size_t>(frame.height) != n)
    throw std::invalid_argument("label_png: frame is " + std::to_string(frame.width) + "x" +
                                std::to_string(frame.height) + " with " + std::to_string(n) +
                                " points (expected a non-empty frame of width*height points)");
  const std::uint32_t largest = *std::max_element(labels.begin(), labels.end());
  if (largest > std::numeric_limits<std::uint16_t>::max())
    throw InputError("label " + std::to_string(largest) +
                     " does not fit a 16-bit PNG (expected labels 0..65535)");
  cv::Mat image(frame.height, frame.width, CV_16UC1);
  auto* px = image.ptr<std::uint16_t>(0);  // a new Mat is continuous
  for (std::size_t i = 0; i < n; ++i) px[i] = static_cast<std::uint16_t>(labels[i]);
  return detail::encode_png16(image);
}

nlohmann::json segmentation_report(const Frame& frame, const SegmentParams& params,
                                   const SegmentResult& r) {
  nlohmann::json j;
  j["proxseg"] = build_info();
  j["parameters"] = to_json(params);
  // Finite points too far out to voxelise (|x| / voxel size beyond 1e9) are left unlabelled like
  // invalid ones; counted so that they are not dropped silently.
  const std::size_t valid = r.voxels.valid_points;
  const std::size_t out_of_range = valid - r.voxels.voxelised_points;
  j["input"] = {{"width", frame.width},
                {"height", frame.height},
                {"organized", frame.organized()},
                {"colour", frame.coloured()},
                {"points", frame.size()},
                {"valid_points", valid},
                {"out_of_range_points", out_of_range}};
  // The blocks computed, which "parameters" alone does not tell: the input can take some off.
  j["features"] = {
      {"colour", r.blocks.colour}, {"texture", r.blocks.texture}, {"shape", r.blocks.shape}};
  if (const std::string off = colourless_note(frame, params.features); !off.empty())
    j["features"]["note"] = "the input has no colour: " + off;
  nlohmann::json times = nlohmann::json::object();
  for (const auto& [stage, ms] : r.times_ms) times[stage] = ms;
  times["total"] = r.total_ms;  // wall time of segment()
  j["times_ms"] = times;
  // Stages on a thread of their own beside the sequence above (not part of the total).
  nlohmann::json concurrent = nlohmann::json::object();
  for (const auto& [stage, ms] : r.concurrent_ms) concurrent[stage] = ms;
  j["concurrent_times_ms"] = concurrent;
  // Where the image-grid stages' time goes: "stage/step" (part of the stages above).
  nlohmann::json steps = nlohmann::json::object();
  for (const auto& [step, ms] : r.steps_ms) steps[step] = ms;
  j["step_times_ms"] = steps;
  j["voxels"] = {{"count", r.voxels.size()}, {"clustered", r.clustered.size()}};
  j["initial_centroids"] = r.initial_centroids.size();
  // Whether stages 2-6 ran (needs_paper_labels); without them "labels" are the image-grid
  // surfaces and k is 0.
  j["paper_labels"] = r.paper_labels;
  j["k"] = r.k();
  j["kmeans_iterations"] = r.kmeans_iterations_run;
  j["mrf"] = {{"enabled", params.mrf.enabled},
              {"energy_before", r.energy_before},
              {"energy_after", r.energy_after},
              {"cycles", r.mrf_cycles_run}};
  nlohmann::json labels = nlohmann::json::array();
  for (std::size_t label = 1; label < r.label_sizes.size(); ++label)
    if (r.label_sizes[label])
      labels.push_back({{"label", label}, {"points", r.label_sizes[label]}});
  j["labels"] = labels;
  const Selection& sel = r.selection;
  // "candidates" are the objects selection picked out ("selection.candidates" counts them);
  // "background" the large planes it reported beside them. Both keep the instance ids of the
  // instance image.
  nlohmann::json candidates = nlohmann::json::array(), background = nlohmann::json::array();
  for (const Candidate& c : sel.components) {
    auto vec = [](const Eigen::Vector3d& v) { return std::vector<double>{v.x(), v.y(), v.z()}; };
    std::vector<std::vector<double>> axes;
    for (int a = 0; a < 3; ++a) axes.push_back(vec(c.box.axes.col(a)));
    (c.background ? background : candidates)
        .push_back(
            {{"id", c.instance},
             {"label", c.label},
             {"points", c.points.size()},
             {"centroid", vec(c.centroid)},
             {"box",
              {{"centre", vec(c.box.centre)}, {"axes", axes}, {"extent", vec(c.box.extent)}}},
             {"background", c.background}});
  }
  j["selection"] = {{"clusters", sel.clusters},
                    {"weak_points", sel.weak_points},
                    {"instances", sel.components.size()},
                    {"candidates", candidates.size()}};
  j["candidates"] = candidates;
  j["background"] = background;
  return j;
}

std::string colourless_note(const Frame& frame, const FeatureParams& features) {
  if (frame.coloured()) return "";
  const FeatureBlocks asked = feature_blocks(features, true, frame.organized());
  const FeatureBlocks got = feature_blocks(features, false, frame.organized());
  const bool colour = asked.colour != got.colour, texture = asked.texture != got.texture;
  if (colour && texture) return "the colour and texture blocks are off";
  if (colour) return "the colour block is off";
  if (texture) return "the texture block is off";
  return "";
}

std::string json_text(const nlohmann::json& j, int indent) {
  return dump_shown(j, indent);
}

nlohmann::json build_info() {
  return {{"version", version()}, {"commit", git_commit()}};
}

OutputSet parse_outputs(const std::string& list, const std::string& field) {
  if (list.empty())
    throw InputError(field + ": no outputs (expected labels, pcd, png, json, html, all or none)");
  OutputSet o{false, false, false, false, false};
  if (list == "none") return o;
  std::size_t start = 0;
  while (start <= list.size()) {
    const std::size_t end = std::min(list.find(',', start), list.size());
    const std::string word = list.substr(start, end - start);
    start = end + 1;
    if (word == "labels")
      o.labels = true;
    else if (word == "pcd")
      o.pcd = true;
    else if (word == "png")
      o.png = true;
    else if (word == "json")
      o.json = true;
    else if (word == "html")
      o.html = true;
    else if (word == "all")
      o = OutputSet{true, true, true, true, true};
    else if (word == "none")
      throw InputError(field + ": none goes alone (it writes nothing), got \"" + list + "\"");
    else
      throw InputError(field + ": unknown output \"" + word +
                       "\" (expected labels, pcd, png, json, html or all, comma-separated; or "
                       "none)");
  }
  return o;
}

std::string to_string(const OutputSet& o) {
  std::string s;
  for (const auto& [on, name] :
       {std::pair{o.labels, "labels"}, std::pair{o.pcd, "pcd"}, std::pair{o.png, "png"},
        std::pair{o.json, "json"}, std::pair{o.html, "html"}})
    if (on) s += (s.empty() ? "" : ",") + std::string(name);
  return s.empty() ? "none" : s;
}

namespace {

// A page's title: the prefix's file name ("learn0" for out/learn0).
std::string page_title(const std::string& prefix) {
  return std::filesystem::path(prefix).filename().string();
}

}  // namespace

std::vector<std::string> output_files(const std::string& prefix, const OutputSet& o,
                                      bool recognition) {
  std::vector<std::string> files;
  if (o.labels) {
    if (recognition) {
      files.push_back(prefix + ".object.png");
    } else {
      files.push_back(prefix + ".label.png");
      files.push_back(prefix + ".instance.png");
    }
  }
  if (o.pcd) files.push_back(prefix + ".pcd");
  if (o.png) files.push_back(prefix + ".png");
  if (o.json) files.push_back(prefix + ".json");
  if (o.html) files.push_back(prefix + ".html");
  return files;
}

namespace {
void write_segmentation_files(const std::string& prefix, const Frame& frame,
                              const std::vector<std::uint32_t>& point_labels,
                              const std::vector<std::uint32_t>& instances,
                              const nlohmann::json& report, const OutputSet& outputs, int threads,
                              std::vector<ViewField> more_fields);
}  // namespace

nlohmann::json write_segmentation(const std::string& prefix, const Frame& frame,
                                  const SegmentParams& params, const SegmentResult& result,
                                  const OutputSet& outputs) {
  const nlohmann::json report = segmentation_report(frame, params, result);
  // The page also shows the k-means labels where the MRF changed them [3.2].
  std::vector<ViewField> more;
  if (outputs.html && result.paper_labels && params.mrf.enabled &&
      result.point_labels_kmeans.size() == frame.size())
    more.push_back({"label_kmeans", result.point_labels_kmeans});
  write_segmentation_files(prefix, frame, result.point_labels, result.selection.instance, report,
                           outputs, params.threads, more);
  return report;
}

void write_segmentation(const std::string& prefix, const Frame& frame,
                        const std::vector<std::uint32_t>& point_labels,
                        const std::vector<std::uint32_t>& instances, const nlohmann::json& report,
                        const OutputSet& outputs, int threads) {
  write_segmentation_files(prefix, frame, point_labels, instances, report, outputs, threads, {});
}

namespace {

// write_segmentation's files; the 3D page shows more_fields before the labels and instances.
void write_segmentation_files(const std::string& prefix, const Frame& frame,
                              const std::vector<std::uint32_t>& point_labels,
                              const std::vector<std::uint32_t>& instances,
                              const nlohmann::json& report, const OutputSet& outputs, int threads,
                              std::vector<ViewField> more_fields) {
  if (point_labels.size() != frame.size() || instances.size() != frame.size())
    throw InputError(
        prefix + ": labels and instances must have one value per point of the frame (" +
        std::to_string(frame.size()) + "), got " + std::to_string(point_labels.size()) + " and " +
        std::to_string(instances.size()));
  // The picture (three quarters of the work: building and compressing it) is made beside the
  // rest, on a thread that ends with it (parallel_for: no OpenMP team left spin-waiting until the
  // process exits); then every file is written at once, so that a failure never leaves a partial
  // set.
  std::string png, pcd, label, instance;
  auto picture = [&] {
    if (outputs.png) png = label_image_png(frame, instances);
  };
  auto rest = [&] {
    if (outputs.pcd) pcd = pcd_bytes(frame, {{"label", point_labels}, {"instance", instances}});
    if (outputs.labels) {
      label = label_png(frame, point_labels);
      instance = label_png(frame, instances);
    }
  };
  if (threads != 1 && outputs.png) {
    detail::parallel_for(2, 2, [&](int i) { i == 0 ? picture() : rest(); });
  } else {
    picture();
    rest();
  }
  std::vector<std::pair<std::string, std::string>> files;
  if (outputs.labels) {
    files.emplace_back(prefix + ".label.png", std::move(label));
    files.emplace_back(prefix + ".instance.png", std::move(instance));
  }
  if (outputs.pcd) files.emplace_back(prefix + ".pcd", std::move(pcd));
  if (outputs.png) files.emplace_back(prefix + ".png", std::move(png));
  if (outputs.json) files.emplace_back(prefix + ".json", dump_shown(report, 2) + "\n");
  if (outputs.html) {
    more_fields.push_back({"label", point_labels});
    more_fields.push_back({"instance", instances});
    files.emplace_back(prefix + ".html", view_page(frame, more_fields, report,
                                                   {ViewOptions{}.max_points, page_title(prefix)}));
  }
  write_files_atomic(files);
}

}  // namespace

namespace {

const char* origin_name(SceneObject::Origin origin) {
  switch (origin) {
    case SceneObject::Origin::kSplit:
      return "split";
    case SceneObject::Origin::kMerged:
      return "merged";
    default:
      return "candidate";
  }
}

}  // namespace

nlohmann::json recognition_json(const SceneObject& o, const Database& db) {
  const Recognition& r = o.recognition;
  const auto rows = [](const Eigen::Matrix4d& m) {
    std::vector<std::vector<double>> out(4, std::vector<double>(4));
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) out[i][j] = m(i, j);
    return out;
  };
  const auto match = [&](const Match& m) -> nlohmann::json {
    if (m.view < 0) return nullptr;
    return {{"name", m.object},           {"view", db.views[m.view].name},
            {"score", m.score},           {"fitness", m.fitness},
            {"coverage", m.coverage},     {"colour", m.colour},
            {"free_space", m.free_space}, {"rmse", m.rmse},
            {"pose", rows(m.pose)}};
  };
  nlohmann::json j = {{"id", o.id},
                      {"instances", o.instances},
                      {"origin", origin_name(o.origin)},
                      {"points", o.points.size()},
                      {"centroid", {o.centroid.x(), o.centroid.y(), o.centroid.z()}},
                      {"name", r.name},
                      {"best", match(r.best)},
                      {"runner_up", match(r.runner_up)},
                      {"views_aligned", r.views_aligned},
                      {"times_ms", {{"describe", r.describe_ms}, {"align", r.align_ms}}}};
  if (r.best.view >= 0) {
    j["score"] = r.best.score;
    j["fitness"] = r.best.fitness;
    j["coverage"] = r.best.coverage;
    j["colour"] = r.best.colour;
    j["free_space"] = r.best.free_space;
    j["pose"] = rows(r.best.pose);
  }
  if (r.lookalike.compared > 0)
    j["lookalike"] = {{"compared", r.lookalike.compared},
                      {"differing", r.lookalike.differing},
                      {"votes_best", r.lookalike.first},
                      {"votes_runner_up", r.lookalike.second},
                      {"agreement_best", r.lookalike.first_agreement},
                      {"agreement_runner_up", r.lookalike.second_agreement},
                      {"decided", r.lookalike_decided}};
  return j;
}

nlohmann::json recognition_candidates_json(const std::vector<SceneObject>& objects,
                                           const Database& db) {
  const std::vector<Rgb> colours = recognition_colours(objects);
  nlohmann::json list = nlohmann::json::array();
  for (std::size_t i = 0; i < objects.size(); ++i) {
    list.push_back(recognition_json(objects[i], db));
    list.back()["colour"] = colours[i];
  }
  return list;
}

std::vector<std::uint32_t> recognition_labels(const Frame& frame,
                                              const std::vector<SceneObject>& objects) {
  const std::vector<int> owner = detail::point_owners(frame, objects);
  std::vector<std::uint32_t> labels(frame.size(), 0);
  for (std::size_t i = 0; i < owner.size(); ++i)
    if (owner[i] >= 0) labels[i] = static_cast<std::uint32_t>(objects[owner[i]].id);
  return labels;
}

nlohmann::json recognition_report(const std::string& input, const std::string& db_dir,
                                  const Database& db, const RecognitionParams& rec,
                                  const SegmentParams* seg,
                                  const std::vector<SceneObject>& objects) {
  nlohmann::json report;
  report["input"] = input;
  report["database"] = {{"dir", db_dir},
                        {"objects", db.objects().size()},
                        {"views", db.views.size()},
                        {"descriptor", to_json(db.descriptor)}};
  report["proxseg"] = build_info();
  report["parameters"] = {{"recognition", to_json(rec)}};
  if (seg) report["parameters"]["segmentation"] = to_json(*seg);
  report["candidates"] = recognition_candidates_json(objects, db);
  // Views whose damaged records left them out (at open, or when recognition read them): the
  // answers come from the others (`proxseg db check` lists every damaged record).
  std::vector<std::string> damaged = db.damaged;
  for (const SceneObject& o : objects)
    for (const std::string& d : o.recognition.damaged)
      if (std::find(damaged.begin(), damaged.end(), d) == damaged.end()) damaged.push_back(d);
  report["database"]["damaged_views"] = damaged;
  return report;
}

nlohmann::json write_recognition(const std::string& prefix, const Frame& frame,
                                 const std::vector<SceneObject>& objects, const Database& db,
                                 nlohmann::json report, bool scene, const OutputSet& outputs) {
  // The report names the files beside it by their file names: it stays right when the folder
  // is moved.
  const std::string stem = std::filesystem::path(prefix).filename().string();
  std::vector<std::pair<std::string, std::string>> files;
  std::vector<std::uint32_t> ids;
  if (scene && (outputs.pcd || outputs.labels || outputs.html))
    ids = recognition_labels(frame, objects);
  if (scene && (outputs.pcd || outputs.labels)) {
    if (outputs.labels) files.emplace_back(prefix + ".object.png", label_png(frame, ids));
    if (outputs.pcd) files.emplace_back(prefix + ".pcd", pcd_bytes(frame, {{"object", ids}}));
    report["labels"] = {{"file", stem + (outputs.pcd ? ".pcd" : ".object.png")},
                        {"field", "object"},
                        {"none", 0},
                        {"meaning",
                         "per point of the input frame, the id (candidates[].id) of the "
                         "recognised object that holds it; 0 = no object"}};
  }
  if (outputs.png) {
    cv::Size scene_size;
    const cv::Mat picture = detail::recognition_image(frame, objects, db, scene_size);
    report["picture"] = {{"file", stem + ".png"},
                         {"width", picture.cols},
                         {"height", picture.rows},
                         {"scene", {{"width", scene_size.width}, {"height", scene_size.height}}},
                         {"legend", "right of the scene: per object its colour, id, name, score"}};
    files.emplace_back(prefix + ".png", detail::encode_png(picture));
  }
  if (outputs.json) files.emplace_back(prefix + ".json", dump_shown(report, 2) + "\n");
  if (outputs.html && scene)
    files.emplace_back(prefix + ".html", view_page(frame, {{"object", ids}}, report,
                                                   {ViewOptions{}.max_points, page_title(prefix)}));
  write_files_atomic(files);
  return report;
}

std::vector<std::string> write_candidates(const std::string& dir, const Frame& frame,
                                          const SegmentResult& result) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw FileError(dir + ": cannot create candidates directory (" + ec.message() + ")");
  std::vector<std::string> written;
  try {
    for (const Candidate& c : result.selection.components) {
      if (c.background) continue;
      Frame cloud;
      cloud.width = static_cast<int>(c.points.size());
      cloud.height = 1;
      for (int p : c.points) {
        cloud.xyz.push_back(frame.xyz[p]);
        // No made-up colour: a colourless candidate stays colourless (recognised by shape).
        if (frame.coloured()) cloud.rgb.push_back(frame.rgb[p]);
      }
      const std::string path =
          (std::filesystem::path(dir) / ("candidate_" + std::to_string(c.instance) + ".pcd"))
              .string();
      write_pcd(path, cloud, {});
      written.push_back(path);
    }
  } catch (...) {
    for (const auto& f : written) std::filesystem::remove(f, ec);
    throw;
  }
  return written;
}

}  // namespace proxseg
