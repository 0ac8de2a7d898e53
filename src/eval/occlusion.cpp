// The paper's occlusion generator [4]: a ball of random radius around a random point of the view
// removed (occlusion.hpp).
#include <proxseg/core/errors.hpp>
#include <proxseg/eval/occlusion.hpp>

#include <proxseg/core/frame.hpp>

#include <algorithm>
#include <cmath>

#include "util/splitmix.hpp"

namespace proxseg {

Occlusion occlude(const std::vector<Eigen::Vector3d>& view, double max_radius, std::uint64_t seed) {
  if (view.empty()) throw InputError("occlude: the view has no points");
  if (!(max_radius >= 0) || !std::isfinite(max_radius))
    throw InputError("occlude: expected a finite max_radius >= 0");
  SplitMix rng{seed};
  const auto uniform = [&rng]() { return rng.uniform(); };
  Occlusion o;
  o.centre = view[std::min(view.size() - 1, static_cast<std::size_t>(uniform() * view.size()))];
  o.radius = uniform() * max_radius;
  for (const auto& p : view)
    if ((p - o.centre).norm() > o.radius) o.points.push_back(p);
  o.removed_share = 1.0 - double(o.points.size()) / view.size();
  return o;
}

}  // namespace proxseg
