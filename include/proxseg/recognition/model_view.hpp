// Making a database view from a described cloud [paper 3.4]: its parts' signatures
// (add_part_signatures()) and what the shortlist keeps in memory (core/database.hpp).
#pragma once
#include <proxseg/core/database.hpp>

#include <string>
#include <vector>

namespace proxseg {

// A view of `object` held in memory (record 0): the cloud as described (describe() or
// restore()), its part signatures added. `name` defaults to object + its position.
ModelView make_model_view(std::string object, Cloud cloud, std::string source,
                          std::string name = {});

}  // namespace proxseg
