#include <proxseg/core/version.hpp>

const char* proxseg::version() {
  return PROXSEG_VERSION;
}
