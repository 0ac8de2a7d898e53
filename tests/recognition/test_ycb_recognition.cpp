// Recognition on real YCB-Video frames (10 frames x 3 objects, a database of the 21 models), with
// leave-one-out, and the box symmetries the judge allows.
#include <gtest/gtest.h>
#include <unistd.h>
#include <proxseg/core/database.hpp>
#include <proxseg/core/errors.hpp>
#include <proxseg/core/pipeline.hpp>
#include <proxseg/core/render.hpp>
#include <proxseg/eval/occlusion.hpp>
#include <proxseg/eval/pose_error.hpp>
#include <proxseg/eval/ycb_frames.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/recognition/database_io.hpp>
#include <proxseg/recognition/model_view.hpp>
#include <proxseg/recognition/recognition.hpp>

#include <sys/stat.h>
#include <Eigen/Geometry>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <numeric>

#include "support/fresh_dir.hpp"
#include "support/model_views.hpp"

namespace fs = std::filesystem;
using namespace proxseg;
using namespace proxseg::test;

namespace {

struct YcbCase {
  std::string truth, named;
  bool pose_ok = false;
  PoseError error;
};

class Ycb : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    classes_ = read_lines(kData + "/ycbv/classes.txt");
    ASSERT_EQ(classes_.size(), 21u);
    const std::string dir = fresh_dir("db_ycbv");
    Database db = open_database(dir, DescriptorParams{});
    for (const auto& c : classes_) {
      const auto pts = read_xyz(kData + "/ycbv/models/" + c + "/points.xyz");
      add_view(db, c, frame_of(pts), Eigen::Vector3d::Constant(std::nan("")), c);
      models_[c] = pts;
      symmetries_[c] = box_symmetries(pts, 0.005);
    }
    db_ = load_database(dir);
  }

  // Right pose: within 2 cm and 10 degrees of meta.json's, allowing for the box symmetries; the
  // mug counts as turn-symmetric about its axis in frames where its handle is hidden.
  static YcbCase judge(const YcbFrame& y, const ObjectTruth& o, const Recognition& r) {
    YcbCase c{o.name, r.name, false, {}};
    c.error = pose_error(r.best.pose, o.pose, symmetries_[o.name]);
    if (o.name == "025_mug" && !handle_visible(y, o))
      c.error = axial_pose_error(r.best.pose, o.pose, Eigen::Vector3d(-0.0031, 0.0007, 0),
                                 Eigen::Vector3d::UnitZ());
    c.pose_ok = r.name == o.name && c.error.translation < 0.02 && c.error.rotation_deg < 10;
    return c;
  }

  // The handle (model x > 5 cm) is visible when some of its points, put in the camera by the
  // true pose, land on mug pixels at their own depth.
  static bool handle_visible(const YcbFrame& y, const ObjectTruth& o) {
    const Intrinsics& k = y.intrinsics;
    int seen = 0;
    for (const auto& p : models_.at(o.name)) {
      if (p.x() < 0.05) continue;
      const Eigen::Vector3d q = o.pose.topLeftCorner<3, 3>() * p + o.pose.topRightCorner<3, 1>();
      const int u = static_cast<int>(std::lround(k.fx * q.x() / q.z() + k.cx));
      const int v = static_cast<int>(std::lround(k.fy * q.y() / q.z() + k.cy));
      if (u < 0 || v < 0 || u >= y.frame.width || v >= y.frame.height) continue;
      const int i = v * y.frame.width + u;
      seen += y.frame.valid(i) && std::abs(y.frame.xyz[i].z() - q.z()) < 0.01 &&
              std::binary_search(o.points.begin(), o.points.end(), i);
    }
    return seen >= 5;
  }

  static void report(const char* what, const std::vector<YcbCase>& cases, double& named,
                     double& posed) {
    int n = 0, p = 0;
    for (const auto& c : cases) {
      n += c.named == c.truth;
      p += c.pose_ok;
      std::printf("  %-16s -> %-22s %6.3f m %6.1f deg %s\n", c.truth.c_str(), c.named.c_str(),
                  c.error.translation, c.error.rotation_deg, c.pose_ok ? "pose ok" : "");
    }
    named = double(n) / cases.size();
    posed = double(p) / cases.size();
    std::printf("%s: named %d/%zu, pose %d/%zu\n", what, n, cases.size(), p, cases.size());
  }

  static std::vector<std::string> classes_;
  static std::map<std::string, std::vector<Eigen::Vector3d>> models_;
  static std::map<std::string, std::vector<Eigen::Matrix4d>> symmetries_;
  // Frame k (1..10) of the YCB-Video sample.
  static YcbFrame frame(int k) {
    char stem[16];
    std::snprintf(stem, sizeof stem, "%06d", k);
    return read_ycb_frame(kData + "/ycbv/frames", stem, classes_);
  }

  static Database db_;
};
std::vector<std::string> Ycb::classes_;
std::map<std::string, std::vector<Eigen::Vector3d>> Ycb::models_;
std::map<std::string, std::vector<Eigen::Matrix4d>> Ycb::symmetries_;
Database Ycb::db_;

