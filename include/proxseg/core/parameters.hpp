// The parameters of segment() [paper 3.1-3.3] and recognize() [3.4] as one table: name, type,
// default, accepted range, unit, one line of help and the paper's value. The JSON config and the
// reports' "parameters" (io/params.hpp), validate(), the CLI's flags, `--set` and help, Python's
// parameter objects and docs/parameters.md (`proxseg params --markdown`) are all made from it.
#pragma once
#include <proxseg/core/errors.hpp>
#include <proxseg/core/pipeline.hpp>
#include <proxseg/core/recognition_types.hpp>

#include <cstdint>
#include <string>
#include <variant>
#include <vector>

namespace proxseg {

// A parameter's value: true/false, an integer, a seed, a real number or the name of a choice
// (an enum: "swap", "expansion", ...).
using ParamValue = std::variant<bool, int, std::uint64_t, double, std::string>;

enum class ParamType { kBool, kInt, kUnsigned, kReal, kChoice };

// One row of the table.
struct Parameter {
  std::string section;  // the JSON section ("voxels", "mrf", "registration", ...); "" = top level
  std::string name;     // the field ("voxel_size")
  ParamType type = ParamType::kReal;
  std::vector<std::string> choices;  // kChoice: the accepted names, in the enum's order
  // kInt, kUnsigned, kReal: the accepted values are [min, max], an end left out when *_open;
  // zero_off: 0 is accepted too (it switches the step off).
  double min = 0, max = 0;
  bool min_open = false, max_open = false, zero_off = false;
  std::string unit;  // "m", "deg", "px", "MiB", "m^2"; "" = none
  std::string help;  // one line
  // The CLI's long flag without its dashes ("voxel-size"); "" = only `--set`. A flag of a bool
  // takes no value: "no-..." sets it false, any other name true.
  std::string flag;
  std::vector<std::string> aliases;  // other spellings of the flag the CLI accepts
  ParamValue default_value;          // SegmentParams{} / RecognitionParams{}
  // The paper's value: segmentation, the paper preset's where the paper states it
  // (preset("paper")); recognition, what section 3.4 says. "" = the paper leaves it open.
  std::string paper;
  // The key before the selection's sections (0.1: "selection.image_normal_step"), still read, with
  // a deprecation note (renamed_note); "" = the key never changed.
  std::string old_key;

  std::string key() const;         // "voxels.voxel_size"; "threads" at the top level
  std::string type_name() const;   // "bool", "int", "uint64", "real", "choice"
  std::string range_text() const;  // "> 0 m", "in [0, 1]", "1 .. 64 px", "swap | expansion"
};

// The tables, in the order of the pipeline (docs/parameters.md).
const std::vector<Parameter>& segment_parameters();
const std::vector<Parameter>& recognition_parameters();

// The row of key ("voxels.voxel_size", or the bare name "voxel_size" when no other section has
// it; an old key or bare old name as well, see renamed_note); nullptr when there is none.
const Parameter* find_parameter(const std::vector<Parameter>& table, const std::string& key);
// For a key that found row by its old spelling, the deprecation note the CLI logs and Python warns
// with: "selection.image_normal_step is now selection.image.normal_step (the old key will be
// removed)"; "" when key is the row's current key or name.
std::string renamed_note(const Parameter& row, const std::string& key);
// The key of the row a mistyped key most likely meant (closest_name over the keys, else the row
// whose name ends the key: "mrf.voxel_size" -> "voxels.voxel_size"); "" when none is near. Every
// "did you mean" about a parameter (config keys, --set, require_parameter) comes from here.
std::string nearest_parameter(const std::vector<Parameter>& table, const std::string& key);
// find_parameter, or InputError "unknown parameter KEY (did you mean ...?)".
const Parameter& require_parameter(const std::vector<Parameter>& table, const std::string& key);

ParamValue get_parameter(const SegmentParams& params, const std::string& key);
ParamValue get_parameter(const RecognitionParams& params, const std::string& key);
// Sets one parameter (key as for find_parameter). InputError "field KEY: expected ..., got ..."
// for a value of the wrong type (an int is taken for a real, a non-negative int for a seed) or
// an unknown choice; the range is validate()'s.
void set_parameter(SegmentParams& params, const std::string& key, const ParamValue& value);
void set_parameter(RecognitionParams& params, const std::string& key, const ParamValue& value);

// The value written as text ("0.01", "true", "swap", "1e+06") and read back from it: the CLI's
// flags and `--set KEY=VALUE`. InputError "KEY: expected ..., got TEXT" when it does not parse.
std::string format_parameter(const ParamValue& value);
ParamValue parse_parameter(const Parameter& row, const std::string& text);
// Whether value lies in row's range (the check validate() makes for every row).
bool in_range(const Parameter& row, const ParamValue& value);

// The candidate nearest to name by edit distance, when near enough to be a likely typo (at most
// a third of its letters differ); "" otherwise. For "did you mean" in every error about a name.
std::string closest_name(const std::string& name, const std::vector<std::string>& candidates);

}  // namespace proxseg
