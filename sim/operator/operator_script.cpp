// Operator scripts: patterns over the stock, CSV files, and the walk between points.
#include "sim/operator/operator_script.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace stencil::sim {
namespace {

// Moves between passes go in any direction: at 2/3 of the pass speed their |dx| + |dy| + |dz| stays
// within the mill's step rate, so the virtual tool keeps up and the hand feels no pull.
constexpr double kRepositionFactor = 2.0 / 3.0;
// Thin-wall sweeps are meant to be too fast: the speed limit and the sweep check hold the tool.
constexpr double kSweepFactor = 10.0;

// The raster's passes meet a wall only where they cross it, 1 mm apart in x (2 mm along a wall at
// 60 degrees), and leave a cusp of stock the height of the wall between each two. A machinist ends
// with a finishing pass around the part at full depth; this one is as careless as the passes:
// around the part at the floor, pressed `press` mm into its walls, the stencil holding the tool on
// them. The way round is found from the middle of what the tool cannot reach at the floor, looking
// out in each direction for where that region ends (a star-shaped outline is followed exactly).
void add_finishing_pass(OperatorScript& script, const StockBox& stock, double press, double speed_mm_per_s,
                        double scale, const std::function<double(double, double)>& touch_tip) {
  constexpr double kGrid = 0.2;   // mm, the search for the blocked region's middle
  constexpr double kMarch = 0.05; // mm, the search outward along each direction
  constexpr int kDirections = 720;
  const Eigen::Vector3d& low = stock.low_mm;
  const Eigen::Vector3d& high = stock.high_mm;
  const auto blocked = [&](double x, double y) { return touch_tip(x, y) > low.z() + 0.01; };
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  int count = 0;
  for (double y = low.y(); y <= high.y(); y += kGrid) {
    for (double x = low.x(); x <= high.x(); x += kGrid) {
      if (blocked(x, y)) {
        sum += Eigen::Vector2d(x, y);
        ++count;
      }
    }
  }
  if (count == 0) {
    return;  // no part in the stock: nothing to finish
  }
  const Eigen::Vector2d centre = sum / count;
  if (!blocked(centre.x(), centre.y())) {
    return;  // not star-shaped about its middle: no way round found this way
  }
  // Each direction's wall: the last blocked point before the open floor. Where the blocked region
  // runs out of the stock instead there is no wall to finish; the way round breaks into arcs there.
  struct Direction {
    Eigen::Vector2d at_wall, pressed, outside;
    bool wall;
  };
  std::vector<Direction> directions;
  const double reach = (high.head<2>() - low.head<2>()).norm();
  const auto in_stock = [&](const Eigen::Vector2d& p) {
    return p.x() >= low.x() && p.x() <= high.x() && p.y() >= low.y() && p.y() <= high.y();
  };
  for (int i = 0; i < kDirections; ++i) {
    const double angle = 2.0 * M_PI * i / kDirections;
    const Eigen::Vector2d u(std::cos(angle), std::sin(angle));
    double edge = 0.0;
    bool wall = false;
    for (double r = 0.0; r <= reach; r += kMarch) {
      const Eigen::Vector2d p = centre + r * u;
      if (!in_stock(p)) {
        break;
      }
      if (!blocked(p.x(), p.y())) {
        wall = true;
        break;
      }
      edge = r;
    }
    const Eigen::Vector2d outside = (centre + (edge + 1.0) * u).cwiseMax(low.head<2>()).cwiseMin(high.head<2>());
    directions.push_back({centre + edge * u, centre + std::max(0.0, edge - press) * u, outside, wall});
  }
  // Start just after a break, so no arc is split across the end of the list (any start will do
  // when the wall goes all the way round).
  int start = 0;
  for (int i = 0; i < kDirections; ++i) {
    if (!directions[static_cast<std::size_t>(i)].wall &&
        directions[static_cast<std::size_t>((i + 1) % kDirections)].wall) {
      start = (i + 1) % kDirections;
      break;
    }
  }
  const double floor = low.z();
  const double above = high.z() + 1.0;
  const bool all_round = std::all_of(directions.begin(), directions.end(), [](const Direction& d) { return d.wall; });
  bool in_arc = false;
  Eigen::Vector2d last = centre;
  for (int k = 0; k <= kDirections; ++k) {
    const Direction& d = directions[static_cast<std::size_t>((start + k) % kDirections)];
    const bool closing = k == kDirections;
    if (d.wall && !in_arc && !closing) {
      // Down to the floor in the open, then in to the wall.
      walk_to(script, {d.outside.x(), d.outside.y(), above}, kRepositionFactor * speed_mm_per_s, scale);
      walk_to(script, {d.outside.x(), d.outside.y(), floor}, kRepositionFactor * speed_mm_per_s, scale);
      in_arc = true;
    }
    if (in_arc && d.wall && (!closing || all_round)) {
      walk_to(script, {d.pressed.x(), d.pressed.y(), floor}, speed_mm_per_s, scale);
      last = d.outside;
    }
    if (in_arc && (!d.wall || closing)) {
      // Out of the wall and up, clear of the part, before the next arc.
      walk_to(script, {last.x(), last.y(), floor}, kRepositionFactor * speed_mm_per_s, scale);
      walk_to(script, {last.x(), last.y(), above}, kRepositionFactor * speed_mm_per_s, scale);
      in_arc = false;
    }
  }
}

}  // namespace

