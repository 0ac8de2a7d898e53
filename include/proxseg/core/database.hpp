// The model database [paper 3.4, Fig. 2]: named objects, each with several partial views,
// described once so that recognition does no feature work on the models. Reading and writing it
// (docs/database.md) is in recognition/database_io.hpp.
#pragma once
#include <proxseg/core/frame.hpp>
#include <proxseg/core/registration_types.hpp>

#include <string>
#include <vector>

namespace proxseg {

struct ModelView {
  std::string object;
  std::string file;      // the view's PCD, relative to the database directory
  std::string features;  // its feature cache, relative to the database directory
  std::string source;    // what it was made from (input files, or the rendering camera)
  Cloud cloud;           // voxel-filtered points in the model frame, normals, FPFH, indexes
};

struct Database {
  std::string dir;
  DescriptorParams descriptor;  // every view and every candidate is described with these
  std::vector<ModelView> views;
  std::vector<std::string> objects() const;  // names, in order of first appearance
};

}  // namespace proxseg
