// A fake CY545 on a virtual clock, its mill, and a raw pty client: what every pty test starts from.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <string_view>

#include "board/sim/sim_facts.hpp"
#include "sim/cy545/fake_cy545.hpp"
#include "sim/mill/simulated_mill.hpp"
#include "tests/sim/cy545/pty_test_client.hpp"

namespace stencil::sim::cy545::test {

inline constexpr hal::MonotonicNs kMs = 1'000'000;

struct FakeCy545Bench {
  SimulatedMill mill{stencil::board::sim::kMillConfig};
  FakeCy545 fake{mill, stencil::board::sim::kMmc4sWiring, 0};
  PtyTestClient client{fake.slave_path()};
  // These tests spell out the address-latching board (cy545_protocol.hpp); the per-line one has its own.
  bool latching = [this] {
    fake.board().set_channel_latching(ChannelLatching::Address);
    return true;
  }();

  // Writes `bytes` and hands them all to the fake at its current virtual time (no time passes, however
  // the kernel splits them). False when they did not all arrive within 2 s of wall time.
  bool send(std::string_view bytes) {
    const std::int64_t target = fake.pty_counters().bytes_read + static_cast<std::int64_t>(bytes.size());
    if (!client.write_raw(bytes)) return false;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(2);
    while (fake.pty_counters().bytes_read < target && std::chrono::steady_clock::now() < deadline) {
      static_cast<void>(fake.wait_for_input(20));
      fake.step(fake.now_ns());
    }
    return fake.pty_counters().bytes_read == target;
  }

  // Sends and reads one reply line.
  std::string query(std::string_view bytes) {
    if (!send(bytes)) return "<not delivered>";
    return client.read_until_cr(2000);
  }

  void advance_ms(std::int64_t ms) { fake.advance(ms * kMs); }
  void advance_to_ns(hal::MonotonicNs at) { fake.step(at); }

  // Locks the adaptive baud rate, enables the drivers and selects `channel` (read strobe on).
  bool start_on_channel(int channel) {
    const int bits = 1 + 4 * channel + 0x20;
    return send("\r") && send("B " + std::to_string(0x40 + bits) + "\r") && send("B 7\r") && send("/B 7\r");
  }
};

}  // namespace stencil::sim::cy545::test
