// SegmentParams and RecognitionParams <-> JSON, for config files (--config) and for echoing
// into every report. The checks (validate) and presets are in pipeline.hpp and
// recognition_types.hpp.
#pragma once
#include <proxseg/core/errors.hpp>
#include <proxseg/core/pipeline.hpp>
#include <proxseg/core/recognition_types.hpp>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace proxseg {

// The sections nest as the structs do: {"selection": {"image": {"normal_step": 4}, ...}}.
nlohmann::json to_json(const SegmentParams& params);
// Overrides the fields present in j; unknown keys or wrong types throw InputError naming the field.
// A key in its old spelling (Parameter::old_key: "selection": {"image_normal_step": 4}) is read
// as its new one, and its renamed_note() appended to *renamed when given (the CLI logs them).
SegmentParams params_from_json(const nlohmann::json& j, SegmentParams base = {},
                               std::vector<std::string>* renamed = nullptr);
// Reads a JSON config file (InputError naming file and field on failure).
SegmentParams read_params(const std::string& path, SegmentParams base = {},
                          std::vector<std::string>* renamed = nullptr);
// RecognitionParams <-> JSON, the same way.
nlohmann::json to_json(const RecognitionParams& params);
RecognitionParams recognition_params_from_json(const nlohmann::json& j,
                                               RecognitionParams base = {});
// A model database's descriptor parameters: {"voxel_size", "normal_radius", "fpfh_radii"}.
nlohmann::json to_json(const DescriptorParams& descriptor);
// A `proxseg recognize --config` file: {"segmentation": {...}, "recognition": {...}}, either
// part optional, each laid out like the report's "parameters".
std::pair<SegmentParams, RecognitionParams> read_recognize_params(
    const std::string& path, SegmentParams seg, RecognitionParams rec,
    std::vector<std::string>* renamed = nullptr);

}  // namespace proxseg