Eigen::Vector3d OperatorScript::position_at(double t) const {
  if (t_s.empty()) {
    return Eigen::Vector3d::Zero();
  }
  if (t <= t_s.front()) {
    return device_mm.front();
  }
  if (t >= t_s.back()) {
    return device_mm.back();
  }
  const auto next = static_cast<std::size_t>(std::upper_bound(t_s.begin(), t_s.end(), t) - t_s.begin());
  const double span = t_s[next] - t_s[next - 1];
  const double f = span > 0.0 ? (t - t_s[next - 1]) / span : 1.0;
  return device_mm[next - 1] + f * (device_mm[next] - device_mm[next - 1]);
}

Eigen::Vector2d OperatorScript::angles_at(double t) const {
  if (t_s.empty()) {
    return Eigen::Vector2d::Zero();
  }
  const auto next = static_cast<std::size_t>(std::upper_bound(t_s.begin(), t_s.end(), t) - t_s.begin());
  if (next == 0) {
    return angles_rad.front();
  }
  return angles_rad[std::min(next, angles_rad.size()) - 1];
}

void walk_to(OperatorScript& script, const Eigen::Vector3d& to_world_mm, double speed_mm_per_s,
             double device_mm_per_world_mm) {
  const Eigen::Vector3d to = device_mm_per_world_mm * to_world_mm;
  if (script.t_s.empty()) {
    script.t_s.push_back(0.0);
    script.device_mm.push_back(to);
    script.angles_rad.push_back(Eigen::Vector2d::Zero());
    return;
  }
  const double distance_world = (to - script.device_mm.back()).norm() / device_mm_per_world_mm;
  script.t_s.push_back(script.t_s.back() + distance_world / speed_mm_per_s);
  script.device_mm.push_back(to);
  script.angles_rad.push_back(Eigen::Vector2d::Zero());
}

OperatorScript carry_on(const OperatorScript& script, double from_s, const Eigen::Vector3d& home_world_mm,
                        const Eigen::Vector3d& rejoin_world_mm, double speed_mm_per_s, double scale, double& approach_s) {
  OperatorScript out;
  const auto walk = [&](const Eigen::Vector3d& to_world) {
    if (out.t_s.empty() || (scale * to_world - out.device_mm.back()).norm() > 1e-9) {
      walk_to(out, to_world, speed_mm_per_s, scale);
    }
  };
  // One axis at a time, as the virtual tool's speed limit counts |dx| + |dy| + |dz|: a diagonal at the
  // hand's speed would leave the tool behind, pulling on the hand.
  walk(home_world_mm);
  walk({rejoin_world_mm.x(), home_world_mm.y(), home_world_mm.z()});
  walk({rejoin_world_mm.x(), rejoin_world_mm.y(), home_world_mm.z()});
  walk(rejoin_world_mm);
  walk(script.position_at(from_s) / scale);
  approach_s = out.duration_s();
  for (std::size_t i = 0; i < script.t_s.size(); ++i) {
    if (script.t_s[i] > from_s) {
      out.t_s.push_back(approach_s + script.t_s[i] - from_s);
      out.device_mm.push_back(script.device_mm[i]);
      out.angles_rad.push_back(script.angles_rad[i]);
    }
  }
  return out;
}

