// Readers and writers for frames: PCD (ascii, binary, binary_compressed), PLY, colour + depth PNG.
#pragma once
#include <proxseg/core/errors.hpp>
#include <proxseg/core/frame.hpp>
#include <proxseg/core/mesh.hpp>
#include <proxseg/core/rgbd.hpp>

#include <string>
#include <utility>
#include <vector>

namespace proxseg {

// PCD with fields x y z and optionally rgb or rgba (any order, extra fields ignored); without a
// colour field (an XYZ-only cloud) Frame::rgb is empty, while a colour field that is not 4 bytes
// is an InputError. An optional integer `label` field (or the field named label_field, e.g.
// "instance") is kept in Frame::label. WIDTH/HEIGHT come from the header.
Frame read_pcd(const std::string& path, const std::string& label_field = "label");
// PLY point cloud or mesh vertices (unorganized: height 1), with their colours if the file has
// them (red, green, blue vertex properties), else Frame::rgb empty. label_field, when not empty,
// names an integer vertex property kept in Frame::label (e.g. "instance" of write_ply's files).
Frame read_ply(const std::string& path, const std::string& label_field = "");
// Dispatches on the extension (.pcd, .ply).
Frame read_point_cloud(const std::string& path);
// What errors call standard input: "<stdin>".
inline constexpr char kStdinName[] = "<stdin>";
// A PCD or PLY cloud held in memory, told apart by its content: a PLY starts with the line "ply",
// a PCD with its header (comment lines, then VERSION, FIELDS, ...). Read as read_pcd and read_ply
// read files; InputError naming `name` for anything else.
Frame read_point_cloud_bytes(const std::string& bytes, const std::string& name);
// Standard input as read_point_cloud_bytes, errors naming "<stdin>" (the command line's "-").
// Its first line is checked before the rest is read, so that input that is neither format (an
// endless stream too) is refused at once, and of a PCD only as much as its header promises is
// read; a terminal is refused (nothing is piped in).
Frame read_point_cloud_stdin();
// A triangle mesh with vertex colours (PLY, e.g. the LINEMOD/BOP models) or a textured Wavefront
// OBJ (read_obj in obj_io.hpp, its texture sampled at vertices at most 2 mm apart); coordinates
// are multiplied by scale (0.001 for millimetre models) so that the mesh is in metres.
Mesh read_mesh(const std::string& path, double scale = 1.0);
// Plain "x y z" lines (YCB-Video models/points.xyz), metres; '#' comments and blank lines skipped.
std::vector<Eigen::Vector3d> read_xyz(const std::string& path);

// {"fx":..,"fy":..,"cx":..,"cy":..,"depth_scale":..}
Intrinsics read_intrinsics(const std::string& path);
// YCB-Video meta JSON: intrinsic_matrix (3x3) and factor_depth.
Intrinsics read_ycb_meta(const std::string& path);
// 8-bit colour PNG/JPG + 16-bit depth PNG of the same size -> organized frame; depth 0 = invalid.
Frame read_rgbd(const std::string& colour_path, const std::string& depth_path, const Intrinsics& k);

// An 8-bit one-channel label image (PNG) of exactly width x height pixels, row-major values
// (YCB-Video -label.png). InputError naming the file otherwise.
std::vector<std::uint8_t> read_label_image(const std::string& path, int width, int height);

// One extra per-point unsigned field written after x y z (rgb) (e.g. "label", "instance"; not
// "rgb" or "rgba").
struct PointField {
  std::string name;
  std::vector<std::uint32_t> values;  // one per point
};
// How write_pcd lays out the point data.
enum class PcdData {
  kBinary,            // DATA binary: the points one after another, uncompressed
  kBinaryCompressed,  // DATA binary_compressed: the fields one after another (all x, then all y,
                      // ...), LZF-compressed, as PCL writes it and PCL, Open3D and read_pcd read
                      // it; an mOSD scene with label and instance fields is 0.27 of its
                      // binary size
};

// A PCD (organized if the frame is) with fields x y z rgb and the extra fields, in memory; a
// frame without colours (Frame::rgb empty) is written as x y z and the extra fields.
std::string pcd_bytes(const Frame& frame, const std::vector<PointField>& fields,
                      PcdData data = PcdData::kBinaryCompressed);
// Writes pcd_bytes to path. Atomic: the file appears whole or not at all.
void write_pcd(const std::string& path, const Frame& frame, const std::vector<PointField>& fields,
               PcdData data = PcdData::kBinaryCompressed);

// Which points write_ply writes. PLY has no image grid and no notion of an invalid point: an
// organized frame's WIDTH/HEIGHT are lost either way.
enum class PlyPoints {
  kValid,  // the points with finite coordinates only, in the frame's row-major order (what
           // viewers and mesh tools expect)
  kAll,    // every point, NaN coordinates kept (Open3D's and PCL's PLY readers keep them): vertex
           // i is the frame's point i, so per-point arrays stay aligned with the file
};

// A binary little-endian PLY of one `vertex` element: x y z (float), red green blue (uchar) when
// the frame is coloured, then each extra field as a signed 32-bit `int` property (Open3D 0.16's
// tensor reader skips `uint` properties; a value above 2^31 - 1 is an InputError).
std::string ply_bytes(const Frame& frame, const std::vector<PointField>& fields,
                      PlyPoints points = PlyPoints::kValid);
// Writes ply_bytes to path. Atomic: the file appears whole or not at all.
void write_ply(const std::string& path, const Frame& frame, const std::vector<PointField>& fields,
               PlyPoints points = PlyPoints::kValid);

// A per-point label image read back (label_png of output.hpp writes them): width x height
// values, row-major.
struct LabelImage {
  int width = 0, height = 0;
  std::vector<std::uint32_t> values;
};
// An 8- or 16-bit one-channel PNG of any size, e.g. one written by label_png. InputError naming
// the file for any other image (colour, alpha, JPEG) or a corrupt one; FileError if it cannot be
// opened.
LabelImage read_label_png(const std::string& path);

// Writes bytes to path through a temporary file in the same directory and a rename.
void write_file_atomic(const std::string& path, const std::string& bytes);
// Writes a set of files (path, bytes) that belong together: every one to its temporary file
// first, then all renamed into place. A failure (InputError naming the file) removes the
// temporary files and whatever new file was already in place, so the set is never left half new;
// files of an earlier run that were not yet replaced stay as they were.
void write_files_atomic(const std::vector<std::pair<std::string, std::string>>& files);
// Checks that files can be made in the folder dir ("" = the current folder) by making one (a
// hidden probe, O_EXCL) and removing it: FileError naming the folder and the system's reason
// otherwise (no permission, a read-only mount). Called before any input is read, so that an
// output that cannot be written fails at once rather than after the work.
void check_writable_folder(const std::string& dir);

}  // namespace proxseg
