// Compiled by ctest Parameters.AdaptationIsChecked, never built into a program: a parameter
// struct whose Boost.Fusion adaptation leaves out a member must not compile
// (src/core/parameter_members.hpp), the same struct with every member listed must.
#include "core/parameter_members.hpp"

namespace {

struct FakeParams {
  double a = 1;
  int b = 2;
  proxseg::MrfParams section;
  bool added_later = false;
};

}  // namespace

#ifdef PROXSEG_LIST_EVERY_MEMBER
PROXSEG_ADAPT_PARAMETERS(FakeParams, a, b, section, added_later)
#else
PROXSEG_ADAPT_PARAMETERS(FakeParams, a, b, section)
#endif

int main() {
  return 0;
}
