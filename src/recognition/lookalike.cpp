// Telling look-alikes apart by the colours where they differ [extension].
#include <proxseg/recognition/lookalike.hpp>

#include <algorithm>
#include <vector>

namespace proxseg {

LookalikeVote lookalike_vote(const Cloud& candidate, const Cloud& first_view,
                             const Eigen::Matrix4d& first_pose, const Cloud& second_view,
                             const Eigen::Matrix4d& second_pose, const RegistrationParams& params) {
  // Two colours that agree under 0.5 are another paint, not another shade of one (a shaded and
  // a lit side of one paint agree above 0.8, chromaticity_agreement()); a lead of 0.2 is more
  // than the agreement's noise between two views of one paint.
  constexpr double kDiffer = 0.5, kLead = 0.2;
  LookalikeVote vote;
  if (candidate.colours.empty() || first_view.colours.empty() || second_view.colours.empty())
    return vote;
  const double delta = params.score_distance, sigma = params.brightness_sigma;
  const std::vector<int> a = nearest_view_points(candidate, first_view, first_pose, delta);
  const std::vector<int> b = nearest_view_points(candidate, second_view, second_pose, delta);
  double sum_first = 0, sum_second = 0;
  for (std::size_t i = 0; i < candidate.size(); ++i) {
    if (a[i] < 0 || b[i] < 0) continue;
    ++vote.compared;
    const Rgb &ca = first_view.colours[a[i]], &cb = second_view.colours[b[i]];
    if (point_colour_agreement(ca, cb, sigma) >= kDiffer) continue;
    ++vote.differing;
    const double with_a = point_colour_agreement(candidate.colours[i], ca, sigma);
    const double with_b = point_colour_agreement(candidate.colours[i], cb, sigma);
    if (with_a >= with_b + kLead) {
      ++vote.first;
      sum_first += with_a;
    } else if (with_b >= with_a + kLead) {
      ++vote.second;
      sum_second += with_b;
    }
  }
  vote.first_agreement = vote.first ? sum_first / vote.first : 0;
  vote.second_agreement = vote.second ? sum_second / vote.second : 0;
  return vote;
}

int lookalike_winner(const LookalikeVote& vote, double share, double agreement, int min_votes) {
  const int votes = vote.first + vote.second;
  if (votes < std::max(1, min_votes)) return 0;
  if (vote.first >= share * votes && vote.first_agreement >= agreement) return 1;
  if (vote.second >= share * votes && vote.second_agreement >= agreement) return 2;
  return 0;
}

}  // namespace proxseg
