// The mill behind MachineLink: a CY545 stepper controller on an MMC-4S multiplexer board, over
// RS-232. One motor channel is driven at a time; each machine update is turned into, per axis that
// moves (in the target's order):
//
//   B <40H + 1 + 4c>H   drivers on, output-mux address c (the axis's motor channel)
//   B 7  /  /B 7        write strobe up and down: the board latches channel c
//   N <steps>           the step count of this leg
//   + or -              its direction
//   G                   go; the chip is busy for steps / rate seconds and reads nothing meanwhile
//
// Start-up: "I", "O 128" (ASCII commands: bit 7 of the mode register; "O 0" would put the chip
// into binary mode, manual chapter 9), the rates, then every output to its safe value: spindle off
// and drivers off, whatever a previous run left latched on the MMC-4S board (its latches survive a
// program's restart and the chip's "I"). stop() does the same whatever fault is latched (a fault
// says the line misbehaved, not that the chip is deaf) and confirms it with "? B".
//
// The chip has a three-character input buffer and ignores input while a move runs, so nothing is
// sent before the previous move is known to be over: on a real port CTS holds the bytes (the chip
// drops CTS while busy); on either port the driver waits the move's computed time, then asks "? P"
// and sends carriage returns until the answer comes (the three characters fit the buffer even if
// the chip is still busy; see wait_free), which also checks every step was made. Homing: per axis, select the channel, put its home switch on the input line (B <61H + 4c>H:
// read strobe on, input address c), then step in short legs, reading the switch ("? B", bit 1)
// between them (see Cy545Config): not the chip's H command, which seeks for as long as it takes
// while the chip reads nothing, so that neither a stop nor a bound can reach it. The chip keeps one
// position register for every channel; the driver tracks it (relative moves add to it) and
// compares it with "? P" in verify().
//
// Rates are given to the chip in steps per second (R, F), as the simulated CY545 takes them; the
// real chip takes an index into its rate table: a rig build must convert (not done: no rig here).
#pragma once

#include <array>
#include <cstdint>
#include <string_view>

#include "hal/clock.hpp"
#include "hal/cy545/cy545_commands.hpp"
#include "hal/cy545/mmc4s_wiring.hpp"
#include "hal/cy545/serial_port.hpp"
#include "hal/machine_link.hpp"

namespace stencil::hal::cy545 {

// What the rig's mill can follow and how far its homing may run, in its motor steps: facts of the rig
// too, which its board passes in. No defaults here.
struct Cy545Motion {
  std::uint32_t step_rate;     // steps/s of every move (R and F: no ramp)
  double update_period_s;      // one machine update: a move that takes longer is refused
  // Homing, per axis: the switch read first (closed: leave it), then an approach in chunks of
  // homing_chunk_steps at homing_rate with the switch read after each, until it closes (or
  // homing_travel_steps: a fault), then a slow departure one step at a time at homing_slow_rate
  // until it reads open homing_debounce_reads times in a row: that edge is home.
  std::uint32_t homing_rate;          // steps/s
  std::uint32_t homing_slow_rate;     // steps/s for the last, edge-finding steps
  std::int32_t homing_chunk_steps;    // how far the approach may run into the switch
  // The departure turns the backlash before the axis moves: at most a leg plus this many steps.
  std::int32_t homing_slack_steps;
  std::int32_t homing_travel_steps;     // the longest approach of one axis
  std::int32_t home_switch_zone_steps;  // the switch's closed zone: a switch still closed this far out is miswired
  // The axes in the order they home (0 x, 1 y, 2 z). Z first: after a crash or a stop mid-cut the tool
  // may stand in the stock, and only raising it first takes it out without ploughing sideways.
  std::array<std::uint8_t, 3> homing_order;
};

// The driver's configuration: the rig's wiring and motion (given), and the driver's own timing.
struct Cy545Config {
  constexpr Cy545Config(const Mmc4sWiring& rig_wiring, const Cy545Motion& rig_motion)
      : wiring(rig_wiring), motion(rig_motion) {}

  Mmc4sWiring wiring;
  Cy545Motion motion;
  int homing_debounce_reads = 3;             // equal reads in a row that settle the switch's state
  MonotonicNs reply_timeout_ns = 50'000'000; // a query's answer
  MonotonicNs pace_margin_ns = 5'000'000;    // beyond its computed time a move is overdue (+ reply_timeout: a fault)
  MonotonicNs probe_interval_ns = 1'000'000; // carriage returns while waiting for "? P" to be answered
  int start_attempts = 20;                   // carriage returns and queries at start-up
  // After each command, before the next: with no CTS handshake the host must give the chip time to
  // execute a command before it sends more (manual, chapter 16). The next command's first three
  // bytes wait in the chip's buffer, so a settle s covers an execution time up to s + 4 byte times
  // (0.69 ms at 57600 baud): 0.5 ms covers 1.2 ms. The manual gives no figure: measure it at the rig.
  MonotonicNs command_settle_ns = 500'000;
};

class Cy545Link final : public MachineLink {
 public:
  Cy545Link(SerialPort& port, Clock& clock, const Cy545Config& config);

