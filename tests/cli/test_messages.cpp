// Messages that named the wrong cause (issue 54, point 9): intrinsics that put a pixel with depth
// beyond a float said "has no valid depth" (or gave a 1-point result), a voxel side too small for
// the grid said "no valid points", a subnormal said "expected a number", a PCD COUNT too large said
// "expected a positive integer". Each must name the field at fault and what was expected.
#include <string>

#include "support/cli_util.hpp"

namespace {
using namespace cli_test;

fs::path dir() {
  const std::string name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
  const fs::path d = fs::path(PROXSEG_TEST_TMP) / "messages" / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

CliRun run(const std::string& args) {
  return run_in(fs::path(PROXSEG_TEST_TMP) / "messages", args);
}

bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// `segment` of the first YCB-Video frame with the camera of `intrinsics` (YCB's, then the
// fields given, which replace those before them).
CliRun segment_ycb_with(const std::string& fields) {
  const fs::path d = dir();
  const std::string frames = kData + "/ycbv/frames/";
  std::ofstream(d / "camera.json") << R"({"fx":1066.778,"fy":1067.487,"cx":312.9869,"cy":241.3109,)"
                                   << R"("depth_scale":10000,)" << fields << "}";
  return run("segment --colour " + frames + "000001-color.png --depth " + frames +
             "000001-depth.png --intrinsics " + (d / "camera.json").string() + " -o " +
             (d / "out").string() + " --outputs json");
}

TEST(Messages, IntrinsicsBeyondAFloatNameTheIntrinsicsNotTheDepth) {
  for (const std::string fields :
       {R"("cx":1e308)", R"("depth_scale":1e-300)", R"("fx":1e-300)",
        // cx on a pixel column: that column alone stayed finite, a silent 1-point result.
        R"("fx":1e-300,"cx":312)"}) {
    const CliRun r = segment_ycb_with(fields);
    EXPECT_EQ(r.code, 1) << fields << ": " << r.err;
    EXPECT_TRUE(has(r.err, "intrinsics") && has(r.err, "beyond the range of a float"))
        << fields << ": " << r.err;
    EXPECT_FALSE(has(r.err, "no valid depth")) << r.err;
    EXPECT_FALSE(fs::exists(dir() / "out.json"));
  }
  EXPECT_EQ(segment_ycb_with(R"("fx":1066.778)").code, 0);  // the camera itself is fine
}

TEST(Messages, VoxelSideTooSmallForTheGridNamesVoxelSize) {
  const fs::path out = dir() / "out";
  for (const std::string size : {"4.9e-324", "1e-30"}) {
    const CliRun r = run("segment " + learn0() + " --voxel-size " + size + " -o " + out.string() +
                         " --outputs json");
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_TRUE(has(r.err, "voxel_size") && has(r.err, "expected at least")) << r.err;
    EXPECT_FALSE(has(r.err, "no valid points")) << r.err;
    EXPECT_FALSE(has(r.err, "expected a number")) << r.err;
  }
}

TEST(Messages, NumbersBeyondADoubleSaySo) {
  const fs::path out = dir() / "out";
  const CliRun tiny = run("segment " + learn0() + " --voxel-size 1e-400 -o " + out.string());
  EXPECT_EQ(tiny.code, 2) << tiny.err;
  EXPECT_TRUE(has(tiny.err, "rounds to 0")) << tiny.err;
  const CliRun huge = run("segment " + learn0() + " --voxel-size 1e400 -o " + out.string());
  EXPECT_EQ(huge.code, 2) << huge.err;
  EXPECT_TRUE(has(huge.err, "too large for a double")) << huge.err;
}

TEST(Messages, PcdCountTooLargeSaysTheLimit) {
  const fs::path d = dir();
  for (const std::string count : {"1073741824", "99999999999999999999"}) {
    std::ofstream(d / "c.pcd") << "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 "
                               << count << "\nWIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1 2 3\n";
    const CliRun r = run("segment " + (d / "c.pcd").string() + " -o " + (d / "out").string());
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_TRUE(has(r.err, "COUNT '" + count + "' (expected at most 1048576")) << r.err;
  }
}

}  // namespace
