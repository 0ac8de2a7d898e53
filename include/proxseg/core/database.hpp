// The model database [paper 3.4, Fig. 2]: named objects, each with several partial views,
// described once so that recognition does no feature work on the models. A view keeps in memory
// what the shortlist compares (its signature, DescriptorParams, registration_types.hpp); its
// described cloud and its parts' signatures are made or read on first use, so that a database
// of thousands of views opens in milliseconds. Making a view is in recognition/model_view.hpp,
// reading and writing the database file in recognition/database_io.hpp (docs/database.md).
#pragma once
#include <proxseg/core/errors.hpp>
#include <proxseg/core/frame.hpp>
#include <proxseg/core/lazy.hpp>
#include <proxseg/core/registration_types.hpp>

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace proxseg {

struct ModelView {
  std::string object;
  std::string name;         // unique in its database ("duck-003"); what reports call the view
  std::string source;       // what it was made from (input files, or the rendering camera)
  std::int64_t record = 0;  // its record in the database file; 0 = not stored
  std::size_t points = 0;   // after the voxel filter
  bool coloured = false;    // the cloud has colours (recognition compares them)
  // The sensor in the model frame; NaN for a full model (seen from everywhere).
  Eigen::Vector3d viewpoint = Eigen::Vector3d::Zero();
  // The whole view's signature (parts empty), and its parts' sketches: sketch_distance() is at
  // most the part's signature_distance(), which lets the shortlist skip reading the parts of
  // views that cannot enter it.
  Signature signature;
  SketchSet part_sketches;
  std::shared_ptr<const Lazy<std::vector<Signature>>> parts;  // the parts' signatures
  std::shared_ptr<const Lazy<Cloud>> described;  // points in the model frame, normals, FPFH, ...

  // The described cloud, read on first use for a stored view. Throws InputError naming the view
  // and what is damaged when its record is (every later call throws the same).
  const Cloud& cloud() const { return described->get(); }
  const std::vector<Signature>& part_signatures() const { return parts->get(); }
};

struct DatabaseFile;  // an open database file (src/recognition/database_file.hpp)

struct Database {
  std::string dir;
  DescriptorParams descriptor;  // every view and every candidate is described with these
  std::vector<ModelView> views;
  // Views left out when the database was opened, their summary records damaged: "where: what".
  std::vector<std::string> damaged;
  // The file the views are read from; null for a database made in memory or not yet written.
  std::shared_ptr<DatabaseFile> file;
  std::vector<std::string> objects() const;  // names, in order of first appearance
};

}  // namespace proxseg
