#include "antpose/registration/yaw_turns.hpp"

#include <algorithm>
#include <cmath>

#include "antpose/geometry/rotation.hpp"

namespace antpose::registration {

OptionProblems YawTurnOptions::Check() const {
  OptionProblems p;
  p.require(min_turn_deg > 0 && min_turn_deg < 45, "min_turn_deg", "in (0, 45)");
  p.require(std::all_of(turns_deg.begin(), turns_deg.end(), [](double t) { return std::abs(t) <= 180; }), "turns_deg",
            "each within ±180");
  return p;
}

namespace {

std::vector<Iso3> turned_about_long_axis(const Iso3& T_board_antenna, const std::vector<double>& turns) {
  std::vector<Iso3> out;
  const Vec3 z = T_board_antenna.linear().col(2);
  for (const double turn : turns) {
    Iso3 T = T_board_antenna;
    T.linear() = exp_so3(turn * z) * T_board_antenna.linear();
    out.push_back(T);
  }
  return out;
}

}  // namespace

double view_angle(const Iso3& T_board_antenna, const std::vector<Vec3>& viewpoints_board) {
  const Mat3 R = T_board_antenna.linear();
  const Vec3 z = R.col(2);
  Vec3 mean = Vec3::Zero();
  for (const Vec3& c : viewpoints_board) {
    Vec3 v = c - T_board_antenna.translation();
    v -= v.dot(z) * z;
    if (v.norm() > 1e-9) mean += v.normalized();
  }
  if (mean.norm() < 1e-9) return 0.0;
  return std::atan2(mean.dot(R.col(0)), mean.dot(R.col(1)));
}

std::vector<double> mirror_turns(const Iso3& T_board_antenna, const Vec3& outline_box_m,
                                 const std::vector<Vec3>& viewpoints_board) {
  // φ folded onto the front half (a half turn about z_a is the same box). On [0, π/2] the width is
  // A cos(|φ| − θ*), symmetric about θ*; beyond, no yaw on the other side of θ* is as wide.
  double phi = view_angle(T_board_antenna, viewpoints_board);
  if (phi > M_PI / 2) phi -= M_PI;
  if (phi < -M_PI / 2) phi += M_PI;
  const double theta = std::atan2(outline_box_m.y(), outline_box_m.x());
  const double other = 2 * theta - std::abs(phi);
  std::vector<double> targets{-phi};
  if (other >= 0 && other <= M_PI / 2) targets.insert(targets.end(), {other, -other});
  // Turning the box by α about z_a moves the direction to the photos from φ to φ + α.
  std::vector<double> out;
  for (const double target : targets) out.push_back(wrap_pi(target - phi));
  return out;
}

std::vector<Iso3> yaw_turns(const Iso3& T_board_antenna, const Vec3& outline_box_m,
                            const std::vector<Vec3>& viewpoints_board, const YawTurnOptions& options) {
  throw_unless_ok(options.Check(), "YawTurnOptions");
  auto candidates = mirror_turns(T_board_antenna, outline_box_m, viewpoints_board);
  for (const double t : options.turns_deg) candidates.push_back(deg2rad(t));
  std::stable_sort(candidates.begin(), candidates.end(), [](double a, double b) { return std::abs(a) < std::abs(b); });
  // Modulo the box's half turn: a turn by α and by α ± π leave the same box.
  const auto apart = [&](double a, double b) {
    const double d = std::abs(wrap_pi(a - b));
    return std::min(d, M_PI - d) >= deg2rad(options.min_turn_deg);
  };
  std::vector<double> turns;
  for (const double t : candidates)
    if (apart(t, 0.0) && std::all_of(turns.begin(), turns.end(), [&](double u) { return apart(t, u); }))
      turns.push_back(t);
  return turned_about_long_axis(T_board_antenna, turns);
}

std::vector<double> crease_turns(const Vec3& outline_box_m) {
  const double theta = std::atan2(outline_box_m.y(), outline_box_m.x());
  return {theta, -theta};
}

std::vector<Iso3> crease_twins(const Iso3& T_board_antenna, const Vec3& outline_box_m,
                               const std::vector<Vec3>& viewpoints_board) {
  auto out = turned_about_long_axis(T_board_antenna, crease_turns(outline_box_m));
  for (Iso3& T : out) {
    // The boresight's side towards the photos: cos(φ) > 0 at the twin's own view angle.
    const Vec3 y = T.linear().col(1);
    const double towards = std::cos(view_angle(T, viewpoints_board)) >= 0 ? 1.0 : -1.0;
    T.translation() -= towards * 0.5 * outline_box_m.y() * y;
  }
  return out;
}

std::optional<Iso3> facing_turn(const Iso3& T_board_antenna, const Vec3& direction_board) {
  const Mat3& R = T_board_antenna.linear();
  const Vec3 d = direction_board - direction_board.dot(R.col(2)) * R.col(2);
  if (d.norm() < 1e-9 * std::max(1.0, direction_board.norm())) return std::nullopt;
  // Turning by α moves the direction's angle from the boresight, φ, to φ + α (mirror_turns).
  double turn = -std::atan2(d.dot(R.col(0)), d.dot(R.col(1)));
  if (turn > M_PI / 2) turn -= M_PI;
  if (turn < -M_PI / 2) turn += M_PI;
  Iso3 T = T_board_antenna;
  T.linear() = exp_so3(turn * R.col(2)) * R;
  return T;
}

}  // namespace antpose::registration
