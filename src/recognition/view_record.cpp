// The bytes of a stored view and their checksums (view_record.hpp).
#include "view_record.hpp"

#include <proxseg/core/errors.hpp>
#include <proxseg/recognition/registration.hpp>

#include <cmath>
#include <cstdint>
#include <cstring>

#include "util/checksum.hpp"

namespace proxseg::detail {
namespace {

template <class T>
void put(std::string& out, const T& v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof v);
}

void put_floats(std::string& out, const Eigen::VectorXf& v) {
  out.append(reinterpret_cast<const char*>(v.data()), sizeof(float) * v.size());
}

// Appends the checksum of everything before it.
std::string sealed(std::string bytes) {
  put(bytes, checksum64(bytes.data(), bytes.size()));
  return bytes;
}

// Reads a record front to back; every read is bounded by its length.
class Reader {
 public:
  Reader(const std::string& where, const std::string& bytes, const char* record)
      : where_(where), record_(record), bytes_(bytes) {
    if (bytes.size() < 8) damaged("shorter than its checksum");
    std::uint64_t sum;
    std::memcpy(&sum, bytes.data() + bytes.size() - 8, 8);
    if (sum != checksum64(bytes.data(), bytes.size() - 8))
      damaged("its checksum does not match its bytes");
    end_ = bytes.size() - 8;
  }
  template <class T>
  T get() {
    T v;
    take(&v, sizeof v);
    return v;
  }
  Eigen::VectorXf floats(std::size_t n) {
    Eigen::VectorXf v(static_cast<Eigen::Index>(n));
    take(v.data(), n * sizeof(float));
    if (!v.allFinite()) damaged("holds a non-finite value");
    return v;
  }
  void take(void* out, std::size_t n) {
    const char* p = span(n);
    if (n > 0) std::memcpy(out, p, n);  // an empty vector's data() may be null
  }
  const char* span(std::size_t n) {
    if (n > end_ - at_) damaged("is shorter than its sizes say");
    const char* p = bytes_.data() + at_;
    at_ += n;
    return p;
  }
  void finish() {
    if (at_ != end_) damaged("is longer than its sizes say");
  }
  [[noreturn]] void damaged(const std::string& what) const {
    throw InputError(where_ + ": " + record_ + " record damaged: " + what);
  }

 private:
  std::string where_;
  const char* record_;
  const std::string& bytes_;
  std::size_t at_ = 0, end_ = 0;
};

void put_signature(std::string& out, const Signature& s) {
  put_floats(out, s.shape);
  put_floats(out, s.colour);
  put(out, s.spread);
}

Signature get_signature(Reader& in, std::size_t shape, std::size_t colour) {
  Signature s;
  s.shape = in.floats(shape);
  s.colour = in.floats(colour);
  s.spread = in.get<double>();
  if (!(s.spread >= 0) || !std::isfinite(s.spread)) in.damaged("holds a negative spread");
  return s;
}

constexpr std::uint32_t kMaxBins = 1 << 16;  // far above 33 x radii + 64 colour cells

}  // namespace

std::string encode_summary(const ViewSummary& s) {
  std::string out;
  for (int k = 0; k < 3; ++k) put(out, s.viewpoint[k]);
  put(out, static_cast<std::uint32_t>(s.signature.shape.size()));
  put(out, static_cast<std::uint32_t>(s.signature.colour.size()));
  put_signature(out, s.signature);
  const SketchSet& k = s.part_sketches;
  put(out, static_cast<std::uint32_t>(k.bins.rows()));
  put(out, static_cast<std::uint32_t>(k.size()));
  out.append(reinterpret_cast<const char*>(k.bins.data()), sizeof(std::uint16_t) * k.bins.size());
  put_floats(out, k.spreads);
  return sealed(std::move(out));
}

ViewSummary decode_summary(const std::string& where, const std::string& bytes) {
  Reader in(where, bytes, "summary");
  ViewSummary s;
  for (int k = 0; k < 3; ++k) s.viewpoint[k] = in.get<double>();
  const auto shape = in.get<std::uint32_t>(), colour = in.get<std::uint32_t>();
  if (shape > kMaxBins || colour > kMaxBins) in.damaged("implausible signature sizes");
  s.signature = get_signature(in, shape, colour);
  const auto rows = in.get<std::uint32_t>(), cols = in.get<std::uint32_t>();
  if (rows > kMaxBins || cols > 1024) in.damaged("implausible sketch sizes");
  SketchSet& k = s.part_sketches;
  k.bins.resize(rows, cols);
  in.take(k.bins.data(), sizeof(std::uint16_t) * rows * cols);
  k.spreads = in.floats(cols);
  in.finish();
  return s;
}

