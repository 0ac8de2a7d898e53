// A coloured triangle mesh: an object model (read_mesh in io/cloud_io.hpp) that render() turns
// into model views [paper 3.4] or synthetic scenes.
#pragma once
#include <proxseg/core/frame.hpp>

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace proxseg {

struct Mesh {
  std::vector<Eigen::Vector3f> vertices;   // metres
  std::vector<Rgb> colours;                // per vertex
  std::vector<Eigen::Vector3i> triangles;  // vertex indices
  std::uint32_t label = 0;                 // ground-truth label written for its pixels
};

}  // namespace proxseg
