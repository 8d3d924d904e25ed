// What crosses between a controller (stencil-sim, stencil-rig) and its displays (stencil-display),
// and nothing else: the controller's process parses no HTTP, no JSON and no WebSocket frame.
//
//  - Requests, over a Unix-domain socket in the controller's run folder (owner-only): fixed-size,
//    versioned Messages both ways. A display says Hello; the controller answers Welcome with the
//    state feed's file descriptor (SCM_RIGHTS), or Mismatch naming both versions. Then Set, Reset,
//    Stop, Pause and Resume, each answered Accepted or Refused (with the reason) and echoing the
//    display's id. Start (the spindle, once homed) is the confirmation the rig's terminal also takes.
//  - The state feed: a sealed memfd the display maps read-only. A FeedHeader written once at
//    start-up (the part's mesh, the limits), then Figures and the stock behind seqlocks, the touched
//    set as bits that are only ever set, and each cycle's force in a ring. The controller's threads
//    write it without ever waiting for a reader; a display that comes late reads the whole state.
#pragma once

#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "firmware/core/control/cycle_messages.hpp"
#include "firmware/services/display_link/request_rules.hpp"
#include "firmware/services/display_link/seqlock.hpp"

namespace stencil::display_link {

// Any change to a Message or to the feed's layout changes this.
inline constexpr std::uint16_t kProtocolVersion = 4;  // 4: the wall's feel (damping, friction, speed limiting)

// ---- the request channel ----

inline constexpr std::uint32_t kMessageMagic = 0x4B4C4453;  // "SDLK" on the wire (little-endian)
inline constexpr std::size_t kReasonBytes = 160;
inline constexpr std::uint8_t kHelloDisplay = 0;
inline constexpr std::uint8_t kHelloControl = 1;

enum class MessageKind : std::uint8_t {
  Hello = 1,     // display -> controller, first; its parameter says who: 0 a display, 1 a control
                 // command (stencil-rig stop, ...), whose requests are recorded as from `control`
  Set = 2,       // display -> controller: parameter, value
  Reset = 3,     // display -> controller
  Stop = 4,      // display -> controller: never rate-limited
  Pause = 5,     // display -> controller: feed hold
  Resume = 6,    // display -> controller
  Start = 7,     // `stencil-rig start` (or any client of the link) -> controller: the spindle on, once
                 // homed (the terminal's 'start'); refused unless the program is waiting for it
  Welcome = 16,  // controller -> display, with the feed's descriptor
  Accepted = 17,
  Refused = 18,  // reason: why
  Mismatch = 19, // version: the controller's; reason: both named. The connection closes.
};

struct Message {
  std::uint32_t magic;
  std::uint16_t version;
  std::uint8_t kind;       // MessageKind
  std::uint8_t parameter;  // Set: Parameter; Hello: 0 a display, 1 a control command; else 0
  std::uint32_t id;        // the display's request number, echoed in the answer
  std::uint32_t reserved;  // 0
  double value;            // Set: the value asked; else 0
  char reason[kReasonBytes];  // Refused, Mismatch: NUL-terminated; else all zero
};
static_assert(std::is_trivially_copyable_v<Message>);
inline constexpr std::size_t kMessageBytes = sizeof(Message);
static_assert(kMessageBytes == 184);

// ---- the state feed ----

inline constexpr std::uint32_t kFeedMagic = 0x44465453;  // "STFD"
inline constexpr int kStockCellsMax = 101 * 101;         // hmi's coarse grid: at most ~100 cells a side
inline constexpr std::uint32_t kForceRing = 2048;         // cycles of force magnitude: 2 s at 1 kHz
inline constexpr int kTimingBins = 51;                    // 10 us bins to 500 us, the last everything longer
inline constexpr double kTimingBinUs = 10.0;

struct TimingHistogram {
  std::uint64_t counts[kTimingBins];
  std::int64_t max_ns;
};

// What the request server did, for the display to show and the controller to report.
struct RequestCounters {
  std::uint64_t displays_connected;  // now
  std::uint64_t displays_seen;       // ever
  std::uint64_t accepted;
  std::uint64_t refused;             // well formed, but the limits or the reset rule say no
  std::uint64_t rate_limited;        // refused for coming too fast
  std::uint64_t malformed;           // not a Message: the connection is closed
  std::uint64_t peers_refused;       // another user's process, or too many displays
};

enum class JobPhase : std::uint8_t { Running = 0, Ended = 1 };

// The event list: the newest kFeedEvents of the commands the cycle took and the safe states it entered.
inline constexpr std::uint32_t kFeedEvents = 32;
enum class FeedEventType : std::uint8_t { Command = 0, SafeState = 1 };
struct FeedEvent {
  std::uint64_t cycle;
  std::int64_t time_ns;
  FeedEventType type;
  control::CommandKind kind;        // Command
  control::CommandSource source;    // both: where it came from
  control::CommandOutcome outcome;  // Command
  control::SafeReason reason;       // SafeState
  std::uint8_t pad[3];
  double asked, applied;            // a parameter's, its command's unit
};

// Everything but the stock and the touched set, as of the newest record the records thread drained.
struct Figures {
  std::uint64_t records;          // drained so far
  std::int64_t first_time_ns;     // the first record's
  std::uint64_t cycle;            // the newest record's
  std::int64_t time_ns;
  double virtual_tip_mm[3];       // world
  double probe_mm[3];             // the device's tip in world
  double device_mm[3];            // the device's tip, device space (the newest record's)
  double virtual_machine_mm[3];   // the virtual tool in machine coordinates (mm from home)
  float force_n[3];
  control::SafeReason record_safe_reason;
  std::uint8_t have_record;
  std::uint8_t have_telemetry;
  JobPhase phase;
  control::Telemetry telemetry;   // the newest
  std::uint64_t telemetry_seen, telemetry_gaps;
  TimingHistogram wakeup, compute;
  std::uint32_t touched_count;    // the mirror's
  std::uint32_t reachable_touched;
  RequestCounters requests;
  char end_text[160];             // Ended: how the job ended
  std::uint64_t events_total;     // ever; the newest kFeedEvents are in events[total % kFeedEvents]
  FeedEvent events[kFeedEvents];
};

// The mill as the machine thread left it at its newest update.
struct FeedMachine {
  std::uint64_t updates;
  double lag_mm;
  double work_mm[3];     // the last target sent: the tool tip in the part's (work) coordinates
  double machine_mm[3];  // the same in machine coordinates (mm from home)
  std::uint8_t held;     // the operator's feed hold is on at the link
  std::uint8_t pad[7];
};

struct StockGridHeader {
  double x0_mm, y0_mm, cell_mm;
  std::int32_t columns, rows;     // columns * rows <= kStockCellsMax
  double lag_mm;                  // the machine side's newest lag
  std::uint64_t updates;
};
struct FeedStock {
  StockGridHeader grid;
  float heights_mm[kStockCellsMax];  // row-major from the block's low corner; the lowest height sampled
};

// Written once, before the descriptor is handed to anyone; then only read.
struct FeedHeader {
  std::uint32_t magic;
  std::uint16_t version;
  std::uint16_t reserved;
  std::uint64_t total_bytes;
  // The sizes the writer was built with: a reader built otherwise refuses the feed.
  std::uint32_t header_bytes, figures_bytes, stock_bytes, telemetry_bytes, machine_bytes, pad2;
  std::uint64_t job_id;           // the controller's start, ns: a display tells a new job from the same
  std::uint32_t controller_pid;
  char program[32];               // "stencil-sim"
  std::uint8_t virtual_clock;     // loop timing is 0 by construction
  std::uint8_t pad[3];
  RequestLimits limits;
  ResetRule reset_rule;
  // The part: triangle_count triangles of 9 floats (mm), a flags byte each (tables' flags), and the
  // touched set's bits, one a triangle.
  std::uint32_t triangle_count, reachable_triangle_count;
  double tool_diameter_mm;
  double workspace_mm[3];
  std::uint64_t mesh_offset, flags_offset, touched_offset, force_ring_offset;
  std::uint64_t figures_offset, stock_offset, machine_offset;
};

// The feed's regions, laid out from a triangle count (both sides compute it; the reader checks it
// against the header).
struct FeedLayout {
  std::uint64_t mesh_offset, flags_offset, touched_offset, force_ring_offset, figures_offset, stock_offset,
      machine_offset, total_bytes;
};
[[nodiscard]] FeedLayout feed_layout(std::uint32_t triangle_count);

using FiguresCell = Seqlock<Figures>;
using StockCell = Seqlock<FeedStock>;
using MachineCell = Seqlock<FeedMachine>;
// The newest cycle whose force is in the ring, and the ring: entry cycle % kForceRing, bits of a float.
struct ForceRing {
  std::uint64_t newest_cycle;
  std::uint32_t force_bits[kForceRing];
};

}  // namespace stencil::display_link
