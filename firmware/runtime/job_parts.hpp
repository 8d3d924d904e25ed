// JobParts: what a board hands the runtime to make a job of: its haptic device, machine link and the
// link's clock, the cycle's configuration and the planner's limits (its frames and its mill), the
// stock, the journal and where a resumed job's record is. The board builds and opens them; the
// runtime builds the rest (runtime/job.hpp) and runs it.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>

#include <Eigen/Core>

#include "firmware/core/control/commanded_stock.hpp"
#include "firmware/core/control/controller.hpp"
#include "firmware/core/control/display_feed.hpp"
#include "firmware/core/motion/machine_planner.hpp"
#include "firmware/core/tables/part_tables.hpp"
#include "firmware/services/journal/journal_writer.hpp"
#include "hal/clock.hpp"
#include "hal/haptic_device.hpp"
#include "hal/machine_link.hpp"

namespace stencil::runtime {

// How a job's time passes: on threads in real time (the rig, stencil-sim --speed 1), or on one
// thread in virtual time, the cycle and the machine side taking turns (stencil-sim --fast).
enum class Timing : std::uint8_t { RealTime, Virtual };

struct JobParts {
  const tables::PartTables* part = nullptr;
  hal::HapticDevice* device = nullptr;   // what the cycle reads and drives
  hal::MachineLink* machine = nullptr;
  // The link's clock: the machine side paces on it. In real time it must be CLOCK_MONOTONIC's (the
  // periodic runner's); in virtual time it is the run's one clock.
  hal::Clock* machine_clock = nullptr;
  control::ControllerConfig controller;  // its frames are the machine side's and the journal's too
  motion::PlannerLimits planner{};
  hal::MonotonicNs period_ns = 1'000'000;  // the cycle's
  hal::MonotonicNs update_ns = 0;          // the machine side's
  hal::MonotonicNs shut_down_bound_ns = 0;  // the machine side's stop at the end of the run
  // The controller's own model of the stock, from the targets it sends, in cells this wide.
  control::StockBlock stock{};
  double model_cell_mm = 0.05;
  journal::JournalWriter* journal = nullptr;  // opened (to resume, for a resumed job); null: no record
  // A resumed job: the first resume_bytes of this journal are the job so far. The touched set and
  // the model of the stock are rebuilt from it before the machine homes; each leg it machined also
  // goes to recorded_leg when there is one (the simulation's mill cuts its stock along it).
  std::string resume_from;
  std::size_t resume_bytes = 0;
  std::function<void(const Eigen::Vector3d& from_mm, const Eigen::Vector3d& to_mm)> recorded_leg;
  // An operator display: fed by the threads around the cycle, never by the cycle; its requests go
  // into the command ring.
  control::DisplayFeed* display = nullptr;
  // Set by a signal: the run's stop goes to the cycle through its command ring.
  const std::atomic<bool>* interrupted = nullptr;
};

// An update's bound from its actual start, in updates: a move of one update's steps plus the CY545's
// commands, each with its settle (up to about 40 ms for three axes that change channel), fits in
// three; an update that outlasts its period only makes the mill fall behind (the backlog slows the
// virtual tool), never a fault.
inline constexpr int kUpdateBoundUpdates = 3;

}  // namespace stencil::runtime