  MachineResult start(MonotonicNs deadline_ns) override;
  void abort_on(const std::atomic<bool>* flag) override { abort_ = flag; }
  [[nodiscard]] MonotonicNs homing_bound_ns() const override;
  MachineResult home(MonotonicNs deadline_ns) override;
  MachineResult declare_home(MonotonicNs deadline_ns) override;
  MachineResult move(const MachineTarget& target, MonotonicNs deadline_ns) override;
  MachineResult verify(MonotonicNs deadline_ns) override;
  MachineResult set_spindle(bool on, MonotonicNs deadline_ns) override;
  MachineResult keep_alive(MonotonicNs deadline_ns) override;
  void hold() override;
  void resume() override;
  MachineResult stop(MonotonicNs deadline_ns) override;
  [[nodiscard]] MachineStatus status() const override;
  [[nodiscard]] std::array<int, 3> home_approach() const override { return {1, 1, 1}; }

  // What the last stop() achieved: the chip answered "? B" with the driver enable low after the
  // spindle-off and drivers-off commands (true), or it could not be confirmed (false: the reason is
  // in last_error(); cut the mill's power).
  [[nodiscard]] bool outputs_confirmed_off() const { return outputs_confirmed_off_; }

  // For tests and the fault report: the last reply's bytes that did not parse, and why.
  [[nodiscard]] const char* last_error() const { return last_error_; }

 private:
  void latch_fault(MachineFault fault);
  MachineResult fail(MachineFault fault);
  [[nodiscard]] MachineResult refuse(MachineRefusal refusal) const;
  // Sends one command once the chip is free; false (fault latched) when the port fails.
  bool send(const CommandBytes& command, MonotonicNs deadline_ns);
  bool send_bits(std::uint8_t code, MonotonicNs deadline_ns);
  bool latch(MonotonicNs deadline_ns);  // write strobe up and down
  bool select_channel(std::uint8_t channel, MonotonicNs deadline_ns);
  // A motor channel's line latched on (data 1) or off (data 0), the drivers on.
  bool latch_motor_line(std::uint8_t channel, bool on, MonotonicNs deadline_ns);
  // A move or seek was sent: the chip is busy for at least shortest_ns and at most longest_ns.
  void started_running(MonotonicNs shortest_ns, MonotonicNs longest_ns);
  // Waits until the chip has answered that it is free and where it is (see the .cpp), but not past
  // the deadline; a wrong position or no answer by the move's longest time is a fault.
  bool wait_free(MonotonicNs deadline_ns);
  bool write_bytes(std::string_view bytes, MonotonicNs deadline_ns);
  // Spindle off, then bits 0-5 low (drivers off), then "? B" to confirm: whatever is latched, on the
  // port directly (no fault is latched by it). False with last_error() saying what failed.
  bool force_outputs_off(MonotonicNs deadline_ns);
  // Sends "? B" and carriage returns until the chip answers (it can only answer once it is free):
  // the user-bit levels it reports, or false by the deadline.
  bool read_user_bits_when_free(std::uint8_t& levels, MonotonicNs deadline_ns);
  bool query(char letter, std::uint32_t& value, MonotonicNs deadline_ns);
  enum class SwitchReading : std::uint8_t { Open, Closed, Bouncing, Failed };
  // The selected home input read `reads` times: Open or Closed when all agree.
  SwitchReading read_home_switch(std::size_t axis, MonotonicNs deadline_ns, int reads);
  // One homing leg on the selected channel: `steps` (signed) at `rate`, then waits for the chip.
  bool homing_leg(std::size_t axis, std::int32_t steps, std::uint32_t rate, MonotonicNs deadline_ns);
  bool home_axis(std::size_t axis, MonotonicNs deadline_ns);
  // +1 or -1: how the chip's '+' moves this axis (Mmc4sWiring::step_direction; anything else is +1).
  [[nodiscard]] std::int64_t chip_sign(std::size_t axis) const { return config_.wiring.step_direction[axis] < 0 ? -1 : 1; }
  [[nodiscard]] bool abort_asked() const { return abort_ != nullptr && abort_->load(std::memory_order_relaxed); }
  MachineResult aborted(MonotonicNs deadline_ns);

  SerialPort& port_;
  Clock& clock_;
  Cy545Config config_;
  MachineState state_ = MachineState::Closed;
  MachineState before_hold_ = MachineState::Closed;
  MachineFault fault_ = MachineFault::None;
  std::array<std::int32_t, 3> commanded_{};
  std::uint32_t position_register_ = 0;  // what "? P" must answer (24 bits)
  int selected_channel_ = -1;            // the channel the address bits and drivers are set for, -1 not
  int motor_line_on_ = -1;               // the motor channel whose line the board has latched on, -1 none
  bool spindle_on_ = false;
  bool drivers_on_ = false;
  bool homed_ = false;
  bool outputs_confirmed_off_ = false;
  const std::atomic<bool>* abort_ = nullptr;
  std::uint32_t rate_sent_ = 0;  // the R the chip holds (0: unknown)
  bool heartbeat_level_ = false;
  int homing_input_ = -1;  // while homing: the input-mux port the read strobe must show
  MonotonicNs heartbeat_due_ns_ = 0;
  MonotonicNs quiet_until_ns_ = 0;  // no command before this: the chip may still execute the last
  MonotonicNs busy_until_ns_ = 0;  // the running move's shortest end
  MonotonicNs busy_bound_ns_ = 0;  // its longest
  bool running_ = false;           // a move or seek was sent and not yet confirmed over
  std::uint64_t moves_done_ = 0;
  std::uint64_t bytes_sent_ = 0;
  std::uint64_t bytes_received_ = 0;
  char last_error_[320] = {};
};

}  // namespace stencil::hal::cy545
