// The virtual depth camera (render.hpp): depths, areas, labels and colours of rendered meshes
// against their analytic values, the z-buffer, and the synthetic tabletop.
#include <proxseg/core/errors.hpp>
#include <proxseg/core/render.hpp>

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <chrono>
#include <cmath>
#include <map>

using namespace proxseg;

namespace {

// A square of side `side` facing the camera (camera == world) at depth z, centred on the axis.
Mesh square(double side, double z, std::uint32_t label, Rgb colour, double cell = 0.05) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(0, 0, z);
  Mesh m = make_plane(
      pose, {side, side}, [&](const Eigen::Vector3d&) { return colour; }, cell);
  m.label = label;
  return m;
}

std::size_t count_label(const Frame& f, std::uint32_t label) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < f.size(); ++i) n += f.valid(i) && f.label[i] == label;
  return n;
}

}  // namespace

TEST(Render, SquareFacingCameraHasExactDepthAreaLabelAndColour) {
  RenderParams rp;
  const double side = 0.3;
  const Frame f = render({square(side, 1.0, 7, {200, 100, 50}, 0.01)}, rp);
  ASSERT_EQ(f.width, 640);
  ASSERT_EQ(f.height, 480);
  ASSERT_EQ(f.size(), 640u * 480u);
  ASSERT_EQ(f.label.size(), f.size());
  std::size_t covered = 0;
  for (std::size_t i = 0; i < f.size(); ++i) {
    if (!f.valid(i)) {
      EXPECT_EQ(f.label[i], 0u);
      EXPECT_EQ(f.rgb[i], (Rgb{0, 0, 0}));
      continue;
    }
    ++covered;
    EXPECT_NEAR(f.xyz[i].z(), 1.0, 1e-5);
    EXPECT_EQ(f.label[i], 7u);
    EXPECT_EQ(f.rgb[i], (Rgb{200, 100, 50}));
  }
  const double side_px = rp.camera.fx * side / 1.0;  // 157.5 px
  const double expected = side_px * side_px;
  EXPECT_NEAR(double(covered), expected, 0.03 * expected);
  // Square centred on the principal point: the centre pixel is covered, the corners are not.
  EXPECT_TRUE(f.valid(240 * 640 + 320));
  EXPECT_FALSE(f.valid(0));
  EXPECT_FALSE(f.valid(479 * 640 + 639));
}

TEST(Render, ZBufferKeepsNearest) {
  RenderParams rp;
  // Far square first so the near one has to win through the z-buffer, then the other order.
  for (bool near_first : {false, true}) {
    std::vector<Mesh> meshes = {square(0.6, 1.5, 1, {10, 10, 10}),
                                square(0.2, 0.8, 2, {250, 0, 0})};
    if (near_first) std::swap(meshes[0], meshes[1]);
    const Frame f = render(meshes, rp);
    const std::size_t c = 240 * 640 + 320;
    ASSERT_TRUE(f.valid(c));
    EXPECT_EQ(f.label[c], 2u);
    EXPECT_NEAR(f.xyz[c].z(), 0.8, 1e-5);
    EXPECT_EQ(f.rgb[c], (Rgb{250, 0, 0}));
    // Outside the near square (it spans +-65 px) but inside the far one (+-105 px).
    const std::size_t o = 240 * 640 + 320 + 90;
    ASSERT_TRUE(f.valid(o));
    EXPECT_EQ(f.label[o], 1u);
    EXPECT_NEAR(f.xyz[o].z(), 1.5, 1e-5);
    // Every pixel of label 2 is at the near depth; far pixels visible around it.
    for (std::size_t i = 0; i < f.size(); ++i)
      if (f.valid(i) && f.label[i] == 2) {
        EXPECT_NEAR(f.xyz[i].z(), 0.8, 1e-5);
      }
    const double near_px = std::pow(525 * 0.2 / 0.8, 2), far_px = std::pow(525 * 0.6 / 1.5, 2);
    EXPECT_NEAR(double(count_label(f, 2)), near_px, 0.03 * near_px);
    EXPECT_NEAR(double(count_label(f, 1)), far_px - near_px, 0.03 * far_px);
  }
}