OperatorScript make_pattern(Pattern pattern, const StockBox& stock, const Eigen::Vector3d& home_world_mm,
                            double speed_mm_per_s, double scale, std::uint64_t seed,
                            const std::function<double(double, double)>& touch_tip, int random_moves) {
  OperatorScript script;
  const Eigen::Vector3d& low = stock.low_mm;
  const Eigen::Vector3d& high = stock.high_mm;
  const double above = high.z() + 1.0;
  walk_to(script, home_world_mm, speed_mm_per_s, scale);
  switch (pattern) {
    case Pattern::Raster: {
      walk_to(script, {low.x(), low.y(), above}, kRepositionFactor * speed_mm_per_s, scale);
      constexpr double kPress = 1.0;    // how far the careless hand presses into the part
      constexpr double kSample = 0.2;   // the pass's points, mm apart
      for (double level = high.z() - 1.0; level >= low.z() - 1e-9; level -= 1.0) {
        bool forward = true;
        for (double x = low.x(); x <= high.x() + 1e-9; x += 1.0) {
          const int samples = static_cast<int>(std::ceil((high.y() - low.y()) / kSample));
          for (int i = 0; i <= samples; ++i) {
            const double f = static_cast<double>(i) / samples;
            const double y = forward ? low.y() + f * (high.y() - low.y()) : high.y() - f * (high.y() - low.y());
            walk_to(script, {x, y, std::max(level, touch_tip(x, y) - kPress)}, speed_mm_per_s, scale);
          }
          forward = !forward;
        }
        // Back to the start corner over the top of everything, for the next level.
        walk_to(script, {high.x(), forward ? low.y() : high.y(), above}, kRepositionFactor * speed_mm_per_s, scale);
        walk_to(script, {low.x(), low.y(), above}, kRepositionFactor * speed_mm_per_s, scale);
      }
      add_finishing_pass(script, stock, kPress, speed_mm_per_s, scale, touch_tip);
      break;
    }
    case Pattern::Plunge:
      for (double x = low.x() + 1.0; x < high.x(); x += 2.0) {
        for (double y = low.y() + 1.0; y < high.y(); y += 2.0) {
          walk_to(script, {x, y, above}, kRepositionFactor * speed_mm_per_s, scale);
          walk_to(script, {x, y, low.z() - 1.0}, speed_mm_per_s, scale);
          walk_to(script, {x, y, above}, kRepositionFactor * speed_mm_per_s, scale);
        }
      }
      break;
    case Pattern::Thinwall:
      for (double z = high.z() - 0.5; z >= low.z(); z -= 1.5) {
        walk_to(script, {low.x(), 0.5 * (low.y() + high.y()), z}, kRepositionFactor * speed_mm_per_s, scale);
        walk_to(script, {high.x(), 0.5 * (low.y() + high.y()), z}, kSweepFactor * speed_mm_per_s, scale);
        walk_to(script, {0.5 * (low.x() + high.x()), low.y(), z}, kSweepFactor * speed_mm_per_s, scale);
        walk_to(script, {0.5 * (low.x() + high.x()), high.y(), z}, kSweepFactor * speed_mm_per_s, scale);
      }
      break;
    case Pattern::Random: {
      std::mt19937_64 random(seed);
      std::uniform_real_distribution<double> unit(0.0, 1.0);
      for (int i = 0; i < random_moves; ++i) {
        const Eigen::Vector3d to(low.x() + unit(random) * (high.x() - low.x()), low.y() + unit(random) * (high.y() - low.y()),
                                 low.z() - 1.0 + unit(random) * (above - low.z() + 1.0));
        walk_to(script, to, (0.5 + 2.0 * unit(random)) * speed_mm_per_s, scale);
      }
      break;
    }
  }
  walk_to(script, {script.device_mm.back().x() / scale, script.device_mm.back().y() / scale, above}, kRepositionFactor * speed_mm_per_s,
          scale);
  walk_to(script, home_world_mm, kRepositionFactor * speed_mm_per_s, scale);
  return script;
}

