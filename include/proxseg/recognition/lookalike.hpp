// Telling look-alikes apart [extension, docs/method.md "Recognition that generalises"]: two
// models of one shape in other colours (an apple and a peach, a blue and a green box) score
// alike on a candidate, because much of what it shows agrees with both within the colour
// agreement's tolerance. Only the points where the two posed models predict other colours tell
// them apart; there, each candidate point votes for the model whose colour it agrees with better.
#pragma once
#include <proxseg/core/recognition_types.hpp>
#include <proxseg/recognition/registration.hpp>

#include <Eigen/Core>

namespace proxseg {

// Compares the candidate's colours with two posed views (candidate <- model poses) on the points
// both explain but colour differently (point_colour_agreement() of their two colours under
// 0.5); a point votes when it agrees with one view by 0.2 more than with the other. Colourless
// clouds give no votes.
LookalikeVote lookalike_vote(const Cloud& candidate, const Cloud& first_view,
                             const Eigen::Matrix4d& first_pose, const Cloud& second_view,
                             const Eigen::Matrix4d& second_pose, const RegistrationParams& params);

// Which view the vote names: 1 (first) or 2 (second) when it has at least min_votes votes, that
// view has at least `share` of them and its voters agree with it at least `agreement` on
// average; 0 when the vote does not decide.
int lookalike_winner(const LookalikeVote& vote, double share, double agreement, int min_votes);

}  // namespace proxseg