TEST(Render, PointsLieOnPixelRaysAndCameraPoseIsApplied) {
  RenderParams rp;
  // World: a box 1 m in front of the camera; camera moved and turned a bit.
  Eigen::Isometry3d box_pose = Eigen::Isometry3d::Identity();
  box_pose.translation() = Eigen::Vector3d(0.05, -0.02, 1.0);
  box_pose.rotate(Eigen::AngleAxisd(0.5, Eigen::Vector3d(1, 1, 0).normalized()));
  Mesh box = make_box(box_pose, {0.2, 0.15, 0.1}, [](const Eigen::Vector3d& p) {
    return Rgb{std::uint8_t(p.x() > 0 ? 255 : 0), 0, 0};
  });
  box.label = 3;
  Eigen::Isometry3d cam = Eigen::Isometry3d::Identity();
  cam.translate(Eigen::Vector3d(0.03, 0.01, -0.1));
  cam.rotate(Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitY()));
  rp.camera_from_world = cam;
  const Frame f = render({box}, rp);
  const Eigen::Isometry3d box_in_cam = cam * box_pose;
  const Eigen::Isometry3d cam_to_box = box_in_cam.inverse();
  std::size_t n = 0;
  for (int v = 0; v < f.height; ++v)
    for (int u = 0; u < f.width; ++u) {
      const std::size_t i = std::size_t(v) * f.width + u;
      if (!f.valid(i)) continue;
      ++n;
      const Eigen::Vector3f& p = f.xyz[i];
      ASSERT_NEAR(rp.camera.fx * p.x() / p.z() + rp.camera.cx, u, 1e-3);
      ASSERT_NEAR(rp.camera.fy * p.y() / p.z() + rp.camera.cy, v, 1e-3);
      // The point is on the box surface: inside the box and close to one face.
      const Eigen::Vector3d q = cam_to_box * p.cast<double>();
      const Eigen::Vector3d h(0.1, 0.075, 0.05);
      const Eigen::Vector3d gap = h - q.cwiseAbs();
      ASSERT_GT(gap.minCoeff(), -1e-5);
      ASSERT_LT(gap.minCoeff(), 1e-5);
      ASSERT_EQ(f.label[i], 3u);
    }
  EXPECT_GT(n, 5000u);
}

TEST(Render, TiltedPlaneMatchesAnalyticRayPlaneIntersection) {
  RenderParams rp;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  const Eigen::Vector3d c(0.1, 0.05, 1.2);
  pose.translation() = c;
  pose.rotate(Eigen::AngleAxisd(0.9, Eigen::Vector3d::UnitX()) *
              Eigen::AngleAxisd(-0.4, Eigen::Vector3d::UnitY()));
  Mesh plane = make_plane(
      pose, {0.6, 0.5},
      [](const Eigen::Vector3d&) {
        return Rgb{1, 2, 3};
      },
      0.04);
  const Frame f = render({plane}, rp);
  const Eigen::Vector3d normal = pose.linear().col(2);
  std::size_t n = 0;
  double max_err = 0;
  for (int v = 0; v < f.height; ++v)
    for (int u = 0; u < f.width; ++u) {
      const std::size_t i = std::size_t(v) * f.width + u;
      if (!f.valid(i)) continue;
      ++n;
      const Eigen::Vector3d ray((u - rp.camera.cx) / rp.camera.fx,
                                (v - rp.camera.cy) / rp.camera.fy, 1.0);
      const double z = normal.dot(c) / normal.dot(ray);
      max_err = std::max(max_err, std::abs(f.xyz[i].z() - z));
    }
  EXPECT_GT(n, 20000u);
  EXPECT_LT(max_err, 1e-5);
  // The plane's depth really varies over the image (it is tilted).
  float zmin = 10, zmax = 0;
  for (std::size_t i = 0; i < f.size(); ++i)
    if (f.valid(i)) zmin = std::min(zmin, f.xyz[i].z()), zmax = std::max(zmax, f.xyz[i].z());
  EXPECT_GT(zmax - zmin, 0.2);
}

