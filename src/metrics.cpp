// Segmentation metrics [paper 4].
#include <proxseg/metrics.hpp>

#include <cmath>
#include <map>
#include <stdexcept>

namespace proxseg {

VMeasure v_measure(const std::vector<std::uint32_t>& truth,
                   const std::vector<std::uint32_t>& predicted) {
  if (truth.size() != predicted.size()) throw std::invalid_argument("v_measure: sizes differ");
  std::map<std::pair<std::uint32_t, std::uint32_t>, double> joint;
  std::map<std::uint32_t, double> classes, clusters;
  double n = 0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    if (!truth[i]) continue;
    joint[{truth[i], predicted[i]}] += 1;
    classes[truth[i]] += 1;
    clusters[predicted[i]] += 1;
    n += 1;
  }
  VMeasure m;
  if (n == 0) return m;
  auto entropy = [n](const std::map<std::uint32_t, double>& counts) {
    double h = 0;
    for (const auto& [key, c] : counts) h -= c / n * std::log(c / n);
    return h;
  };
  const double h_c = entropy(classes), h_k = entropy(clusters);
  double h_c_given_k = 0, h_k_given_c = 0;
  for (const auto& [key, c] : joint) {
    h_c_given_k -= c / n * std::log(c / clusters[key.second]);
    h_k_given_c -= c / n * std::log(c / classes[key.first]);
  }
  // Conventions of the paper that defines the measure: a single class is perfectly homogeneous,
  // a single cluster perfectly complete.
  m.homogeneity = h_c > 0 ? 1.0 - h_c_given_k / h_c : 1.0;
  m.completeness = h_k > 0 ? 1.0 - h_k_given_c / h_k : 1.0;
  const double s = m.homogeneity + m.completeness;
  m.v = s > 0 ? 2 * m.homogeneity * m.completeness / s : 0.0;
  return m;
}

std::vector<std::uint32_t> mosd_objects(const std::vector<std::uint32_t>& labels) {
  std::vector<std::uint32_t> out(labels.size());
  for (std::size_t i = 0; i < labels.size(); ++i)
    out[i] = labels[i] == 0 ? 0 : labels[i] < 10 ? 1 : labels[i] / 10;
  return out;
}

}  // namespace proxseg
