// The names of evaluation scenes: a scene's category, number and cross-validation fold from its
// file name, and the scene files of a folder in natural order (mOSD learn scenes, the generated
// clutter, piles and occlusion sets of `proxseg synth`).
#pragma once
#include <proxseg/core/errors.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace proxseg {

// The category of a scene from its name: an mOSD learn scene ("learn17.pcd" -> "stacked"): 0-16
// boxes, 17-24 stacked, 25-32 occluded, 33-44 cylindric; a name starting with "clutter" (the
// generated clutter set of `proxseg synth --clutter`, clutter-001.pcd ...) -> "clutter"; any
// other name -> "other".
std::string scene_category(const std::string& scene_name);

// The number at the end of a scene's file stem ("clutter-017.pcd" -> 17, "learn3.pcd" -> 3), or
// -1 if the stem does not end in a digit.
long scene_number(const std::string& scene_name);

// The cross-validation fold of a scene (seg_cv): its category for mOSD learn scenes (boxes,
// stacked, occluded, cylindric), "<kind>-odd" / "<kind>-even" for generated scenes (clutter,
// piles, occlusion: the file name's prefix) by the parity of their number (the seed of the
// generated scene; no number -> even), "other" else.
std::string scene_fold(const std::string& scene_name);

// The files of a folder with one of the extensions (lower case), in natural order (learn2 before
// learn10). InputError if the folder does not exist or holds no such file.
std::vector<std::filesystem::path> scene_files(const std::string& dir,
                                               const std::vector<std::string>& extensions = {
                                                   ".pcd"});

}  // namespace proxseg
