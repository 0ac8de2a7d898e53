// A virtual depth camera: z-buffer rendering of coloured triangle meshes into a Frame, and the
// built-in synthetic tabletop scene used by `proxseg synth`, the demo and the tests.
#pragma once
#include <proxseg/core/frame.hpp>
#include <proxseg/core/mesh.hpp>

#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <vector>

namespace proxseg {

struct Camera {
  int width = 640, height = 480;
  double fx = 525.0, fy = 525.0, cx = 319.5, cy = 239.5;  // Kinect-like
};

struct RenderParams {
  Camera camera;
  Eigen::Isometry3d camera_from_world = Eigen::Isometry3d::Identity();
  double depth_noise = 0.0;  // std of the Kinect-like noise at 1 m (grows with z^2), metres
  // Kinect-like quantisation: the sensor measures disparity, so 1/depth is rounded to steps of
  // disparity_step (1/m) and the depth steps grow with z^2 (Kinect v1: about 0.00285, i.e.
  // 2.85 mm at 1 m and 6.4 mm at 1.5 m; Khoshelham and Elberink 2012). 0 = depth rounded to
  // 1 mm when there is noise, exact otherwise.
  double disparity_step = 0.0;
  std::uint32_t seed = 1;
};

// Renders the meshes (z-buffer visibility, barycentric vertex colours) into an organized frame
// in the camera frame; pixels hit by no triangle are invalid (NaN). label holds Mesh::label.
Frame render(const std::vector<Mesh>& meshes, const RenderParams& params);

// Mesh builders. Each surface is tessellated into a grid of roughly `cell`-sized quads and
// coloured per vertex by colour(local point), so textures (stripes, checkerboards) show through.
// The meshes are in the frame given by `pose` (world_from_local); label is left at 0.
using ColourFn = std::function<Rgb(const Eigen::Vector3d& local)>;
// A rectangle in the local xy plane, centred at the origin (normal +z), size = (x, y) extent.
Mesh make_plane(const Eigen::Isometry3d& pose, const Eigen::Vector2d& size, const ColourFn& colour,
                double cell = 0.005);
// A closed box centred at the origin, edges along the local axes, size = (x, y, z) extent.
Mesh make_box(const Eigen::Isometry3d& pose, const Eigen::Vector3d& size, const ColourFn& colour,
              double cell = 0.005);
// A closed cylinder centred at the origin, axis along local z from -height/2 to height/2.
Mesh make_cylinder(const Eigen::Isometry3d& pose, double radius, double height,
                   const ColourFn& colour, double cell = 0.005);

// A closed surface of revolution about the local z axis: the profile (radius >= 0, z) is swept
// around, each profile point a ring of vertices. Cups, bowls, fruit, pens and bottles. Every
// profile segment is cut into roughly `cell`-long pieces; a profile that starts and ends on the
// axis (radius 0) gives a closed surface, wound consistently along the profile's direction.
Mesh make_lathe(const Eigen::Isometry3d& pose, const std::vector<Eigen::Vector2d>& profile,
                const ColourFn& colour, double cell = 0.005);

// Partial views of one mesh for a model database [3.4, Fig. 2 right]: the virtual camera is put
// on a sphere around the mesh's bounding-box centre, looking at it, and the visible surface is
// kept (z-buffer), with the mesh's vertex colours and optional depth noise.
struct ViewSphereParams {
  int views = 8;
  double distance = 0;  // camera to centre, metres; 0 = max(0.6, 3 x the mesh's diameter)
  Camera camera;
  double depth_noise = 0;     // as RenderParams::depth_noise
  double disparity_step = 0;  // as RenderParams::disparity_step
  std::uint32_t seed = 1;     // view i uses seed + i
};
struct RenderedView {
  Frame points;         // valid points only, in the mesh's frame (unorganized)
  Eigen::Vector3d eye;  // the camera centre in the mesh's frame
};
// n unit directions spread evenly over the sphere (Fibonacci lattice); the same n gives the same
// directions.
std::vector<Eigen::Vector3d> view_sphere(int n);
// camera_from_world of a camera at eye looking at target (image y down, z forward).
Eigen::Isometry3d look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target);
std::vector<RenderedView> render_views(const Mesh& mesh, const ViewSphereParams& params);

struct SynthParams {
  std::uint32_t seed = 1;
  double depth_noise = 0.0015;  // metres at 1 m
};
// A table with coloured and textured boxes and cylinders; labels: 1 = table, 2.. = objects.
Frame synth_scene(const SynthParams& params);
// The pieces of synth_scene: its meshes in the world frame (table top at z = 0, z up, the
// camera on the -y side looking down at it) and its camera (noise and seed from params).
std::vector<Mesh> synth_meshes(const SynthParams& params);
RenderParams synth_render_params(const SynthParams& params);

}  // namespace proxseg
