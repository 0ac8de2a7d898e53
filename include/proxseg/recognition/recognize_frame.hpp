// One frame of a recognition batch (docs/batch.md): segment it, recognise its candidates against
// the database, write the outputs; built from the pieces of io/batch.hpp, so that its row and
// files are laid out like segment_frame's. The CLI's `recognize --batch` and the Dask runner
// (python/proxseg/dask.py) both use it.
#pragma once
#include <proxseg/core/database.hpp>
#include <proxseg/core/pipeline.hpp>
#include <proxseg/core/recognition_types.hpp>
#include <proxseg/io/batch.hpp>
#include <proxseg/io/frame_source.hpp>
#include <proxseg/io/output.hpp>

#include <nlohmann/json.hpp>
#include <string>

namespace proxseg {

// What a recognition batch does with each frame.
struct RecognizeJob {
  std::string out_dir;  // outputs go to OUT_DIR/<frame id>.* (folders made as needed)
  OutputSet outputs;    // which files (write_recognition)
  SegmentParams segmentation;
  RecognitionParams recognition;
  std::string db_dir;  // where the database was loaded from (named in the reports)
  double load_ms = 0;  // the time it took (the reports' times_ms.load_database)
};

// segment_frame() for recognition: the row has "objects" (names, in report order) instead of
// "k" and "candidates"; the report equals `proxseg recognize`'s for the frame (its times aside).
nlohmann::json recognize_frame(const FrameSource& frame, const RecognizeJob& job,
                               const Database& db);

}  // namespace proxseg
