// SegmentParams <-> JSON, for config files (--config) and for echoing into every report.
#pragma once
#include <proxseg/pipeline.hpp>
#include <proxseg/recognition.hpp>

#include <nlohmann/json.hpp>

namespace proxseg {

nlohmann::json to_json(const SegmentParams& params);
// Overrides the fields present in j; unknown keys or wrong types throw InputError naming the field.
SegmentParams params_from_json(const nlohmann::json& j, SegmentParams base = {});
// Reads a JSON config file (InputError naming file and field on failure).
SegmentParams read_params(const std::string& path, SegmentParams base = {});
// Named parameter sets: "default" (the best measured settings, docs/results.md) and "paper"
// (exactly the settings the paper gives: w_c = 0.275, alpha-beta swap, 2 cm voxels, alpha = 0.85;
// everything the paper leaves open keeps its default). Throws InputError for an unknown name.
SegmentParams preset(const std::string& name);

// Checks ranges (voxel size > 0, weights >= 0, ...); throws InputError naming the field.
void validate(const SegmentParams& params);

// RecognitionParams <-> JSON, the same way.
nlohmann::json to_json(const RecognitionParams& params);
RecognitionParams recognition_params_from_json(const nlohmann::json& j,
                                               RecognitionParams base = {});
void validate(const RecognitionParams& params);
// A `proxseg recognize --config` file: {"segmentation": {...}, "recognition": {...}}, either
// part optional, each laid out like the report's "parameters".
std::pair<SegmentParams, RecognitionParams> read_recognize_params(const std::string& path,
                                                                  SegmentParams seg,
                                                                  RecognitionParams rec);

}  // namespace proxseg