TEST(Render, PerspectiveCorrectColourInterpolation) {
  // One tilted quad whose colour is a linear ramp in its local x: the rendered colour at each
  // pixel must be the ramp evaluated at the 3-D point (perspective-correct, not screen-linear).
  RenderParams rp;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(0, 0, 1.0);
  pose.rotate(Eigen::AngleAxisd(1.1, Eigen::Vector3d::UnitY()));
  Mesh plane = make_plane(
      pose, {1.0, 0.4},
      [](const Eigen::Vector3d& p) {
        return Rgb{std::uint8_t(std::lround((p.x() + 0.5) * 250)), 0, 0};
      },
      10.0);  // a single quad
  ASSERT_EQ(plane.triangles.size(), 2u);
  const Frame f = render({plane}, rp);
  const Eigen::Isometry3d inv = pose.inverse();
  std::size_t n = 0;
  for (std::size_t i = 0; i < f.size(); ++i) {
    if (!f.valid(i)) continue;
    ++n;
    const double x = (inv * f.xyz[i].cast<double>()).x();
    ASSERT_NEAR(f.rgb[i][0], (x + 0.5) * 250, 1.01);
  }
  EXPECT_GT(n, 10000u);
}

TEST(Render, NoiseIsDeterministicAndHasTheRequestedStd) {
  RenderParams rp;
  rp.depth_noise = 0.003;
  const std::vector<Mesh> meshes = {square(0.8, 1.0, 1, {9, 9, 9})};
  rp.seed = 5;
  const Frame a = render(meshes, rp), b = render(meshes, rp);
  rp.seed = 6;
  const Frame c = render(meshes, rp);
  ASSERT_EQ(a.size(), b.size());
  std::size_t same_ab = 0, same_ac = 0, valid = 0;
  double sum = 0, sum2 = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a.valid(i), b.valid(i));
    if (!a.valid(i)) continue;
    ++valid;
    same_ab += a.xyz[i] == b.xyz[i];
    same_ac += a.xyz[i] == c.xyz[i];
    const double z = a.xyz[i].z();
    sum += z;
    sum2 += z * z;
    // Noise moves the point along its ray; depth quantised to 1 mm.
    EXPECT_NEAR(z * 1000, std::round(z * 1000), 1e-3);
  }
  ASSERT_GT(valid, 100000u);
  EXPECT_EQ(same_ab, valid);
  EXPECT_LT(same_ac, valid / 2);
  const double mean = sum / valid, sd = std::sqrt(sum2 / valid - mean * mean);
  EXPECT_NEAR(mean, 1.0, 2e-4);
  EXPECT_NEAR(sd, 0.003, 0.3 * 0.003);
  // Noise grows with z^2: at 2 m the std is ~4x that at 1 m.
  const Frame far = render({square(1.6, 2.0, 1, {9, 9, 9})}, rp);
  double s2 = 0, s22 = 0;
  std::size_t nf = 0;
  for (std::size_t i = 0; i < far.size(); ++i)
    if (far.valid(i)) ++nf, s2 += far.xyz[i].z(), s22 += double(far.xyz[i].z()) * far.xyz[i].z();
  const double m2 = s2 / nf, sd2 = std::sqrt(s22 / nf - m2 * m2);
  EXPECT_NEAR(sd2, 0.012, 0.3 * 0.012);
}