// Under ASan + UBSan (make test-sanitize) every third frame (1, 4, 7, 10): the same code paths and
// floors in a quarter of the time.
#ifdef PROXSEG_SANITIZE
constexpr int kFrameStep = 3;
#else
constexpr int kFrameStep = 1;
#endif

TEST_F(Ycb, GroundTruthMasks) {
  std::vector<YcbCase> cases;
  for (int k = 1; k <= 10; k += kFrameStep) {
    const YcbFrame y = frame(k);
    ASSERT_EQ(y.objects.size(), 3u);
    for (const auto& o : y.objects) {
      const Recognition r =
          recognize(describe_candidate(points_of(y.frame, o.points), db_), db_, {});
      cases.push_back(judge(y, o, r));
    }
  }
  double named = 0, posed = 0;
  report("ground-truth masks", cases, named, posed);
  EXPECT_GE(named, 0.9);
  EXPECT_GE(posed, 0.8);
}

TEST_F(Ycb, ProxsegCandidates) {
  std::vector<YcbCase> cases;
  std::vector<std::string> stray;
  int split = 0, merged = 0;
  for (int k = 1; k <= 10; k += kFrameStep) {
    const YcbFrame y = frame(k);
    const SegmentResult seg = segment(y.frame, SegmentParams{});
    const std::vector<SceneObject> objects = recognize_scene(y.frame, seg.selection, db_, {});
    for (const auto& s : objects) {
      split += s.origin == SceneObject::Origin::kSplit;
      merged += s.origin == SceneObject::Origin::kMerged;
    }
    // A named object that is no truth's best match (IoU >= 0.5) under that truth's name.
    std::vector<const SceneObject*> matched;
    for (const auto& o : y.objects) {
      const SceneObject* best = nullptr;
      double best_iou = 0;
      for (const SceneObject& s : objects) {
        std::vector<int> inter;
        std::set_intersection(s.points.begin(), s.points.end(), o.points.begin(), o.points.end(),
                              std::back_inserter(inter));
        const double iou =
            double(inter.size()) / (s.points.size() + o.points.size() - inter.size());
        if (iou > best_iou) best_iou = iou, best = &s;
      }
      if (!best || best_iou < 0.5) {
        cases.push_back({o.name, "(no candidate)", false, {}});
        continue;
      }
      if (best->recognition.name == o.name) matched.push_back(best);
      cases.push_back(judge(y, o, best->recognition));
    }
    for (const SceneObject& s : objects)
      if (s.recognition.name != "unknown" &&
          std::find(matched.begin(), matched.end(), &s) == matched.end())
        stray.push_back("frame " + std::to_string(k) + ": " + s.recognition.name + " " +
                        std::to_string(s.recognition.best.score) + " on " +
                        std::to_string(s.points.size()) + " points");
  }
  double named = 0, posed = 0;
  report("proxseg candidates", cases, named, posed);
  std::printf("objects split %d, merged %d; names on no object of the frame: %d\n", split, merged,
              static_cast<int>(stray.size()));
  for (const auto& s : stray) std::printf("  %s\n", s.c_str());
  EXPECT_GE(named, 0.9);
  EXPECT_GE(posed, 0.8);
  // Nothing but the frame's objects is named (the desk's edge was named 040_large_marker).
  EXPECT_EQ(stray.size(), 0u);
}

