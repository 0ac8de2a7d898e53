// The page of a batch: OUT/index.html, one file that shows the frames of a batch folder as a grid
// of their pictures with their counts (candidates, or named objects) and times, failed frames
// marked with their error, sorting, filtering by name and status, paging (60 frames a page, so
// that a batch of 10,000 opens at once), the distributions of time and count, and a link from
// each frame to its 3D page (--outputs html) or picture. `proxseg view OUT/` writes it.
#pragma once
#include <proxseg/core/errors.hpp>

#include <string>

namespace proxseg {

// The page of the batch in out_dir, from its summary logs (summarize, frame_rows); the frames'
// pictures and pages are linked by file name, so the page goes with the folder. title "" = the
// folder's name. InputError when out_dir holds no batch's summary log.
std::string batch_page(const std::string& out_dir, const std::string& title = "");

}  // namespace proxseg
