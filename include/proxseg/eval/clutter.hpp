// Seeded cluttered tabletop scenes with per-point ground truth (`proxseg synth --clutter`): the
// development set for making the segmentation generalise beyond the few real scenes.
// docs/clutter.md describes what it makes and what it lacks.
#pragma once
#include <proxseg/core/errors.hpp>
#include <proxseg/core/frame.hpp>
#include <proxseg/core/render.hpp>

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

namespace proxseg {

enum class ClutterKind { mesh, box, cylinder };
enum class ClutterPose { standing, lying, stacked, leaning };
const char* to_string(ClutterKind k);
const char* to_string(ClutterPose p);

// A fixed object that scenes may draw (ClutterParams::catalogue): it appears exactly as given,
// without scale jitter or recolouring, so that it looks like the model a recogniser was given,
// up to the scene's lighting (shading is baked in as for every object).
struct CatalogueObject {
  std::string name;  // ClutterObject::name of its instances
  ClutterKind kind = ClutterKind::mesh;
  Mesh mesh;  // object frame, metres, unshaded colours; a box or cylinder centred on the origin
  // Box or cylinder centred on the origin: shading turns normals away from the centre (meshes
  // are shaded by their triangles' winding).
  bool convex = false;
  // Always placed lying (a marker); otherwise standing as modelled (z up) or, with p_lying,
  // turned 90 degrees about its longer horizontal axis.
  bool lies = false;
};

// Every knob of the generator. The defaults are the documented development set; a scene is a
// pure function of the whole struct (same params -> bit-identical frame).
struct ClutterParams {
  std::uint32_t seed = 1;
  // Folder of LINEMOD meshes obj_*.ply in millimetres (../shared/data/lmo/models); empty = boxes
  // and cylinders only. InputError if given and missing or without obj_*.ply. The meshes are read
  // once per process and folder (a cache keyed by path, size and modification time).
  std::string models_dir;

  // --- objects
  int min_objects = 5, max_objects = 15;  // object count, uniform in [min, max]
  // Shares of the objects: LINEMOD meshes (each mesh at most once per scene; when none is
  // left, or without models_dir, their share goes to boxes and cylinders), boxes, and
  // cylinders (1 - mesh_share - box_share).
  double mesh_share = 0.3;
  double box_share = 0.45;
  double mesh_scale_jitter = 0.1;  // meshes rescaled by a factor uniform in [1 - j, 1 + j]
  double mesh_recolour = 0.3;      // probability that a mesh's colours are tinted per channel
  // Fixed objects (scene_eval.hpp's known and unknown objects): a free or touching object is
  // drawn from the catalogue with probability catalogue_share, uniformly and with replacement,
  // at most 2 instances of one entry per scene (when every entry has 2, the object is drawn as
  // without a catalogue). An empty catalogue draws nothing: scenes are those of the generator
  // without it, bit for bit.
  std::vector<CatalogueObject> catalogue;
  double catalogue_share = 0;
  // Box and cylinder extents, metres: every extent in [min_size, max_size] (cylinder
  // diameters 3-12 cm); the flat ones ("marker" 3-3.5 x 11-14 x 1.2-2 cm or a 2.2-3 cm thick
  // cylinder, "soap bar" 5-7 x 8-10 x 2-3 cm, leaning "board"s) may be thinner, down to
  // flat_min_thickness.
  double min_size = 0.03, max_size = 0.30;
  double flat_min_thickness = 0.012;
  double flat_share = 0.15;  // probability that a box or cylinder is a small flat one, lying

