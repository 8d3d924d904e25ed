// The simulated CY545 chip itself (no I/O): receive buffer, parser, registers, busy timing, user bits,
// step pulses to the MMC-4S board, query replies. Driven on a caller-given clock; see cy545_protocol.hpp.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "hal/clock.hpp"
#include "sim/cy545/cy545_command_parser.hpp"
#include "sim/cy545/mmc4s_board.hpp"
#include "sim/cy545/move_profile.hpp"

namespace stencil::sim::cy545 {

// What the chip is doing.
enum class Activity : std::uint8_t { idle, moving, homing, delaying, waiting_for_bit };

struct Cy545Counters {
  std::int64_t bytes_received = 0;            // every byte that reached the chip's serial input
  std::int64_t bytes_before_baud_lock = 0;    // ignored: they came before the first CR
  std::int64_t bytes_dropped_while_busy = 0;  // overflowed the 3-character receive buffer
  std::int64_t malformed_lines = 0;
  std::int64_t unsupported_commands = 0;
  std::int64_t commands_executed = 0;
  std::int64_t replies = 0;
  std::int64_t steps_issued = 0;              // step pulses, whatever channel they reached
  std::int64_t home_aborts = 0;               // H gave up after 2^24 - 1 steps in one phase
};

// The last line refused, with why and where.
struct Cy545LineError {
  std::string line;      // as received, without the CR
  const char* reason = "";
  int column = 0;
  ParseStatus status = ParseStatus::malformed;
};

class Cy545Chip {
 public:
  Cy545Chip(Mmc4sBoard& board, hal::MonotonicNs start_ns);

  // Runs the executing command up to `now_ns` (steps, completion, then the buffered input). Time never
  // goes back: an earlier `now_ns` is ignored.
  void advance_to(hal::MonotonicNs now_ns);

  // One byte arriving on the serial input at `now_ns` (advance_to(now_ns) first).
  void receive(std::uint8_t byte, hal::MonotonicNs now_ns);

  // Reply bytes produced since the last call.
  [[nodiscard]] std::string take_output();

  // The reset pin: registers as after power-up, baud rate unlocked, buffers emptied. Board latches stay.
  void power_on_reset();

  // How long the chip is busy taking a command that moves nothing (ns): the manual gives no figure,
  // only that without CTS the host must wait for the chip to execute each command (chapter 16).
  // 0 (the default) where bytes arrive with no wire time (the wall-clock runner cannot know when a
  // pty's bytes left the host); FakeCy545Clock sets kCommandTimeNs, with the bytes' wire time.
  void set_command_time_ns(hal::MonotonicNs ns) { command_time_ns_ = ns; }
  static constexpr hal::MonotonicNs kCommandTimeNs = 1'000'000;  // ASSUMPTION: 1 ms, to be measured at the rig

  // Fault hook: A and P queries report the register plus this (modulo 2^24).
  void set_query_position_offset(std::int32_t steps) { query_position_offset_ = steps; }

  [[nodiscard]] hal::MonotonicNs now_ns() const { return now_ns_; }
  [[nodiscard]] Activity activity() const { return activity_; }
  [[nodiscard]] bool busy() const { return activity_ != Activity::idle; }
  [[nodiscard]] bool cts_ready() const { return !busy(); }
  [[nodiscard]] bool baud_locked() const { return baud_locked_; }
  [[nodiscard]] std::uint32_t position_register() const { return position_; }
  [[nodiscard]] std::uint32_t step_count() const { return step_count_; }
  [[nodiscard]] bool direction_positive() const { return direction_ == StepDirection::positive; }
  [[nodiscard]] std::uint32_t rate() const { return rate_; }
  [[nodiscard]] std::uint32_t first_rate() const { return first_rate_; }
  [[nodiscard]] std::uint32_t slope() const { return slope_; }
  [[nodiscard]] std::uint32_t mode() const { return mode_; }
  [[nodiscard]] std::uint8_t user_bit_latches() const { return latches_; }
  [[nodiscard]] std::uint8_t data_bus_latches() const { return data_bus_; }
  // What the user-bit pins read: the latches, bit 6 = ready, bit 1 = input mux while bit 5 is set.
  [[nodiscard]] std::uint8_t pin_levels() const;
  [[nodiscard]] int receive_buffer_bytes() const { return buffered_; }
  [[nodiscard]] const Cy545Counters& counters() const { return counters_; }
  [[nodiscard]] const std::optional<Cy545LineError>& last_error() const { return last_error_; }

