// Colour conversions (colour.hpp): RGB to HSV for the colour feature [paper 3.1].
#include <proxseg/core/colour.hpp>

#include <algorithm>
#include <array>
#include <cmath>

namespace proxseg {

Eigen::Vector3d rgb_to_hsv(const Rgb& c) {
  static const std::array<double, 256> unit = [] {  // byte / 255.0, without the divisions
    std::array<double, 256> t;
    for (int i = 0; i < 256; ++i) t[i] = i / 255.0;
    return t;
  }();
  const double r = unit[c[0]], g = unit[c[1]], b = unit[c[2]];
  const double mx = std::max({r, g, b}), mn = std::min({r, g, b}), delta = mx - mn;
  double h = 0;
  if (delta > 0) {
    if (mx == r) {
      // fmod(x, 6) for x = (g - b) / delta + 6 in [5, 7], exactly (x - 6 is exact there).
      const double x = (g - b) / delta + 6.0;
      h = x >= 6.0 ? x - 6.0 : x;
    } else if (mx == g) {
      h = (b - r) / delta + 2.0;
    } else {
      h = (r - g) / delta + 4.0;
    }
    h /= 6.0;
  }
  const double s = mx > 0 ? delta / mx : 0.0;
  return {h, s, mx};
}

Eigen::Vector3d hsv_to_rgb(const Eigen::Vector3d& hsv) {
  const double h6 = (hsv[0] - std::floor(hsv[0])) * 6, s = hsv[1], v = hsv[2];
  const int k = static_cast<int>(h6) % 6;
  const double f = h6 - std::floor(h6), p = v * (1 - s), q = v * (1 - s * f),
               t = v * (1 - s * (1 - f));
  const Eigen::Vector3d rgb[6] = {{v, t, p}, {q, v, p}, {p, v, t}, {p, q, v}, {t, p, v}, {v, p, q}};
  return rgb[k] * 255.0;
}

Rgb to_rgb8(const Eigen::Vector3d& c) {
  auto q = [](double x) { return static_cast<std::uint8_t>(std::clamp(std::lround(x), 0L, 255L)); };
  return {q(c.x()), q(c.y()), q(c.z())};
}

}  // namespace proxseg