bool parse_finite_field(const std::string& field, double& value) {
  std::size_t used = 0;
  try {
    value = std::stod(field, &used);
  } catch (...) {
    return false;  // not a number at all, or out of double's range
  }
  while (used < field.size() && (field[used] == ' ' || field[used] == '\r')) {
    ++used;
  }
  return used != 0 && used == field.size() && std::isfinite(value);
}

bool read_operator_csv(const std::string& path, OperatorScript& script, std::string& error) {
  std::ifstream in(path);
  if (!in) {
    error = path + ": cannot be read";
    return false;
  }
  return parse_operator_csv(in, path, script, error);
}

bool write_operator_csv(const std::string& path, const OperatorScript& script, std::string& error) {
  std::FILE* file = std::fopen(path.c_str(), "w");
  if (file == nullptr) {
    error = path + ": cannot be written";
    return false;
  }
  bool written = std::fprintf(file, "t_s,x_mm,y_mm,z_mm,a_rad,b_rad\n") > 0;
  for (std::size_t i = 0; i < script.t_s.size() && written; ++i) {
    const Eigen::Vector2d angles = i < script.angles_rad.size() ? script.angles_rad[i] : Eigen::Vector2d::Zero();
    written = std::fprintf(file, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", script.t_s[i], script.device_mm[i].x(),
                           script.device_mm[i].y(), script.device_mm[i].z(), angles.x(), angles.y()) > 0;
  }
  written = std::fclose(file) == 0 && written;
  if (!written) {
    error = path + ": could not be written in full";
  }
  return written;
}

bool parse_operator_csv(std::istream& in, const std::string& path, OperatorScript& script, std::string& error) {
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') {
      line.pop_back();  // a file written on Windows: its blank lines are blank too
    }
    if (line.empty() || line[0] == '#' || (number == 1 && line.rfind("t_s", 0) == 0)) {
      continue;  // comments and a header line
    }
    std::vector<double> values;
    std::stringstream fields(line);
    std::string field;
    while (std::getline(fields, field, ',')) {
      double value = 0.0;
      if (!parse_finite_field(field, value)) {
        error = path + ": line " + std::to_string(number) + ": field " + std::to_string(values.size() + 1) + " '" + field +
                "' is not a finite number";
        return false;
      }
      values.push_back(value);
    }
    if (line.back() == ',') {  // getline gives no empty last field: a row is not guessed complete
      error = path + ": line " + std::to_string(number) + ": field " + std::to_string(values.size() + 1) +
              " '' is not a finite number";
      return false;
    }
    if (values.size() != 4 && values.size() != 6) {
      error = path + ": line " + std::to_string(number) + ": " + std::to_string(values.size()) +
              " fields; expected t_s,x_mm,y_mm,z_mm[,a_rad,b_rad]";
      return false;
    }
    if (!script.t_s.empty() && !(values[0] > script.t_s.back())) {
      error = path + ": line " + std::to_string(number) + ": t_s " + std::to_string(values[0]) +
              " does not increase (the previous row's is " + std::to_string(script.t_s.back()) + ")";
      return false;
    }
    script.t_s.push_back(values[0]);
    script.device_mm.emplace_back(values[1], values[2], values[3]);
    script.angles_rad.emplace_back(values.size() == 6 ? values[4] : 0.0, values.size() == 6 ? values[5] : 0.0);
  }
  if (script.t_s.empty()) {
    error = path + ": no rows; expected t_s,x_mm,y_mm,z_mm[,a_rad,b_rad]";
    return false;
  }
  return true;
}

}  // namespace stencil::sim