TEST(Render, IsFastEnough) {
  // ~50k triangles covering much of a 640x480 frame.
  RenderParams rp;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(0, 0, 1.0);
  pose.rotate(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitX()));
  std::vector<Mesh> meshes = {make_plane(
      pose, {1.0, 0.8},
      [](const Eigen::Vector3d&) {
        return Rgb{100, 100, 100};
      },
      0.0063)};
  const std::size_t tris = meshes[0].triangles.size();
  EXPECT_GT(tris, 40000u);
  EXPECT_LT(tris, 60000u);
  render(meshes, rp);  // warm-up
  const auto t0 = std::chrono::steady_clock::now();
  const Frame f = render(meshes, rp);
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_GT(f.valid_count(), 100000u);
  EXPECT_LT(secs, 0.2);
}

TEST(Render, BuildersHaveTheRequestedShape) {
  auto white = [](const Eigen::Vector3d&) { return Rgb{255, 255, 255}; };
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(1, 2, 3);
  const Mesh box = make_box(pose, {0.1, 0.2, 0.3}, white, 0.01);
  // 6 faces of 10x20, 10x30, 20x30 cells (each twice), 2 triangles per cell.
  EXPECT_EQ(box.triangles.size(), 2u * 2 * (200 + 300 + 600));
  EXPECT_EQ(box.colours.size(), box.vertices.size());
  Eigen::Vector3f lo = box.vertices[0], hi = box.vertices[0];
  for (const auto& v : box.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  EXPECT_TRUE(lo.isApprox(Eigen::Vector3f(0.95f, 1.9f, 2.85f), 1e-6));
  EXPECT_TRUE(hi.isApprox(Eigen::Vector3f(1.05f, 2.1f, 3.15f), 1e-6));
  const Mesh cyl = make_cylinder(pose, 0.05, 0.2, white, 0.005);
  for (const auto& v : cyl.vertices) {
    const Eigen::Vector3f l = v - pose.translation().cast<float>();
    EXPECT_LE(std::hypot(l.x(), l.y()), 0.05f + 1e-5f);
    EXPECT_LE(std::abs(l.z()), 0.1f + 1e-5f);
  }
  // The side alone has ceil(2 pi 5 cm / 5 mm) = 63 x 40 cells.
  EXPECT_GT(cyl.triangles.size(), 2u * 63 * 40);
  // Colour functions get local coordinates.
  const Mesh striped = make_plane(
      pose, {0.2, 0.1},
      [](const Eigen::Vector3d& p) {
        return Rgb{std::uint8_t(p.x() > 0 ? 200 : 10), 0, 0};
      },
      0.01);
  for (std::size_t i = 0; i < striped.vertices.size(); ++i)
    EXPECT_EQ(striped.colours[i][0], striped.vertices[i].x() > 1.0f + 1e-6f ? 200 : 10);
}

TEST(Render, RejectsBadMeshes) {
  Mesh m = square(0.1, 1, 1, {1, 1, 1});
  m.colours.pop_back();
  EXPECT_THROW(render({m}, RenderParams{}), proxseg::InputError);
  Mesh t = square(0.1, 1, 1, {1, 1, 1});
  t.triangles.push_back({0, 1, int(t.vertices.size())});
  EXPECT_THROW(render({t}, RenderParams{}), proxseg::InputError);
}

TEST(Render, TrianglesBehindTheCameraAreSkipped) {
  RenderParams rp;
  const Frame f = render({square(0.5, -1.0, 1, {1, 1, 1}), square(0.5, 0.0, 2, {1, 1, 1})}, rp);
  EXPECT_EQ(f.valid_count(), 0u);
}

TEST(SynthScene, LooksLikeATabletopScene) {
  SynthParams sp;
  const Frame f = synth_scene(sp);
  ASSERT_EQ(f.width, 640);
  ASSERT_EQ(f.height, 480);
  ASSERT_EQ(f.label.size(), f.size());
  std::map<std::uint32_t, std::size_t> counts;
  for (std::size_t i = 0; i < f.size(); ++i)
    if (f.valid(i)) {
      ++counts[f.label[i]];
    } else {
      EXPECT_EQ(f.label[i], 0u);
    }
  for (std::uint32_t l = 1; l <= 6; ++l) {
    EXPECT_GE(counts[l], 1500u) << "label " << l;
    if (l > 1) {
      EXPECT_GT(counts[1], counts[l]);
    }
  }
  EXPECT_EQ(counts.size(), 6u);  // nothing but the table and the five objects
  EXPECT_GT(f.valid_count(), f.size() / 2);
  EXPECT_LT(f.valid_count(), f.size());  // background behind the table is empty

  // Fit the table plane to the label-1 points; objects lie above it (the camera side).
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < f.size(); ++i)
    if (f.valid(i) && f.label[i] == 1) mean += f.xyz[i].cast<double>();
  mean /= double(counts[1]);
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < f.size(); ++i)
    if (f.valid(i) && f.label[i] == 1) {
      const Eigen::Vector3d d = f.xyz[i].cast<double>() - mean;
      cov += d * d.transpose();
    }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
  Eigen::Vector3d n = es.eigenvectors().col(0);
  if (n.dot(-mean) < 0) n = -n;  // towards the camera
  // The camera looks down at the table at 35-45 degrees.
  const double tilt = std::asin(std::abs(n.z())) * 180 / 3.14159265358979;
  EXPECT_GT(tilt, 35);
  EXPECT_LT(tilt, 45);
  EXPECT_LT(std::sqrt(es.eigenvalues()(0) / counts[1]), 0.004);  // flat up to noise
  std::map<std::uint32_t, double> max_height;
  for (std::size_t i = 0; i < f.size(); ++i) {
    if (!f.valid(i) || f.label[i] < 2) continue;
    const double h = n.dot(f.xyz[i].cast<double>() - mean);
    EXPECT_GT(h, -0.006);
    max_height[f.label[i]] = std::max(max_height[f.label[i]], h);
  }
  for (std::uint32_t l = 2; l <= 6; ++l) {
    EXPECT_GT(max_height[l], 0.05) << "label " << l;
    EXPECT_LT(max_height[l], 0.21) << "label " << l;
  }
  // The table is 0.8-1.4 m from the camera at the image centre.
  const std::size_t c = 240 * 640 + 320;
  ASSERT_TRUE(f.valid(c));
  EXPECT_GT(f.xyz[c].norm(), 0.8);
  EXPECT_LT(f.xyz[c].norm(), 1.4);
}