std::string encode_parts(const std::vector<Signature>& parts) {
  std::string out;
  put(out, static_cast<std::uint32_t>(parts.size()));
  put(out, static_cast<std::uint32_t>(parts.empty() ? 0 : parts[0].shape.size()));
  put(out, static_cast<std::uint32_t>(parts.empty() ? 0 : parts[0].colour.size()));
  for (const Signature& s : parts) put_signature(out, s);
  return sealed(std::move(out));
}

std::vector<Signature> decode_parts(const std::string& where, const std::string& bytes) {
  Reader in(where, bytes, "parts");
  const auto n = in.get<std::uint32_t>(), shape = in.get<std::uint32_t>(),
             colour = in.get<std::uint32_t>();
  if (n > 1024 || shape > kMaxBins || colour > kMaxBins) in.damaged("implausible sizes");
  std::vector<Signature> parts;
  parts.reserve(n);
  for (std::uint32_t i = 0; i < n; ++i) parts.push_back(get_signature(in, shape, colour));
  in.finish();
  return parts;
}

std::string encode_body(const Cloud& c) {
  std::string out;
  put(out, static_cast<std::uint32_t>(c.size()));
  put(out, static_cast<std::uint32_t>(c.features.rows()));
  put(out, static_cast<std::uint32_t>(c.colours.empty() ? 0 : 1));
  out.reserve(out.size() + c.size() * (6 * 4 + 3 + c.features.rows() * 4) + 8);
  for (const auto& p : c.points)
    for (int k = 0; k < 3; ++k) put(out, static_cast<float>(p[k]));
  for (const auto& n : c.normals)
    for (int k = 0; k < 3; ++k) put(out, static_cast<float>(n[k]));
  for (Eigen::Index j = 0; j < c.features.cols(); ++j)
    for (Eigen::Index i = 0; i < c.features.rows(); ++i)
      put(out, static_cast<float>(c.features(i, j)));
  for (const Rgb& rgb : c.colours) out.append(reinterpret_cast<const char*>(rgb.data()), 3);
  return sealed(std::move(out));
}

Cloud decode_body(const std::string& where, const std::string& bytes, std::size_t points,
                  std::size_t dims, const Eigen::Vector3d& viewpoint) {
  Reader in(where, bytes, "body");
  const auto n = in.get<std::uint32_t>(), d = in.get<std::uint32_t>(),
             coloured = in.get<std::uint32_t>();
  if (n != points || d != dims || coloured > 1)
    in.damaged("holds " + std::to_string(n) + " points of " + std::to_string(d) +
               " feature dimensions (expected " + std::to_string(points) + " of " +
               std::to_string(dims) + ")");
  const auto vectors = [&](const char* what) {
    const float* f = reinterpret_cast<const float*>(in.span(std::size_t(n) * 3 * sizeof(float)));
    std::vector<Eigen::Vector3d> out(n);
    for (std::uint32_t i = 0; i < n; ++i) {
      float xyz[3];
      std::memcpy(xyz, f + 3 * i, sizeof xyz);
      out[i] = Eigen::Vector3d(xyz[0], xyz[1], xyz[2]);
      if (!out[i].allFinite()) in.damaged(std::string("holds a non-finite ") + what);
    }
    return out;
  };
  std::vector<Eigen::Vector3d> xyz = vectors("point"), normals = vectors("normal");
  const Eigen::VectorXf f = in.floats(std::size_t(n) * d);
  Eigen::MatrixXd features = Eigen::Map<const Eigen::MatrixXf>(f.data(), d, n).cast<double>();
  std::vector<Rgb> colours;
  if (coloured) {
    const char* c = in.span(std::size_t(n) * 3);
    colours.resize(n);
    for (std::uint32_t i = 0; i < n; ++i) std::memcpy(colours[i].data(), c + 3 * i, 3);
  }
  in.finish();
  return restore(std::move(xyz), std::move(normals), std::move(features), viewpoint,
                 std::move(colours));
}

}  // namespace proxseg::detail
