// One frame of a recognition batch (recognize_frame.hpp).
#include <proxseg/recognition/recognition.hpp>
#include <proxseg/recognition/recognize_frame.hpp>

#include <utility>

#include "util/stopwatch.hpp"

namespace proxseg {

nlohmann::json recognize_frame(const FrameSource& source, const RecognizeJob& job,
                               const Database& db) {
  return frame_row(source, [&](nlohmann::json& row) {
    const detail::Stopwatch whole;
    const std::string prefix = output_prefix(job.out_dir, source.id);
    const Frame frame = read_frame(source);
    check_memory(frame, job.segmentation, source.files().front());
    detail::Stopwatch step;
    const SegmentResult result = segment(frame, job.segmentation);
    const double segment_ms = step.lap();
    const auto objects = recognize_scene(frame, result.selection, db, job.recognition);
    const double recognize_ms = step.lap();
    nlohmann::json report =
        recognition_report(source.cloud.empty() ? source.colour : source.cloud, job.db_dir, db,
                           job.recognition, &job.segmentation, objects);
    report["times_ms"] = {{"load_database", job.load_ms},
                          {"segment", segment_ms},
                          {"recognize", recognize_ms},
                          {"total", job.load_ms + whole.ms()}};
    write_recognition(prefix, frame, objects, db, std::move(report), true, job.outputs);
    row["outputs"] = file_sizes(job.out_dir, output_files(prefix, job.outputs, true));
    nlohmann::json names = nlohmann::json::array();
    for (const auto& o : objects) names.push_back(o.recognition.name);
    row["objects"] = names;
  });
}

}  // namespace proxseg