// Leave-one-out over the database: with the frame's object X removed from the 21 models, X
// (its ground-truth mask) must come out unknown and the frame's other two objects still be named.
TEST_F(Ycb, LeaveOneOutRejectsTheMissingObject) {
  int rejected = 0, cases = 0, named = 0, others = 0;
  for (const std::string& left_out :
       {std::string("009_gelatin_box"), std::string("025_mug"), std::string("061_foam_brick")}) {
    Database db = db_;
    db.views.erase(std::remove_if(db.views.begin(), db.views.end(),
                                  [&](const ModelView& v) { return v.object == left_out; }),
                   db.views.end());
    for (int k = 1; k <= 10; k += kFrameStep) {
      const YcbFrame y = frame(k);
      for (const auto& o : y.objects) {
        const Recognition r =
            recognize(describe_candidate(points_of(y.frame, o.points), db), db, {});
        if (o.name == left_out) {
          ++cases;
          rejected += r.name == "unknown";
          if (r.name != "unknown")
            std::printf("  frame %d: %s left out, named %s (%.3f)\n", k, o.name.c_str(),
                        r.name.c_str(), r.best.score);
        } else {
          ++others;
          named += r.name == o.name;
          if (r.name != o.name)
            std::printf("  frame %d: %s (without %s) named %s (%.3f)\n", k, o.name.c_str(),
                        left_out.c_str(), r.name.c_str(), r.best.score);
        }
      }
    }
  }
  std::printf("left out: %d/%d rejected; the others: %d/%d named\n", rejected, cases, named,
              others);
  EXPECT_EQ(rejected, cases);
  EXPECT_EQ(named, others);
}

// The judge's symmetries: a box's are found whatever its orientation in the model frame,
// including a square prism's, whose principal axes are arbitrary in the square.
std::vector<Eigen::Vector3d> box_surface(const Eigen::Vector3d& size, const Eigen::Matrix3d& turn) {
  std::vector<Eigen::Vector3d> out;
  const double step = 0.002;
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    for (double side : {-0.5, 0.5})
      for (double u = -size[b] / 2; u <= size[b] / 2; u += step)
        for (double v = -size[c] / 2; v <= size[c] / 2; v += step) {
          Eigen::Vector3d p;
          p[a] = side * size[a], p[b] = u, p[c] = v;
          out.push_back(turn * p + Eigen::Vector3d(0.01, -0.02, 0.03));
        }
  }
  return out;
}

TEST(Evaluation, BoxSymmetriesWhateverTheBoxOrientation) {
  const Eigen::Matrix3d turn = (Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitX()) *
                                Eigen::AngleAxisd(1.1, Eigen::Vector3d::UnitY()))
                                   .toRotationMatrix();
  // A brick with a square cross-section: the 8 turns of a square prism.
  const auto brick = box_surface({0.05, 0.075, 0.05}, turn);
  const auto s8 = box_symmetries(brick, 0.002);
  EXPECT_EQ(s8.size(), 8u);
  // Every one maps the box onto itself: its centre stays, its turn is one of the prism's.
  for (const auto& s : s8) {
    const Eigen::Vector3d centre(0.01, -0.02, 0.03);
    EXPECT_LT((s.topLeftCorner<3, 3>() * centre + s.topRightCorner<3, 1>() - centre).norm(), 1e-3);
  }
  // Three different sides: the identity and the three half turns.
  EXPECT_EQ(box_symmetries(box_surface({0.04, 0.06, 0.08}, turn), 0.002).size(), 4u);
  // A cube: the 24 turns.
  EXPECT_EQ(box_symmetries(box_surface({0.05, 0.05, 0.05}, turn), 0.002).size(), 24u);
}

}  // namespace
