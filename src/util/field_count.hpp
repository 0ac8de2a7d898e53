// The number of data members of an aggregate struct, at compile time: the most initialisers its
// brace initialisation takes (Boost.PFR's idea, which Debian 12's Boost 1.74 does not have). The
// parameter table checks each adapted struct's count against its Boost.Fusion adaptation with it,
// so that a member added to a struct but not to the adaptation stops the build.
#pragma once

#include <cstddef>
#include <utility>

namespace proxseg::detail {

// Converts to any member type; never called (only its conversion is looked at).
struct AnyMember {
  template <class T>
  constexpr operator T() const;  // NOLINT(google-explicit-constructor): what the count relies on
};

template <class S, class... A>
constexpr auto braces_take(int) -> decltype(S{std::declval<A>()...}, true) {
  return true;
}
template <class S, class... A>
constexpr bool braces_take(...) {
  return false;
}

// The members of S: initialisers are added one by one until S{...} no longer compiles. A member
// that is an array would count once per element; the parameter structs have none.
template <class S, class... A>
constexpr std::size_t field_count() {
  if constexpr (braces_take<S, A..., AnyMember>(0))
    return field_count<S, A..., AnyMember>();
  else
    return sizeof...(A);
}

}  // namespace proxseg::detail
