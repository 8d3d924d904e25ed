// The simulated operator: where the hand wants the tool to go over time (a script of world points
// walked at a steady speed, from a pattern or a CSV file), and the hand itself, a spring pulling
// the handle towards the script against the force the device renders, so that the operator can
// overpower 5 N as a person can.
#pragma once

#include <cstdint>
#include <functional>
#include <istream>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "sim/mill/stock_zmap.hpp"

namespace stencil::sim {

// A path of device-space points with the time (s) at which the hand is at each; in between it
// moves in a straight line.
struct OperatorScript {
  std::vector<double> t_s;
  std::vector<Eigen::Vector3d> device_mm;
  std::vector<Eigen::Vector2d> angles_rad;

  [[nodiscard]] double duration_s() const { return t_s.empty() ? 0.0 : t_s.back(); }
  // Where the script is at t (clamped to its ends).
  [[nodiscard]] Eigen::Vector3d position_at(double t) const;
  [[nodiscard]] Eigen::Vector2d angles_at(double t) const;
};

// Appends the world point `to` to the script, reached at `speed_mm_per_s` (world) from the last.
void walk_to(OperatorScript& script, const Eigen::Vector3d& to_world_mm, double speed_mm_per_s,
             double device_mm_per_world_mm);

enum class Pattern : std::uint8_t { Raster, Plunge, Thinwall, Random };

// The patterns over the stock (world mm), starting and ending at `home`. `touch_tip(x, y)` is the
// lowest the tool's tip can be over (x, y) without entering the part (the floor where it is clear):
// raster: levels 1 mm apart from the stock's top down to the floor, passes along y 1 mm apart in x;
//   where a pass meets the part it rides over it 1 mm too deep (a careless operator), so the
//   stencil holds the tool on the part; then one finishing pass around the part at the floor,
//   pressed 1 mm into its walls, for the cusps the passes leave between them on the walls;
// plunge: straight down to the floor at points 2 mm apart, through the part where it is there;
// thinwall: fast sweeps straight across the stock at several heights, through whatever is there;
// random: a random walk over and into the stock (seeded), `random_moves` moves (200: about 40 minutes).
[[nodiscard]] OperatorScript make_pattern(Pattern pattern, const StockBox& stock, const Eigen::Vector3d& home_world_mm,
                                          double speed_mm_per_s, double device_mm_per_world_mm, std::uint64_t seed,
                                          const std::function<double(double, double)>& touch_tip,
                                          int random_moves = 200);

// The way back into a job that stopped (a resume): from `home` across at home's height to above
// `rejoin` (world; along x, then y), straight down to it, then to where `script` was at `from_s`, and on with the rest
// of `script` from there. `approach_s` is how long the way back takes.
[[nodiscard]] OperatorScript carry_on(const OperatorScript& script, double from_s, const Eigen::Vector3d& home_world_mm,
                                      const Eigen::Vector3d& rejoin_world_mm, double speed_mm_per_s,
                                      double device_mm_per_world_mm, double& approach_s);

// One comma-separated field as a finite number: all of it (trailing blanks and a carriage return
// aside), or false. For the CSV reader and the programs' number lists alike.
[[nodiscard]] bool parse_finite_field(const std::string& field, double& value);

// A script from CSV rows t_s,x_mm,y_mm,z_mm[,a_rad,b_rad] (device space, times increasing). On bad
// input returns false with `error` naming the file (`name`), the line and what was expected.
[[nodiscard]] bool read_operator_csv(const std::string& path, OperatorScript& script, std::string& error);
// The script as read_operator_csv reads it back (a header line, then t_s,x_mm,y_mm,z_mm,a_rad,b_rad
// rows with every digit a double needs). False with `error` naming the file when it cannot be written.
[[nodiscard]] bool write_operator_csv(const std::string& path, const OperatorScript& script, std::string& error);
[[nodiscard]] bool parse_operator_csv(std::istream& in, const std::string& name, OperatorScript& script,
                                      std::string& error);

// The hand: the handle is pulled to the script by a spring of stiffness k (N per device mm), the
// device pushes back with the rendered force; the handle moves a fraction of the way to where the
// two balance each millisecond (a hand's sluggishness, and stable for a stiff device).
struct OperatorHand {
  double stiffness_n_per_mm = 1.0;
  double follow_fraction = 0.3;
  Eigen::Vector3d handle_mm = Eigen::Vector3d::Zero();

  void step(const Eigen::Vector3d& script_mm, const Eigen::Vector3d& rendered_force_n) {
    const Eigen::Vector3d balance = script_mm + rendered_force_n / stiffness_n_per_mm;
    handle_mm += follow_fraction * (balance - handle_mm);
  }
};

}  // namespace stencil::sim
