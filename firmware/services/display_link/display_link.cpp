#include "firmware/services/display_link/display_link.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>

#include <fcntl.h>

#include "firmware/core/control/safe_state.hpp"
#include "firmware/core/motion/machine_frames.hpp"
#include "firmware/core/stencil/contact_query.hpp"

namespace stencil::display_link {
namespace {

// The figures go out at most this often: a display samples them at 20 Hz, and the records thread
// (thousands of records a second, far more in --fast) should not copy them for each one.
constexpr auto kPublishEvery = std::chrono::milliseconds(1);
constexpr auto kStockEvery = std::chrono::milliseconds(100);

void add(TimingHistogram& histogram, std::int64_t ns) {
  const double us = static_cast<double>(std::max<std::int64_t>(ns, 0)) / 1000.0;
  const int bin = std::min(kTimingBins - 1, static_cast<int>(us / kTimingBinUs));
  ++histogram.counts[bin];
  histogram.max_ns = std::max(histogram.max_ns, ns);
}

}  // namespace

RequestLimits limits_of(const control::ControllerConfig& config) {
  RequestLimits limits;
  limits.board_force_limit_n = config.haptic.max_force_n;
  limits.mill_speed_mm_per_s = std::min(config.max_axis_move_mm, config.max_total_move_mm) / config.period_s;
  limits.min_coupling_n_per_device_mm = config.min_coupling_n_per_device_mm;
  limits.max_coupling_n_per_device_mm = config.max_coupling_n_per_device_mm;
  limits.max_damping_n_s_per_m = config.max_damping_n_s_per_m;
  return limits;
}

void coarse_stock(const control::CommandedStock& model, FeedStock& stock) {
  StockGridHeader& grid = stock.grid;
  const std::uint64_t updates = grid.updates;
  const double lag = grid.lag_mm;
  grid = StockGridHeader{0.0, 0.0, 0.0, 0, 0, lag, updates};
  if (!model.ready() || model.columns() <= 0 || model.rows() <= 0) {
    return;
  }
  const int longer = std::max(model.columns(), model.rows());
  const int factor = std::max(1, (longer + 99) / 100);
  grid.columns = (model.columns() + factor - 1) / factor;
  grid.rows = (model.rows() + factor - 1) / factor;
  if (grid.columns * grid.rows > kStockCellsMax) {
    grid.columns = grid.rows = 0;
    return;
  }
  grid.cell_mm = model.cell_mm() * factor;
  grid.x0_mm = model.block().low_mm.x();
  grid.y0_mm = model.block().low_mm.y();
  const auto top = static_cast<float>(model.block().high_mm.z());
  std::fill_n(stock.heights_mm, grid.columns * grid.rows, top);
  // Every third model cell in each direction is enough: the narrowest cut is a tool's width, many
  // model cells wide; this keeps the sampling to about a millisecond on the machine side's thread.
  const int stride = std::max(1, factor / 3);
  for (int row = 0; row < model.rows(); row += stride) {
    for (int column = 0; column < model.columns(); column += stride) {
      float& cell = stock.heights_mm[(row / factor) * grid.columns + column / factor];
      cell = std::min(cell, static_cast<float>(model.height(column, row)));
    }
  }
}

DisplayLink::DisplayLink(const tables::PartTables& part, const control::ControllerConfig& config, DisplayLinkOptions options)
    : part_(part),
      config_(config),
      options_(std::move(options)),
      touched_(std::make_unique<engine::TriangleSet>()),
      figures_(std::make_unique<Figures>()),
      stock_(std::make_unique<FeedStock>()) {
  contact_tool_ready_ = engine::build_contact_tool(part.tool.spec, control::touch_distance_mm(config), contact_tool_);
  touched_->observe(&DisplayLink::heard_touched, this);
  control::Telemetry& t = figures_->telemetry;
  t.coupling_n_per_device_mm = config.haptic.coupling_n_per_device_mm;
  t.force_limit_n = config.haptic.max_force_n;
  t.speed_limit_mm_per_s = config.max_axis_move_mm / config.period_s;
  t.damping_n_s_per_m = config.feel.damping_n_s_per_m;
  t.friction = config.feel.friction;
  t.speed_limiting = config.feel.speed_limiting;
}

DisplayLink::~DisplayLink() { stop(); }

bool DisplayLink::start(std::string& error) {
  FeedFacts facts;
  facts.limits = limits_of(config_);
  facts.reset_rule = ResetRule{config_.still_time_s, config_.reset_distance_mm};
  facts.virtual_clock = options_.virtual_clock;
  facts.program = options_.program;
  if (!feed_.create(part_, facts, error)) {
    return false;
  }
  // Our own view of what we publish (the reset rule's telemetry); a memfd is mapped again, read-only.
  const int again = fcntl(feed_.fd(), F_DUPFD_CLOEXEC, 0);
  if (again < 0 || !own_view_.open(again, error)) {
    error = "the display feed: " + (again < 0 ? std::string(std::strerror(errno)) : error);
    return false;
  }
  publish(true);
  feed_.publish(*stock_);
  // The mill at home until its first update (machine coordinates 0).
  for (int i = 0; i < 3; ++i) {
    machine_.work_mm[i] = config_.frames.home_world_mm[i];
  }
  feed_.publish(machine_);
  RequestServerOptions server_options;
  server_options.socket_path = options_.socket_path;
  server_ = std::make_unique<RequestServer>(
      server_options, feed_.fd(), [this](const Request& request) { return decide(request); }, commands_);
  if (!server_->start(error)) {
    server_.reset();
    return false;
  }
  return true;
}

void DisplayLink::end(const std::string& how) {
  if (server_ == nullptr) {
    return;
  }
  figures_->phase = JobPhase::Ended;
  std::memset(figures_->end_text, 0, sizeof figures_->end_text);
  std::memcpy(figures_->end_text, how.data(), std::min(how.size(), sizeof figures_->end_text - 1));
  publish(true);
}

void DisplayLink::stop() {
  if (server_ != nullptr) {
    server_->stop();
    figures_->requests = server_->counters();
    server_.reset();
  }
}

std::string DisplayLink::decide(const Request& request) {
  if (request.kind == RequestKind::Set) {
    return refusal(request, own_view_.header().limits);
  }
  if (request.kind == RequestKind::Start) {
    std::uint8_t awaiting = kAwaiting;
    if (!start_wait_.compare_exchange_strong(awaiting, kStarted)) {
      return "not waiting for a start: the spindle is started once, after homing and before the cut";
    }
    return "";
  }
  if (request.kind == RequestKind::Stop) {
    // Before the cut, a stop ends the wait for the start (the run ends, nothing cut); it also goes to
    // the cycle's ring as ever, for a cycle that would run after all.
    std::uint8_t awaiting = kAwaiting;
    static_cast<void>(start_wait_.compare_exchange_strong(awaiting, kStopped));
  }
  Figures now{};
  const bool read = own_view_.read(now);
  if (read && now.phase == JobPhase::Ended) {
    return "the job has ended";
  }
  if (request.kind == RequestKind::Stop) {
    return "";  // otherwise always: in the safe state already, the cycle keeps its first reason
  }
  if (!read) {
    return "the controller is busy; try again";
  }
  if (request.kind == RequestKind::Pause || request.kind == RequestKind::Resume) {
    return pause_refusal(request.kind, now.have_telemetry != 0, now.telemetry);
  }
  return reset_refusal(now.have_telemetry != 0, now.telemetry, own_view_.header().reset_rule);
}

void DisplayLink::heard_touched(void* self, std::uint32_t id) {
  auto& link = *static_cast<DisplayLink*>(self);
  link.feed_.mark_touched(id);
  if (id < link.part_.triangle_count() && (link.part_.triangle_flags[id] & tables::kTriangleReachable) != 0) {
    ++link.figures_->reachable_touched;
  }
}

void DisplayLink::seed_touched(const engine::TriangleSet& touched) {
  for (std::uint32_t t = 0; t < part_.triangle_count(); ++t) {
    if (touched.contains(t)) {
      touched_->insert(t);
    }
  }
  figures_->touched_count = static_cast<std::uint32_t>(touched_->count());
  publish(true);
}

void DisplayLink::on_record(const control::JournalRecord& record) {
  Figures& f = *figures_;
  if (f.have_record == 0) {
    f.first_time_ns = record.time_ns;
    f.have_record = 1;
  }
  // The cycle marks the touched set at the virtual tool each cycle; where its count grew, the same
  // marking here gives the same triangles (a cycle whose count did not grow added none).
  if (record.touched_triangles > touched_->count() && contact_tool_ready_) {
    const Eigen::Vector3d tip(record.virtual_tip_mm[0], record.virtual_tip_mm[1], record.virtual_tip_mm[2]);
    static_cast<void>(engine::mark_touched(part_, contact_tool_, {tip, Eigen::Vector3d::UnitZ()},
                                           control::touch_distance_mm(config_), *touched_));
  }
  ++f.records;
  f.cycle = record.cycle;
  f.time_ns = record.time_ns;
  std::copy(std::begin(record.virtual_tip_mm), std::end(record.virtual_tip_mm), f.virtual_tip_mm);
  const Eigen::Vector3d probe =
      motion::device_to_world(config_.frames, Eigen::Vector3d(record.device_mm[0], record.device_mm[1], record.device_mm[2]));
  f.probe_mm[0] = probe.x();
  f.probe_mm[1] = probe.y();
  f.probe_mm[2] = probe.z();
  std::copy(std::begin(record.force_n), std::end(record.force_n), f.force_n);
  std::copy(std::begin(record.device_mm), std::end(record.device_mm), f.device_mm);
  const Eigen::Vector3d machine = motion::world_to_machine_mm(
      config_.frames, Eigen::Vector3d(record.virtual_tip_mm[0], record.virtual_tip_mm[1], record.virtual_tip_mm[2]));
  f.virtual_machine_mm[0] = machine.x();
  f.virtual_machine_mm[1] = machine.y();
  f.virtual_machine_mm[2] = machine.z();
  f.record_safe_reason = record.safe_reason;
  if (record.safe_reason != control::SafeReason::None && !in_safe_state_) {
    add_event(FeedEvent{record.cycle, record.time_ns, FeedEventType::SafeState, control::CommandKind::Stop,
                        record.safe_source, control::CommandOutcome::Done, record.safe_reason, {}, 0.0, 0.0});
  }
  in_safe_state_ = record.safe_reason != control::SafeReason::None;
  f.touched_count = static_cast<std::uint32_t>(touched_->count());
  const float force = std::sqrt(record.force_n[0] * record.force_n[0] + record.force_n[1] * record.force_n[1] +
                                record.force_n[2] * record.force_n[2]);
  feed_.record_force(record.cycle, force);
  publish(false);
}

void DisplayLink::on_command(const control::CommandEvent& event) {
  add_event(FeedEvent{event.cycle, event.time_ns, FeedEventType::Command, event.kind, event.source, event.outcome,
                      control::SafeReason::None, {}, event.asked, event.applied});
  publish(true);  // an operator waits to see what came of it
}

void DisplayLink::add_event(const FeedEvent& event) {
  Figures& f = *figures_;
  f.events[f.events_total % kFeedEvents] = event;
  ++f.events_total;
}

void DisplayLink::on_telemetry(const control::Telemetry& telemetry) {
  Figures& f = *figures_;
  if (f.have_telemetry != 0 && telemetry.cycle > f.telemetry.cycle + 1) {
    f.telemetry_gaps += telemetry.cycle - f.telemetry.cycle - 1;  // dropped by a full ring
  }
  add(f.wakeup, telemetry.wakeup_ns);
  if (telemetry.cycle > 1) {
    add(f.compute, telemetry.last_compute_ns);
  }
  f.telemetry = telemetry;
  f.have_telemetry = 1;
  ++f.telemetry_seen;
  publish(false);
}

void DisplayLink::on_machine(const control::MachineView& machine, const control::CommandedStock& model) {
  // The position, every update (small); the stock, at most ten times a second (large).
  ++machine_.updates;
  machine_.lag_mm = machine.lag_mm;
  std::copy(std::begin(machine.commanded_tip_mm), std::end(machine.commanded_tip_mm), machine_.work_mm);
  const Eigen::Vector3d in_machine = motion::world_to_machine_mm(
      config_.frames, Eigen::Vector3d(machine.commanded_tip_mm[0], machine.commanded_tip_mm[1], machine.commanded_tip_mm[2]));
  machine_.machine_mm[0] = in_machine.x();
  machine_.machine_mm[1] = in_machine.y();
  machine_.machine_mm[2] = in_machine.z();
  machine_.held = machine.held ? 1 : 0;
  feed_.publish(machine_);
  const double lag_mm = machine.lag_mm;
  const auto now = std::chrono::steady_clock::now();
  if (sampled_ != std::chrono::steady_clock::time_point{} && now - sampled_ < kStockEvery) {
    return;
  }
  sampled_ = now;
  coarse_stock(model, *stock_);  // on the caller's thread, which owns the model
  stock_->grid.lag_mm = lag_mm;
  ++stock_->grid.updates;
  feed_.publish(*stock_);
}

RequestCounters DisplayLink::counters() const { return server_ != nullptr ? server_->counters() : figures_->requests; }

void DisplayLink::publish(bool now) {
  if (feed_.fd() < 0) {
    return;
  }
  const auto clock = std::chrono::steady_clock::now();
  if (!now && clock - published_ < kPublishEvery) {
    return;
  }
  published_ = clock;
  if (server_ != nullptr) {
    figures_->requests = server_->counters();
  }
  feed_.publish(*figures_);
}

}  // namespace stencil::display_link