TEST(SynthScene, IsDeterministicForASeed) {
  SynthParams sp;
  sp.seed = 3;
  const Frame a = synth_scene(sp), b = synth_scene(sp);
  sp.seed = 4;
  const Frame c = synth_scene(sp);
  ASSERT_EQ(a.size(), b.size());
  std::size_t diff_ab = 0, diff_ac = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    diff_ab += a.valid(i) != b.valid(i) || (a.valid(i) && a.xyz[i] != b.xyz[i]) ||
               a.rgb[i] != b.rgb[i] || a.label[i] != b.label[i];
    diff_ac += a.valid(i) && c.valid(i) && a.xyz[i] != c.xyz[i];
  }
  EXPECT_EQ(diff_ab, 0u);
  EXPECT_GT(diff_ac, a.valid_count() / 2);
  // The layout is fixed: same labels everywhere (noise does not move pixels between labels).
  EXPECT_EQ(a.label, c.label);
}

TEST(SynthScene, NoiselessSceneHasDistinctTextures) {
  SynthParams sp;
  sp.depth_noise = 0;
  const Frame f = synth_scene(sp);
  // The striped and checkerboard boxes show two clearly different colours each.
  for (std::uint32_t l : {3u, 4u}) {
    int lo = 765, hi = 0;
    for (std::size_t i = 0; i < f.size(); ++i)
      if (f.valid(i) && f.label[i] == l) {
        const int s = f.rgb[i][0] + f.rgb[i][1] + f.rgb[i][2];
        lo = std::min(lo, s), hi = std::max(hi, s);
      }
    EXPECT_GT(hi - lo, 100) << "label " << l;
  }
}
