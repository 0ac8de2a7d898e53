#include <proxseg/recognition/model_view.hpp>
#include <proxseg/recognition/registration.hpp>

#include <algorithm>
#include <limits>

namespace proxseg {

double parts_reach(const Signature& whole, const std::vector<Signature>& parts) {
  double reach = 0;
  for (const Signature& p : parts) {
    // signature_distance() leaves the spread term out for a zero spread, and is then no metric:
    // no bound.
    if (!(p.spread > 0) || !(whole.spread > 0)) return std::numeric_limits<double>::infinity();
    reach = std::max(reach, signature_distance(whole, p));
  }
  return reach;
}

ModelView make_model_view(std::string object, Cloud cloud, std::string source, std::string name) {
  add_part_signatures(cloud);
  ModelView v;
  v.object = std::move(object);
  v.name = name.empty() ? v.object : std::move(name);
  v.source = std::move(source);
  v.points = cloud.size();
  v.coloured = !cloud.colours.empty();
  v.viewpoint = cloud.viewpoint;
  std::vector<Signature> parts = std::move(cloud.signature.parts);
  cloud.signature.parts.clear();
  v.signature = cloud.signature;
  v.parts_reach = parts_reach(v.signature, parts);
  v.parts = std::make_shared<const Lazy<std::vector<Signature>>>(std::move(parts));
  v.described = std::make_shared<const Lazy<Cloud>>(std::move(cloud));
  return v;
}

}  // namespace proxseg
