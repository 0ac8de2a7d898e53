#include <proxseg/recognition/model_view.hpp>
#include <proxseg/recognition/registration.hpp>

#include <algorithm>

namespace proxseg {

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
  if (!parts.empty()) {
    v.part_sketches.resize(sketch_of(parts[0]).size(), static_cast<Eigen::Index>(parts.size()));
    for (std::size_t k = 0; k < parts.size(); ++k) v.part_sketches.col(k) = sketch_of(parts[k]);
  }
  v.parts = std::make_shared<const Lazy<std::vector<Signature>>>(std::move(parts));
  v.described = std::make_shared<const Lazy<Cloud>>(std::move(cloud));
  return v;
}

}  // namespace proxseg
