// Selection on the image grid (SelectionParams::Geometry::kImage) [paper 3.3, extension]:
// internal to core. segment() runs its two steps apart (pipeline.cpp); the tests call them.
#pragma once
#include <proxseg/core/frame.hpp>
#include <proxseg/core/selection.hpp>

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

namespace proxseg {

// Selection on the image grid of an organized frame (SelectionParams::Geometry::kImage): the
// support plane within the sensor's noise, then connected components of the remaining pixels
// that no depth step or concave crease separates; small pieces join their main neighbour.
// point_labels as for select_candidates. threads: 0 = all cores; the result does not depend on it.
Selection select_candidates_on_image(const Frame& frame,
                                     const std::vector<std::uint32_t>& point_labels,
                                     const SelectionParams& params, int threads = 0);

// The same in two steps. The geometry needs only the frame, so segment() reads it while the
// colour labels are computed: image_surfaces() finds the normals, the support plane, the creases
// and the surfaces (small pieces joined to their neighbour); select_on_image() merges the
// surfaces where the labels agree and forms the instances. select_candidates_on_image() is
// image_surfaces() with labelled = (point_labels != 0), then select_on_image().
struct ImageSurfaces {
  std::vector<Eigen::Vector3f> normals;                     // per pixel, NaN where none
  bool plane_found = false;                                 // whether a support plane was found
  Eigen::Vector3f plane_normal = Eigen::Vector3f::UnitZ();  // plane: normal . x + offset = 0
  float plane_offset = 0;
  std::vector<char> in_plane;  // per pixel: in the support plane within the sensor's noise
  std::vector<char> crease;    // per pixel: on a concave crease
  std::vector<int> surface;    // per pixel: surface id 0..count-1, -2 the plane, -1 none
  int count = 0;               // surfaces (connected components before any joining)
  // Wall time of each step inside image_surfaces(), in order (normals, support plane, ...).
  std::vector<std::pair<std::string, double>> steps_ms;
};
// labelled: per pixel, whether it takes part (valid and labelled).
ImageSurfaces image_surfaces(const Frame& frame, const std::vector<char>& labelled,
                             const SelectionParams& params, int threads = 0);
Selection select_on_image(const Frame& frame, ImageSurfaces surfaces,
                          const std::vector<std::uint32_t>& point_labels,
                          const SelectionParams& params, int threads = 0);

}  // namespace proxseg
