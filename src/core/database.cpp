// The model database in memory (database.hpp): its objects and views, looked up by name.
#include <proxseg/core/database.hpp>

#include <set>

namespace proxseg {

std::vector<std::string> Database::objects() const {
  std::vector<std::string> names;
  std::set<std::string> seen;
  for (const ModelView& v : views)
    if (seen.insert(v.object).second) names.push_back(v.object);
  return names;
}

}  // namespace proxseg
