// The object-varied development set for recognition: a pool of many object kinds (the LINEMOD
// meshes and colour look-alikes of them, the YCB-Video shapes with generated paint, scanned
// textured meshes, and generated fruit, pens, markers, cups, bowls, boxes and cans), split into
// two halves of objects. Within a half, database folds leave different objects out, so that
// every object is unknown in some fold; scenes of a fold hold its known and unknown objects;
// database views are captured unlike the scenes (nearer, lit from the camera, other white
// balance). A rule is chosen on one half and scored on the other (docs/method.md,
// "Recognition that generalises"); bench/scene_bench --set objects runs it.
#pragma once
#include <proxseg/core/database.hpp>
#include <proxseg/core/errors.hpp>
#include <proxseg/eval/scene_eval.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace proxseg {

// One object of the pool.
struct PoolObject {
  CatalogueObject entry;  // name, mesh (object frame, metres, unshaded colours), placement
  std::string family;     // linemod, ycb, scan or generated
  // Look-alike group ("" = none): objects of one shape in other colours, or of one colour in
  // other shapes. A group stays in one half, so that a fold may know one and not the other.
  std::string group;
  int half = 0;  // 0 = A, 1 = B
};

struct ObjectPoolParams {
  // Each source is left out when empty.
  std::string linemod_dir;   // BOP LINEMOD obj_0000NN.ply (millimetres)
  std::string ycbv_dir;      // YCB-Video models/<class>/points.xyz and classes.txt
  std::string textured_dir;  // <name>/textured_simple_reoriented.obj (+ MTL and texture)
  bool generated = true;     // the generated fruit, pens, markers, cups, bowls, boxes and cans
};

// The pool, in a fixed order. Throws InputError when a given source lacks a file it needs.
std::vector<PoolObject> object_pool(const ObjectPoolParams& params);

// One database configuration of a half: which of its objects the database holds.
struct ObjectFold {
  std::string name;  // "A1", "A2", ..., "B1", ...
  int half = 0;
  std::vector<int> known, unknown;  // pool indices
};

struct ObjectFoldParams {
  int known = 12;   // objects in the database of a fold
  int unknown = 4;  // objects of the half that scenes show and the database does not hold
};

// Per half, folds until every object of the half has been unknown once: fold k leaves out the
// next `unknown` objects of the half (in pool order, wrapping) and knows the `known` objects
// after them. Look-alikes are neighbours in pool order, so some folds know one of a group and
// not the other.
std::vector<ObjectFold> object_folds(const std::vector<PoolObject>& pool,
                                     const ObjectFoldParams& params = {});

// The fold's catalogue for scene_set_params(): known entries first, then the unknown ones.
SceneCatalogue fold_catalogue(const std::vector<PoolObject>& pool, const ObjectFold& fold);

// How the database views are captured: unlike the scenes (which are 0.6-1.3 m away, lit by one
// light per scene from above), as a database made on a turntable would be.
struct CaptureParams {
  int views = 8;                    // per object, from view_sphere() directions
  double distance = 0.45;           // camera to the object's centre, metres
  double depth_noise = 0.0015;      // RenderParams::depth_noise (Kinect-like, at 1 m)
  double disparity_step = 0.00285;  // RenderParams::disparity_step
  // Shading of each view: a light beside the camera (up and to the left of it), this ambient.
  double ambient = 0.6;
  // Per object, each colour channel is scaled by a gain in [1 - w, 1 + w] (another camera's
  // white balance).
  double white_balance = 0.05;
  std::uint32_t seed = 7;
};

// The mesh with every colour's hue turned so that its dominant hue (circular mean, weighted by
// saturation x value: greys have no say) becomes `hue` (0-1); saturation and value kept, so that
// shading and texture stay and only the colour differs: a look-alike.
Mesh hue_turned(Mesh mesh, double hue);

// The database of the catalogue's known entries, captured with `capture`, in memory.
Database captured_database(const SceneCatalogue& catalogue, const CaptureParams& capture,
                           const DescriptorParams& descriptor);

}  // namespace proxseg
