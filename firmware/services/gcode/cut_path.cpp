#include "firmware/services/gcode/cut_path.hpp"

#include <algorithm>
#include <cmath>

#include "firmware/core/stencil/sweep.hpp"

namespace stencil::gcode {

void CutPath::homed() {
  // The first homing is where the program starts (the writer's way in); a later one (a resumed job)
  // is a way from wherever the tool was: straight up first (home is the top of the travel), then across.
  const Eigen::Vector3d& home = settings_.home_world_mm;
  if (homed_ && at_ != home) {
    if (at_.z() != home.z()) {
      moves_.push_back({MoveKind::Traverse, Eigen::Vector3d(at_.x(), at_.y(), home.z()), 0.0});
    }
    moves_.push_back({MoveKind::Traverse, home, 0.0});
  }
  at_ = home;
  homed_ = true;
}

void CutPath::feed_to(const Eigen::Vector3d& to, double seconds) {
  moves_.push_back({MoveKind::Feed, to, seconds});
  at_ = to;
}

bool CutPath::command(const control::MachineCommandRecord& record, std::string& error) {
  const Eigen::Vector3d target(record.target_tip_mm[0], record.target_tip_mm[1], record.target_tip_mm[2]);
  if (!target.allFinite()) {
    error = "machine target " + std::to_string(record.update) + " is not a finite point";
    return false;
  }
  if (!homed_) {
    error = "machine target " + std::to_string(record.update) + " comes before the machine was homed";
    return false;
  }
  // The staircase: one leg per axis that moves, in the recorded order (3: no leg). An order that
  // leaves out an axis that moves is not a path the mill can have taken: refused, not guessed at.
  Eigen::Vector3d corner = at_;
  double total = 0.0;
  for (const std::uint8_t axis : record.order) {
    if (axis < 3) {
      total += std::abs(target[axis] - corner[axis]);
      corner[axis] = target[axis];
    }
  }
  if (settings_.path == motion::MachinePath::Staircase && corner != target) {
    error = "machine target " + std::to_string(record.update) +
            " moves an axis its recorded leg order leaves out: not a staircase the mill can have moved";
    return false;
  }
  ++targets_;
  if (target == at_) {
    return true;  // a backlash take-up: the motors move, the tool does not
  }
  if (settings_.path == motion::MachinePath::Straight) {
    feed_to(target, settings_.update_s);
    return true;
  }
  corner = at_;
  for (const std::uint8_t axis : record.order) {
    if (axis < 3 && corner[axis] != target[axis]) {
      const double length = std::abs(target[axis] - corner[axis]);
      corner[axis] = target[axis];
      feed_to(corner, settings_.update_s * length / total);
    }
  }
  return true;
}

namespace {

double distance_to_segment(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double length2 = ab.squaredNorm();
  const double t = length2 > 0.0 ? std::clamp((p - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

double speed_of(const Eigen::Vector3d& from, const CutMove& move) {
  return move.seconds > 0.0 ? (move.to_mm - from).norm() / move.seconds : 0.0;
}

// Bounds the work of one merge: each extension looks at every corner it would drop.
constexpr std::size_t kMaxMergedCorners = 256;
constexpr double kOnPathMm = 1e-9;

}  // namespace

MergeResult merge_collinear(const std::vector<CutMove>& moves, const Eigen::Vector3d& start_mm,
                            const tables::PartTables& part, double tolerance_mm) {
  MergeResult result;
  const double step_mm = engine::sweep_step_mm(part);
  Eigen::Vector3d from = start_mm;
  std::size_t i = 0;
  while (i < moves.size()) {
    CutMove merged = moves[i];
    std::size_t next = i + 1;
    if (merged.kind == MoveKind::Feed) {
      const double speed = speed_of(from, merged);
      Eigen::Vector3d previous_end = merged.to_mm;
      while (next < moves.size() && moves[next].kind == MoveKind::Feed && next - i < kMaxMergedCorners) {
        const CutMove& candidate = moves[next];
        const double candidate_speed = speed_of(previous_end, candidate);
        if (std::abs(candidate_speed - speed) > 0.1 * std::max(speed, candidate_speed)) {
          break;
        }
        double deviation = 0.0;
        for (std::size_t k = i; k < next; ++k) {
          deviation = std::max(deviation, distance_to_segment(moves[k].to_mm, from, candidate.to_mm));
        }
        if (deviation > tolerance_mm) {
          break;
        }
        if (deviation > kOnPathMm) {
          const double length = (candidate.to_mm - from).norm();
          const int sub_steps = static_cast<int>(std::ceil(length / step_mm)) + 1;
          ++result.sweep_checks;
          if (engine::check_sweep(part, from, candidate.to_mm, step_mm, sub_steps).status != engine::SweepStatus::Legal) {
            break;
          }
        }
        merged.to_mm = candidate.to_mm;
        merged.seconds += candidate.seconds;
        previous_end = candidate.to_mm;
        ++result.merged_away;
        ++next;
      }
    }
    result.moves.push_back(merged);
    from = merged.to_mm;
    i = next;
  }
  return result;
}

}  // namespace stencil::gcode