  // --- poses (probabilities of the relation an object is placed with; the first object is
  // placed free; a stacked or leaning object without a suitable partner is placed touching).
  // free: a random spot of the layout area, not overlapping anything. All placements are checked
  // by 2D footprints (convex hulls of the vertices) against every object whose height range
  // overlaps: no interpenetration at all.
  double p_touching = 0.3;  // beside a placed object, footprint gap uniform in [0, max_touch_gap]
  double p_stacked = 0.12;  // on the top face of a placed box (footprint inside the face)
  double p_leaning = 0.1;   // a board or cylinder tilted, its top against a placed box's side
  // A free or touching object lies: a box on its largest face, a cylinder on its side, a mesh
  // turned 90 degrees about its longer horizontal axis (otherwise: upright as modelled).
  double p_lying = 0.25;
  double max_touch_gap = 0.005;  // metres
  // A touching box beside a box is placed flush with probability p_flush: turned by a multiple
  // of 90 degrees (+-1) from its neighbour and moved along one of its face normals, face to face
  // as in a pile (0: touching boxes take any turn and direction).
  double p_flush = 0;
  // A touching object is instead placed in front of its neighbour with probability p_front:
  // towards the camera (+-22.5 degrees of azimuth), at a footprint gap uniform in
  // [min_front_gap, max_front_gap], so that it hides part of the neighbour. With p_front > 0 the
  // camera's azimuth is drawn before the placement and the cameras tried stay within 15 degrees
  // of it (0: touching only, any azimuth).
  double p_front = 0;
  double min_front_gap = 0.02, max_front_gap = 0.08;  // metres
  double min_lean_deg = 10, max_lean_deg = 30;        // leaning tilt from vertical
  double max_lean_gap = 0.001;                        // leaning contact gap, metres
  // Layout area (where free objects' centres fall): sum of the footprints / density, density
  // uniform in this range (denser = more contact and occlusion), capped at max_area_half_extent
  // per axis (metres) and 15 cm inside the table; every footprint stays 2 cm inside the table.
  double min_density = 0.2, max_density = 0.35;
  double max_area_half_extent = 0.45;

  // --- camera (world: table top z = 0, z up, table centred on the origin, its edges along x
  // and y). Elevation, azimuth (uniform over the full turn) and look-at point are drawn, then
  // the distance, uniform between the nearest at which every object's footprint and height are
  // in the image (12 px margin) and max_distance. Up to 6 cameras are drawn per layout; the
  // first under which a quarter-resolution render shows every object with 1.2 x
  // min_visible_points (scaled) is used, otherwise the layout is redrawn.
  Camera camera;                                          // 640 x 480, fx = fy = 525 (Kinect-like)
  double min_distance = 0.6, max_distance = 1.3;          // eye to look-at point, metres
  double min_elevation_deg = 30, max_elevation_deg = 70;  // above the table plane
  // Look-at point: the layout centre (itself within 3 cm of the table centre) +- this in x and
  // y, metres, at a height of 2-6 cm.
  double target_jitter = 0.05;
  // Table top: width (x) and depth (y) uniform in these ranges (metres); beyond its edges the
  // sensor sees nothing (no return, label 0), as in mOSD where floor and walls were cropped.
  double min_table_width = 1.4, max_table_width = 2.2;
  double min_table_depth = 1.0, max_table_depth = 1.5;

  // --- appearance
  // Lambertian shading baked into the vertex colours: one light per scene, elevation uniform
  // in the range (degrees), random azimuth; brightness = ambient + (1 - ambient) max(0, n.l).
  double min_ambient = 0.3, max_ambient = 0.55;
  double min_light_elevation_deg = 35, max_light_elevation_deg = 80;
  // Objects are textured per vertex (4 mm grid), the table per pixel (filtered over the
  // pixel's footprint, so that checks and grain do not alias).
  double colour_noise = 2.5;  // std of per-pixel RGB sensor noise, 8-bit levels (0 = none)

  // --- sensor (RenderParams; seeded from the scene seed)
  double depth_noise = 0.0015;      // metres at 1 m, grows with z^2
  double disparity_step = 0.00285;  // Kinect v1 disparity quantisation, 1/m

