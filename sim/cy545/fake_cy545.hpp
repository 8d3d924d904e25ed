// The fake CY545 controller on a real pseudo-terminal: owns the pty master, feeds the bytes a driver
// writes to the simulated chip, writes the chip's replies back; the chip drives the MMC-4S board and the
// simulated mill. Driven by the caller's clock (step/advance); fault hooks for tests.
//
// Init-time versus run-time: the constructor and close_pty() open and close file descriptors; step()
// does non-blocking reads and writes only. Nothing here is meant for the 1 kHz cycle: this is the
// simulated far side of the serial cable. Not thread-safe: FakeCy545Runner serialises access.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "hal/clock.hpp"
#include "sim/cy545/cy545_chip.hpp"
#include "sim/cy545/mmc4s_board.hpp"
#include "sim/mill/simulated_mill.hpp"

namespace stencil::sim::cy545 {

struct PtyCounters {
  std::int64_t bytes_read = 0;           // from the driver, handed to the chip
  std::int64_t bytes_written = 0;        // to the driver: replies and injected bytes
  std::int64_t replies_suppressed = 0;   // reply bytes not sent (stop-replying fault)
  std::int64_t write_failures = 0;       // bytes the pty would not take (nobody reading)
};

class FakeCy545 {
 public:
  // Opens the pty (posix_openpt, grantpt, unlockpt, ptsname), puts it in raw mode, makes the master
  // non-blocking, and keeps a slave descriptor of its own so that the master never sees a hang-up
  // when the driver closes and reopens the slave. Throws std::system_error naming the failing call.
  // `wiring`: how the rig's MMC-4S board is wired (its board's facts), as the driver is told too.
  FakeCy545(SimulatedMill& mill, const hal::cy545::Mmc4sWiring& wiring, hal::MonotonicNs start_ns);
  ~FakeCy545();
  FakeCy545(const FakeCy545&) = delete;
  FakeCy545& operator=(const FakeCy545&) = delete;

  // The path the driver opens, e.g. /dev/pts/7.
  [[nodiscard]] const std::string& slave_path() const { return slave_path_; }

  // Runs the chip to `now_ns`, then hands it every byte waiting on the pty (arriving from `now_ns` on,
  // one byte time apart: set_byte_time_ns), then writes its replies. Call it with a non-decreasing clock.
  void set_byte_time_ns(hal::MonotonicNs ns) { byte_time_ns_ = ns; }
  void step(hal::MonotonicNs now_ns);
  void advance(hal::MonotonicNs dt_ns) { step(chip_.now_ns() + dt_ns); }
  [[nodiscard]] hal::MonotonicNs now_ns() const { return chip_.now_ns(); }

  // Blocks up to `timeout_ms` for bytes from the driver (poll on the master). False on timeout or closed.
  [[nodiscard]] bool wait_for_input(int timeout_ms) const;
  [[nodiscard]] int master_fd() const { return master_fd_; }

  [[nodiscard]] Cy545Chip& chip() { return chip_; }
  [[nodiscard]] const Cy545Chip& chip() const { return chip_; }
  [[nodiscard]] Mmc4sBoard& board() { return board_; }
  [[nodiscard]] const Mmc4sBoard& board() const { return board_; }
  [[nodiscard]] const PtyCounters& pty_counters() const { return counters_; }

  // ---- Fault injection.
  // Stop replying: commands still execute, but no reply byte is sent.
  void set_replies_suppressed(bool suppressed) { replies_suppressed_ = suppressed; }
  // Garble replies: every reply byte has its top bit flipped (what a baud-rate mismatch looks like).
  void set_replies_garbled(bool garbled) { replies_garbled_ = garbled; }
  // Send these bytes to the driver now, unasked (garbage on the line).
  void send_unsolicited(std::string_view bytes);
  // A and P queries report the position register plus `steps` (modulo 2^24): a wrong position.
  void set_reported_position_offset(std::int32_t steps) { chip_.set_query_position_offset(steps); }
  // Unplug: close the master and the fake's own slave descriptor. The driver's next read sees a
  // hang-up (0 or EIO) and its writes fail with EIO; step() then only runs the chip's clock.
  void close_pty();
  [[nodiscard]] bool pty_open() const { return master_fd_ >= 0; }

 private:
  void read_input(hal::MonotonicNs now_ns);
  void write_bytes(std::string_view bytes);
  void flush_replies();

  Mmc4sBoard board_;
  Cy545Chip chip_;
  int master_fd_ = -1;
  int own_slave_fd_ = -1;
  std::string slave_path_;
  hal::MonotonicNs byte_time_ns_ = 0;  // 0: a batch of bytes all arrives at once
  bool replies_suppressed_ = false;
  bool replies_garbled_ = false;
  PtyCounters counters_;
};

}  // namespace stencil::sim::cy545
