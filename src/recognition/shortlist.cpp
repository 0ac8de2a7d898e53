// The shortlist [extension, docs/method.md "A database that scales"]: the views that recognition
// aligns, nearest to the candidate by signature, with the parts of a view compared only while
// their sketches' bound lets it in [docs/database.md].
#include <proxseg/core/errors.hpp>
#include <proxseg/recognition/recognition.hpp>

#include <algorithm>
#include <limits>

namespace proxseg {
namespace {

// Floating-point slack of sketch_distance() as a bound (signature_distance() sums about 130
// float differences in float arithmetic, a sketch holds the spread as a float).
constexpr double kBoundSlack = 1e-4;

// The least sketch_distance() from the candidate to the view's parts, and the view's own
// distance: at most its view_distance().
double parts_bound(const Eigen::VectorXf& candidate, bool coloured, const ModelView& view,
                   double whole, Eigen::Index shape_bins) {
  double d = whole;
  for (Eigen::Index k = 0; k < view.part_sketches.size(); ++k)
    d = std::min(
        d, sketch_distance(candidate, view.part_sketches, k, shape_bins, coloured, view.coloured));
  return d;
}

using Ranked = std::vector<std::pair<double, int>>;  // (distance, view), nearest first

// The views of a shortlist of `shortlist` taken from `ranked` (sorted): the nearest ones, and
// further the nearest view of a second object when they all show one.
std::vector<int> take_shortlist(const Ranked& ranked, const Database& db, int shortlist) {
  std::vector<int> out;
  for (const auto& r : ranked) {
    if (shortlist > 0 && static_cast<int>(out.size()) >= shortlist) {
      // Keep going only for the nearest view of a second object.
      const std::string& first = db.views[out.front()].object;
      const bool one_object =
          std::all_of(out.begin(), out.end(), [&](int v) { return db.views[v].object == first; });
      if (!one_object) break;
      if (db.views[r.second].object == first) continue;
    }
    out.push_back(r.second);
  }
  return out;
}

// The largest distance a view can have and still enter the shortlist taken from the views
// measured so far (infinite while it could take any).
double entry_distance(Ranked measured, const Database& db, int shortlist) {
  if (static_cast<int>(measured.size()) < shortlist) return std::numeric_limits<double>::infinity();
  std::sort(measured.begin(), measured.end());
  const std::vector<int> taken = take_shortlist(measured, db, shortlist);
  if (static_cast<int>(taken.size()) <= shortlist &&
      std::all_of(taken.begin(), taken.end(),
                  [&](int v) { return db.views[v].object == db.views[taken[0]].object; }))
    return std::numeric_limits<double>::infinity();  // no second object yet
  double d = 0;
  for (const auto& m : measured)
    if (std::find(taken.begin(), taken.end(), m.second) != taken.end()) d = std::max(d, m.first);
  return d;
}

}  // namespace

std::vector<int> shortlist_views(const Cloud& candidate, const Database& db, int shortlist,
                                 const std::vector<std::string>& objects, bool parts,
                                 std::vector<std::string>* damaged) {
  Ranked bounds;  // (a lower bound of the view's distance, view)
  const Eigen::VectorXf sketch = sketch_of(candidate.signature);
  const bool coloured = candidate.signature.colour.size() > 0;
  const Eigen::Index shape_bins = candidate.signature.shape.size();
  std::vector<double> whole(db.views.size(), 0.0);
  for (int v = 0; v < static_cast<int>(db.views.size()); ++v) {
    const ModelView& view = db.views[v];
    if (!objects.empty() && std::find(objects.begin(), objects.end(), view.object) == objects.end())
      continue;
    if (shortlist > 0) whole[v] = signature_distance(candidate.signature, view.signature);
    bounds.emplace_back(
        shortlist > 0 && parts
            ? parts_bound(sketch, coloured, view, whole[v], shape_bins) - kBoundSlack
            : whole[v],
        v);
  }
  // Ties (and the whole order without a shortlist) go by view index.
  std::sort(bounds.begin(), bounds.end());
  if (shortlist <= 0 || !parts) return take_shortlist(bounds, db, shortlist);
  // A view's parts are read (stored databases) and compared only while its bound says it could
  // still enter: exactly the shortlist of every view's view_distance().
  Ranked measured;
  double entry = std::numeric_limits<double>::infinity();
  for (const auto& [bound, v] : bounds) {
    if (bound > entry) break;
    double d = whole[v];
    try {
      for (const Signature& part : db.views[v].part_signatures())
        d = std::min(d, signature_distance(candidate.signature, part));
    } catch (const InputError& e) {
      if (damaged) damaged->push_back(e.what());
      continue;
    }
    measured.emplace_back(d, v);
    if (measured.size() % 16 == 0 || static_cast<int>(measured.size()) == shortlist)
      entry = entry_distance(measured, db, shortlist);
  }
  std::sort(measured.begin(), measured.end());
  return take_shortlist(measured, db, shortlist);
}

}  // namespace proxseg
