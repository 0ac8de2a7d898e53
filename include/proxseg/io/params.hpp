// SegmentParams and RecognitionParams <-> JSON, for config files (--config) and for echoing
// into every report. The checks (validate) and presets are in pipeline.hpp and
// recognition_types.hpp.
#pragma once
#include <proxseg/core/pipeline.hpp>
#include <proxseg/core/recognition_types.hpp>

#include <nlohmann/json.hpp>

namespace proxseg {

nlohmann::json to_json(const SegmentParams& params);
// Overrides the fields present in j; unknown keys or wrong types throw InputError naming the field.
SegmentParams params_from_json(const nlohmann::json& j, SegmentParams base = {});
// Reads a JSON config file (InputError naming file and field on failure).
SegmentParams read_params(const std::string& path, SegmentParams base = {});
// RecognitionParams <-> JSON, the same way.
nlohmann::json to_json(const RecognitionParams& params);
RecognitionParams recognition_params_from_json(const nlohmann::json& j,
                                               RecognitionParams base = {});
// A model database's descriptor parameters: {"voxel_size", "normal_radius", "fpfh_radii"}.
nlohmann::json to_json(const DescriptorParams& descriptor);
// A `proxseg recognize --config` file: {"segmentation": {...}, "recognition": {...}}, either
// part optional, each laid out like the report's "parameters".
std::pair<SegmentParams, RecognitionParams> read_recognize_params(const std::string& path,
                                                                  SegmentParams seg,
                                                                  RecognitionParams rec);

}  // namespace proxseg
