// A database view made from a described cloud (model_view.hpp) [paper 3.4].
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
  v.part_sketches = sketch_set(parts);
  v.parts = std::make_shared<const Lazy<std::vector<Signature>>>(std::move(parts));
  v.described = std::make_shared<const Lazy<Cloud>>(std::move(cloud));
  return v;
}

}  // namespace proxseg
