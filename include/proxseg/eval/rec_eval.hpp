// Recognition evaluation [paper 4, Tables 2-3, Fig. 3]: a seeded test set of object views from
// random viewpoints that are not database viewpoints, the paper's occlusion generator applied to
// it, and the measures of the paper (true- and false-positive rates, ROC, precision-recall).
// bench/rec_bench (`make bench-rec`) runs it; docs/metrics.md defines the measures.
#pragma once
#include <proxseg/core/database.hpp>
#include <proxseg/core/errors.hpp>
#include <proxseg/core/render.hpp>

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace proxseg {

// One object of the evaluation: a mesh in its model frame (metres).
struct TestObject {
  std::string name, file;
  Mesh mesh;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // bounding-box centre, where cameras look
  std::vector<Eigen::Matrix4d> symmetries;           // box_symmetries() of its vertices
};

// Every .ply mesh of dir, in file-name order, scaled by `scale` (BOP models are in mm: 0.001).
// BOP LINEMOD files (obj_000001.ply, ...) are named after their objects (ape, can, ...), other
// files after their stem. Throws InputError for a folder without meshes or a bad mesh.
std::vector<TestObject> read_test_objects(const std::string& dir, double scale);

// The model database of the evaluation: `views` render_views() of every object (the paper's
// Fig. 2: partial views from fixed viewpoints), described with `descriptor`. With a directory,
// built with add_view() and read back with load_database(), as a user would; without one, in
// memory (the sweeps).
Database render_database(const std::vector<TestObject>& objects, int views,
                         const DescriptorParams& descriptor, const std::string& dir = "");

struct TestSetParams {
  int tests = 2241;  // the paper's test set size; round-robin over the objects
  std::uint64_t seed = 1;
  double min_distance = 0.5, max_distance = 1.5;  // camera to object centre, metres
  double depth_noise = 0.0015;                    // RenderParams::depth_noise
  double disparity_step = 0.00285;                // RenderParams::disparity_step (Kinect v1)
  // A test viewpoint is at least this far (degrees, seen from the object) from every database
  // viewpoint, so that no test is a noisy copy of a stored view.
  double min_angle_to_view_deg = 10;
  Camera camera;
};

// One test: an object view from a random direction, distance and roll, in the camera frame
// (the sensor at the origin, as recognition assumes).
struct TestView {
  int index = 0;   // in the clean test set
  int object = 0;  // into the objects
  double distance = 0, nearest_view_deg = 0;
  Eigen::Matrix4d truth = Eigen::Matrix4d::Identity();  // camera <- model
  std::vector<Eigen::Vector3d> points;
  // The rendered colour of each point (the mesh's vertex colours; one per point), so that a
  // recogniser can be given them (describe_candidate(points, db, &colours)).
  std::vector<Rgb> colours;
  int bin = -1;             // occlusion bin (index into the bins), -1 = not occluded
  double occlusion = 0;     // share of the view's points removed
  int rendered_points = 0;  // before occlusion
};

// The test set: test k shows object k mod objects. database_directions are the viewpoints
// (unit directions from the object centre, view_sphere()) of every database the tests will meet.
// Test k depends only on the objects, the parameters and k.
std::vector<TestView> make_test_views(const std::vector<TestObject>& objects,
                                      const TestSetParams& params,
                                      const std::vector<Eigen::Vector3d>& database_directions);

// The paper's Table 3 bins of removed points: [10, 20), [20, 30), ..., [60, 70) %.
struct OcclusionBin {
  double lo = 0, hi = 0;
};
std::vector<OcclusionBin> paper_occlusion_bins();

// The synthetically occluded test set [4]: test i of the clean set (i < count) goes through
// occlude() with a random radius up to the view's size, redrawn (new seed) until its removed
// share falls in bin i mod bins, so that every bin gets the same number of tests. A test whose
// bin is not reached in 1000 draws is left out.
std::vector<TestView> occluded_test_views(const std::vector<TestView>& clean, int count,
                                          const std::vector<OcclusionBin>& bins,
                                          std::uint64_t seed);

// What a recogniser answered for one test: its best object (before any threshold), the score
// it ranks by, the pose of the best view and its time.
struct Answer {
  std::string best;  // empty: no view aligned
  double score = 0;
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();  // camera <- model
  double ms = 0;                                       // describe + recognition, wall
  // Stage times: describe (wall), and RANSAC (with correspondences), ICP and scoring summed
  // over the database views (views run in parallel, so the sums exceed the wall time).
  double describe_ms = 0, ransac_ms = 0, icp_ms = 0, score_ms = 0;
};

// The paper's measures over a set of tests at one minimum score: a test is a true positive when
// the answer names its object, a false positive when it names another, rejected ("unknown") when
// the score is under min_score. pose_ok: named right and within 2 cm and 10 degrees of the truth
// (the least over the object's symmetries).
struct Rates {
  int tests = 0, right = 0, wrong = 0, unknown = 0, pose_ok = 0;
  double mean_ms = 0;
  double tp_rate() const { return tests ? double(right) / tests : 0; }
  double fp_rate() const { return tests ? double(wrong) / tests : 0; }
  double pose_rate() const { return tests ? double(pose_ok) / tests : 0; }
};
bool named_right(const Answer& a, const TestView& t, const std::vector<TestObject>& objects,
                 double min_score);
// Over the tests `which` selects (all when empty); answers[i] belongs to tests[i].
Rates rates(const std::vector<TestView>& tests, const std::vector<Answer>& answers,
            const std::vector<TestObject>& objects, double min_score,
            const std::function<bool(const TestView&)>& which = {});

// The ROC [Fig. 3a] and precision-recall [Fig. 3b] curve as the minimum score goes from above
// every score down to 0: one point per distinct score. recall = tp_rate; precision = right /
// (right + wrong).
struct CurvePoint {
  double min_score = 0, tp_rate = 0, fp_rate = 0, precision = 1;
};
std::vector<CurvePoint> score_curve(const std::vector<TestView>& tests,
                                    const std::vector<Answer>& answers,
                                    const std::vector<TestObject>& objects,
                                    const std::function<bool(const TestView&)>& which = {});

}  // namespace proxseg
