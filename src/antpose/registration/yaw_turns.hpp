// A strategy from the candidates themselves: the best one turned about its long axis.
//
// A panel's outline constrains its yaw about the long axis z_a only weakly, and a descent by the
// outline (silhouette.hpp) has basins a few tens of degrees wide: where every strategy's start lay
// in one wrong basin, the panel's own was never looked at. Two kinds of start reach the others:
//  - Mirror yaws. Seen along a direction at angle φ from its boresight (about z_a), a box of width
//    w (x_a) and depth d (y_a) shows an outline w|cos φ| + d|sin φ| wide. That width is the same at
//    −φ (the other side face seen) and, where 2θ* − |φ| lies in [0, π/2], at ±(2θ* − |φ|),
//    θ* = atan(d/w) (the width's maximum, where the box's diagonal stands across the line of
//    sight); a box's half turn aside (pose_selection.hpp's turned_round). Only the photos' other
//    directions and the faces' inner edges tell these apart.
//  - A grid of turns (turns_deg) about the candidate's own long axis, spaced about a basin's width,
//    for the basins no symmetry predicts (a face's inner edges, brackets and end caps lining up
//    with the photo's edges at another yaw).
// φ is taken for the mean direction to the photos. A third kind reaches the true pose where the
// descent cannot: crease twins. Where a side face is too faint against its background to be seen
// (a dark side before dark windows), the photos show the front face alone, and a box turned by θ*
// about z_a and centred on the true front face's middle fits that: its diagonal then runs along
// the front face, its ends where the face's corners are, the outline only √(1 + (d/w)²) − 1 wider
// (2 % for a thin panel), in every photo of that side alike. The true pose is then the box turned
// back by ∓θ* and moved by d/2 away from the photos along its own boresight: its outline meets
// fewer edges (not the faint face's) but lies better on those it meets, and the selection weighs
// the two by that placement (pose_selection.hpp). A fourth start comes from outside the photos: a
// known mast, which a panel's back faces (pose_selection.hpp), turns the box to face it
// (facing_turn). register_antenna refines and judges each start like any other proposal.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include "antpose/core/check.hpp"
#include "antpose/geometry/point_cloud.hpp"

namespace antpose::registration {

struct YawTurnOptions {
  std::size_t of_best = 1;    // the best candidates (by their outline) turned; 0: none
  double min_turn_deg = 4.0;  // a turn smaller than this leaves the candidate where it is
  std::vector<double> turns_deg{-60.0, -30.0, 30.0, 60.0, 90.0};  // the grid: 30° apart over a half turn
  OptionProblems Check() const;
};

/// The direction from the box's centre to the viewpoints (their mean, about z_a: φ of the file
/// comment), rad, in (−π, π]; 0 where every viewpoint lies on the long axis.
double view_angle(const Iso3& T_board_antenna, const std::vector<Vec3>& viewpoints_board);

/// The turns about z_a (rad, right-handed) that take `T_board_antenna` to each other yaw at which a
/// box of `outline_box_m` (width, depth, height) shows an outline as wide towards the viewpoints
/// (the file comment's mirror yaws), in (−π, π].
std::vector<double> mirror_turns(const Iso3& T_board_antenna, const Vec3& outline_box_m,
                                 const std::vector<Vec3>& viewpoints_board);

/// `T_board_antenna` turned about its own long axis by its mirror turns and the grid's, those within
/// min_turn_deg of no turn or of a smaller one left out; smallest turn first.
std::vector<Iso3> yaw_turns(const Iso3& T_board_antenna, const Vec3& outline_box_m,
                            const std::vector<Vec3>& viewpoints_board, const YawTurnOptions& options);

/// The turns about z_a (rad, right-handed) to a box's crease twins (file comment): +θ* and −θ*, θ* =
/// atan(d / w) for a box of `outline_box_m` (width w, depth d, height).
std::vector<double> crease_turns(const Vec3& outline_box_m);

/// `T_board_antenna` turned about its own long axis by each of its crease turns and moved by half the
/// box's depth along the turned boresight, away from the viewpoints (file comment): the true pose
/// where `T_board_antenna` lays its outline on a crease.
std::vector<Iso3> crease_twins(const Iso3& T_board_antenna, const Vec3& outline_box_m,
                               const std::vector<Vec3>& viewpoints_board);

/// `T_board_antenna` turned about its own long axis z_a, by at most a quarter turn, until its
/// boresight or its reverse lies in the plane of z_a and `direction_board` (a face, not an edge,
/// towards it). nullopt where the direction runs along z_a.
std::optional<Iso3> facing_turn(const Iso3& T_board_antenna, const Vec3& direction_board);

}  // namespace antpose::registration
