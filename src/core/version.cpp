// The version and commit the library was built from (version.hpp).
#include <proxseg/core/version.hpp>

const char* proxseg::version() {
  return PROXSEG_VERSION;
}