 private:
  void parse_byte(std::uint8_t byte, hal::MonotonicNs at_ns);
  void parse_binary_byte(std::uint8_t byte, hal::MonotonicNs at_ns);
  void execute_line(hal::MonotonicNs at_ns);
  void execute(const Cy545Command& command, hal::MonotonicNs at_ns);
  void execute_command(const Cy545Command& command, hal::MonotonicNs at_ns);
  void apply_bit_command(std::uint32_t argument);
  void write_user_bits(std::uint8_t latches);
  void start_move(std::uint32_t steps, StepDirection direction, hal::MonotonicNs at_ns);
  void start_home(std::uint32_t bit_argument, hal::MonotonicNs at_ns);
  void issue_step(StepDirection direction);
  void finish(hal::MonotonicNs at_ns);
  void initialise_registers();
  void reply(char letter, std::uint32_t value);
  [[nodiscard]] bool bit_matches(std::uint32_t bit_argument) const;
  // Each returns true when it reached `now_ns` without finishing.
  bool run_move(hal::MonotonicNs now_ns);
  bool run_home(hal::MonotonicNs now_ns);

  Mmc4sBoard& board_;
  hal::MonotonicNs now_ns_;
  Activity activity_ = Activity::idle;
  bool baud_locked_ = false;

  // Registers.
  std::uint32_t position_ = 0;
  std::uint32_t step_count_ = 0;
  StepDirection direction_ = StepDirection::positive;
  std::uint32_t rate_ = 0;
  std::uint32_t first_rate_ = 0;
  std::uint32_t slope_ = 0;
  std::uint32_t mode_ = 0;
  std::uint8_t latches_ = 0;   // user bits 0-5 and 7 (bit 6 is the busy output)
  std::uint8_t data_bus_ = 0;

  // Serial input: the 3-character receive buffer (filled while busy) and the line being parsed.
  std::array<std::uint8_t, 3> buffer_{};
  int buffered_ = 0;
  std::string line_;

  // A command in the binary format (mode bit 7 clear): letter, count, then `count` data bytes (only
  // the first three are kept: no command of the chip takes more).
  struct Binary {
    enum class Stage : std::uint8_t { letter, count, data } stage = Stage::letter;
    char letter = 0;
    std::size_t count = 0;
    std::size_t received = 0;
    std::array<std::uint8_t, 3> data{};
  } binary_;

  // The executing command.
  struct Move {
    hal::MonotonicNs start_ns = 0;
    MoveProfile profile{0, 1, 1, 0};
    std::uint32_t steps_done = 0;
    StepDirection direction = StepDirection::positive;
  } move_;
  struct Home {
    std::uint32_t bit_argument = 0;
    bool stepping_away = false;        // the first phase: - until the bit stops matching
    hal::MonotonicNs phase_start_ns = 0;
    hal::MonotonicNs step_interval_ns = 0;
    std::uint32_t steps_in_phase = 0;
  } home_;
  hal::MonotonicNs delay_end_ns_ = 0;
  std::uint32_t wait_bit_argument_ = 0;

  std::string output_;
  std::int32_t query_position_offset_ = 0;
  hal::MonotonicNs command_time_ns_ = 0;
  Cy545Counters counters_;
  std::optional<Cy545LineError> last_error_;
};

}  // namespace stencil::sim::cy545
