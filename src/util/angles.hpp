// Pi and degree <-> radian conversions: one definition for the parameters given in degrees
// (tolerances, tilts, elevations) and the generators that draw angles.
#pragma once

namespace proxseg::detail {

constexpr double kPi = 3.14159265358979323846;

// Evaluated as (deg * pi) / 180, the order the code used before this header, so that results
// stay bit-identical.
constexpr double radians(double deg) {
  return deg * kPi / 180;
}
constexpr double degrees(double rad) {
  return rad * 180 / kPi;
}

}  // namespace proxseg::detail