  // --- validity: every object must show at least this many valid points, otherwise the next
  // layout of the same seed is drawn (sub-stream 1, 2, ...); std::runtime_error after
  // max_layouts draws.
  int min_visible_points = 400;
  int max_layouts = 64;
};

// The layout decision for one object (all lengths in metres, world frame: table top z = 0).
struct ClutterObject {
  std::uint32_t label = 0;  // 10 * (i + 1), i = 1..n
  ClutterKind kind = ClutterKind::box;
  // LINEMOD file stem (obj_000005), the catalogue entry's name, or box / cylinder / marker /
  // soap bar / board.
  std::string name;
  int catalogue = -1;  // index into ClutterParams::catalogue, -1 = not from the catalogue
  // plain, stripes, checker, blotches, label, bands, scan (mesh colours), catalogue
  std::string texture;
  ClutterPose pose = ClutterPose::standing;
  Eigen::Vector3d size = Eigen::Vector3d::Zero();  // box extents; cylinder (2r, 2r, h); mesh bbox
  Eigen::Isometry3d world_from_object = Eigen::Isometry3d::Identity();
  std::uint32_t support = 1;    // what it rests on: 1 = table, else the label of the box below
  std::uint32_t neighbour = 0;  // touching: placed beside; leaning: rests against; 0 = none
  double gap = 0;               // footprint gap to neighbour (touching, leaning)
  double tilt_deg = 0;          // leaning: tilt from vertical
  std::vector<std::uint32_t> touching;  // every object within max_touch_gap at overlapping heights
  std::vector<Eigen::Vector2d> footprint;  // convex hull of the world vertices in the table plane
  double z_min = 0, z_max = 0;             // lowest and highest world vertex
  std::size_t visible_points = 0;          // valid points labelled with it in the frame
};

struct ClutterScene {
  Frame frame;  // organized 640 x 480; label: 0 no return, 1 table, 10 * (i + 1) object i
  std::vector<ClutterObject> objects;
  std::string table;    // wood, cloth or plain: seed % 3 = 0, 1, 2
  RenderParams render;  // camera pose, noise, seed
  Eigen::Vector3d eye = Eigen::Vector3d::Zero(), target = Eigen::Vector3d::Zero();  // world
  double elevation_deg = 0, azimuth_deg = 0;
  Eigen::Vector3d light = Eigen::Vector3d::UnitZ();  // unit direction towards the light
  int layout = 0;  // the sub-stream that gave a valid layout (0 = the first draw)
};

// Lambertian shading baked into a mesh's colours: brightness = exposure x (ambient + (1 -
// ambient) max(0, n.light)), light a unit direction. Normals from the triangles (area-weighted),
// turned outwards as a whole when the mesh is wound inwards; with centre (boxes, cylinders),
// each turned away from it.
void shade(Mesh& m, const Eigen::Vector3d& light, double ambient, double exposure,
           const Eigen::Vector3d* centre = nullptr);

// Named kinds of generated scene, the development sets of the segmentation (docs/clutter.md):
// "clutter" (the defaults above: a cluttered tabletop), "piles" (mostly boxes, placed face to
// face, stacked and touching, in dense piles) and "occlusion" (a low camera over a dense layout:
// objects seen in pieces behind others). InputError for another name.
ClutterParams clutter_kind(const std::string& kind);

// Draws and renders one scene; throws InputError for a bad models_dir or inconsistent params,
// std::runtime_error if no valid layout is found in max_layouts draws.
ClutterScene clutter_layout_scene(const ClutterParams& params);
// Its frame only.
Frame clutter_scene(const ClutterParams& params);
// One line for logs: "11 objects (4 meshes, 6 boxes, 1 cylinders; 0 stacked, 1 leaning, 4 lying,
// 3 touching pairs), wood table, 231696 valid points, camera 1.19 m at 38 deg".
std::string clutter_summary(const ClutterScene& scene);

}  // namespace proxseg
