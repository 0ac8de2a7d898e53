// The frames of a dataset for batch work: point cloud files and RGB-D pairs, found in folders
// (recursively), list files or globs, each named by its path relative to the dataset's root.
#pragma once
#include <proxseg/core/errors.hpp>
#include <proxseg/core/frame.hpp>
#include <proxseg/core/rgbd.hpp>

#include <string>
#include <vector>

namespace proxseg {

// How the files of an RGB-D pair are named. Each pattern is a path relative to one folder in
// which {id} stands for the frame's name: "{id}-color.png" beside "{id}-depth.png" (YCB-Video),
// or "rgb/{id}.png" and "depth/{id}.png" (one folder per stream, as in BOP).
struct RgbdNaming {
  // A colour image (PNG/JPG) that matches this pattern makes a frame with the depth image below.
  std::string colour = "{id}-color.png";
  // Its 16-bit depth PNG; missing: that frame fails when it is read.
  std::string depth = "{id}-depth.png";
  // Its camera: a JSON file per frame, used when it exists, YCB-Video meta (intrinsic_matrix,
  // factor_depth) or intrinsics (fx, fy, cx, cy, depth_scale).
  std::string meta = "{id}-meta.json";
  // One camera JSON (either kind) for every pair without a meta file; empty: such a pair fails
  // when it is read.
  std::string intrinsics;
};

// One frame of a batch: a point cloud file, or the files of an RGB-D pair.
struct FrameSource {
  // The frame's name, unique in the batch: its path relative to the root without the extension
  // (or without the colour pattern's part around {id}), '/'-separated: "learn0", "video1/000001".
  // Outputs are named after it.
  std::string id;
  std::string cloud;          // .pcd or .ply; empty for an RGB-D pair
  std::string colour, depth;  // an RGB-D pair
  std::string camera;         // the pair's camera JSON (read_camera); empty: reading fails
  // An entry of a folder that cannot be read as a frame: a symbolic link loop, a dangling link,
  // a folder that cannot be listed, or a special file (FIFO, device) named like a frame. It
  // stays in the batch so that its row reports it: `problem` says what it is, `unreadable` is
  // its path, and read_frame throws FileError with both. Empty for a readable frame.
  std::string unreadable, problem;
  std::vector<std::string> files() const;  // the input files, in the order above
};

// The frames of the given sources, in natural order of their ids (numbers within names compare
// as numbers: scene2 before scene10). A source is:
// - a folder: every .pcd and .ply file under it, and every RGB-D pair whose colour image matches
//   naming.color, recursively (hidden entries and symbolic links to folders are not followed);
//   an entry that cannot be read (see FrameSource::unreadable) is a frame that fails, not an
//   error of the whole batch;
// - a glob, when it holds *, ? or [...]: the files whose paths match it ('*' and '?' do not cross
//   '/', "**/" matches any number of folders), kept when they are clouds or colour images;
// - a .pcd or .ply file, or a colour image named by naming.color: that frame;
// - a list file (any other file): one input per line, a cloud or a colour
//   image (named by naming.color), or "COLOR DEPTH [META_OR_INTRINSICS.json]"; relative paths
//   are relative to the list's folder; blank lines and lines starting with '#' are skipped.
// Ids are relative to the root: the folder itself when the only source is a folder, else the
// deepest folder that holds every frame. InputError (naming the source, or the list file and
// line, and what the entry is when it is no file: a folder, a FIFO, a link loop) for a source
// that does not exist, a list line that is not a frame, no frame at all, or
// two frames with one id (e.g. a.pcd and a.ply: their outputs would overwrite each other).
std::vector<FrameSource> discover_frames(const std::vector<std::string>& sources,
                                         const RgbdNaming& naming = {});

// The order of frame ids: runs of digits compare as numbers ("scene2" < "scene10"), the rest
// byte by byte.
bool natural_less(const std::string& a, const std::string& b);

// Shard index of count (1-based, "--shard 2/3"): the frames whose id hashes to it (FNV-1a of the
// id, modulo count), in the same order. Deterministic and stable: a frame keeps its shard
// whatever other frames the dataset gains or loses. InputError unless 1 <= index <= count.
std::vector<FrameSource> shard_frames(const std::vector<FrameSource>& frames, int index, int count);

// A camera JSON of either kind: YCB-Video meta when it has "intrinsic_matrix" (read_ycb_meta),
// else intrinsics (read_intrinsics).
Intrinsics read_camera(const std::string& path);
// Reads the frame: read_point_cloud for a cloud, read_rgbd with read_camera for a pair
// (InputError naming the colour image when it has no camera file).
Frame read_frame(const FrameSource& source);

}  // namespace proxseg
