// Penalty-based speed limiting (issue 29, the thesis's alternative to capping the virtual tool alone):
// a force on the hand that opposes its velocity and rises as it nears the speed the mill can follow.
#pragma once

#include <Eigen/Core>

namespace stencil::engine {

// The law: nothing below an onset, then a damper's force rising at a bounded slope, at most the force
// limit. Why this shape, by measurement (stencil-wall-test --test speed and --test release: the three
// simulated grasps, the rig's 10 device mm/s, the CAN link's 0.7 ms; --heading 45 for a diagonal,
// --penalty-slope to try another slope):
// - To hold a push F under the limit v the penalty must reach F before v: at least F / v on average
//   from a standstill, 200 N s/m for the 2 N push issue 29 asks about at the rig's 10 mm/s. What a
//   sampled damper renders stably bounds the slope everywhere, not just on average (a steeper stretch
//   anywhere rings wherever a push puts the hand on it): so a straight line, the least slope that
//   gets there, rather than a barrier that steepens towards the limit.
// - On the filtered velocity alone the lightest grasp (0.3 kg) still rings 8 % of its speed 100 ms on
//   at 240 N s/m and is unstable by 300, and a handle let go buzzes at the force limit at 400. On the
//   velocity predicted past the filter's lag (velocity_predictor.hpp) all three grasps settle within
//   5 % along an axis up to 400 (the lightest 5.7 % at 450), all three are unstable at 600, and a
//   handle let go comes to rest at every coupling up to 600. kSpeedPenaltySlopeNSPerM is about 0.6 of
//   where it goes unstable, the most that keeps the lightest grasp's jitter (its velocity comes from
//   positions in whole micrometres, 1 mm/s a period) under issue 29's 5 % along a diagonal too: 3 %
//   of its speed along an axis, 4.6 % along a diagonal (8.6 % at 400).
// - The onset: free below a tenth of the limit (a handle at rest, its positions flickering by a
//   micrometre, feels nothing). Not later: along a horizontal diagonal the cap's |dx| + |dy| bound
//   lets the mill follow only 7.1 of the rig's 10 mm/s, and from a quarter the slope would reach
//   only 1.9 N there. From a tenth it holds 2 N at 6.6 mm/s along an axis and 6.3 along a diagonal,
//   and pushes up to 3.1 N (2.2 N) under the limit; the cap's spring takes over beyond. Where the
//   slope can reach the force limit from later on (a faster mill, a lower force limit) the onset is
//   that later point: any push under the force limit is held under the speed limit.
inline constexpr double kSpeedPenaltySlopeNSPerM = 350.0;  // N s per device metre
inline constexpr double kSpeedPenaltyOnsetFraction = 0.1;  // of the speed limit

// The speed the mill can follow along `direction` (any length), in the unit of the two limits: the
// cap's rule (stencil/move_limit.hpp) bounds each axis by `axis_speed` and |vx| + |vy| + |vz| by
// `total_speed`, so along a diagonal it is less than along an axis. Infinity when neither bounds it
// (no cap) or the direction is zero or not finite. Real-time safe.
[[nodiscard]] double mill_speed_along(const Eigen::Vector3d& direction, double axis_speed, double total_speed);

// The penalty (N) on a hand moving at `velocity_m_per_s` (device m/s) when the mill follows
// `limit_m_per_s` along that direction (device m/s): against the velocity, of magnitude
// slope x (speed - onset) clamped to [0, max_force_n], the onset the later of onset_fraction x limit
// and the speed from which the slope reaches the force limit at the limit. Zero when the limit is
// infinite (no cap), and when an input is not finite or not positive (the cap alone then holds the
// tool). Real-time safe: fixed work, no allocation.
[[nodiscard]] Eigen::Vector3d speed_penalty_n(const Eigen::Vector3d& velocity_m_per_s, double limit_m_per_s,
                                              double max_force_n,
                                              double slope_n_s_per_m = kSpeedPenaltySlopeNSPerM,
                                              double onset_fraction = kSpeedPenaltyOnsetFraction);

}  // namespace stencil::engine
