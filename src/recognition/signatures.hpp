// A described cloud's signature [extension, docs/method.md "A database that scales"], for
// describe() and restore(). Private to src/recognition.
#pragma once
#include <proxseg/core/registration_types.hpp>

namespace proxseg::detail {

// The signature of the whole cloud: its mean FPFH per radius block, its colour histogram and its
// spread; no parts (add_part_signatures()).
Signature make_signature(const Cloud& c);

}  // namespace proxseg::detail
