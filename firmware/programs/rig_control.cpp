#include "firmware/programs/rig_control.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <thread>
#include <vector>

#include "firmware/core/control/safe_state.hpp"
#include "firmware/services/display_link/controller_client.hpp"
#include "firmware/services/display_link/message_codec.hpp"

namespace stencil::app {
namespace {

using display_link::ControllerClient;
using display_link::LinkState;
using display_link::Message;
using display_link::MessageKind;

constexpr int kExitRefused = 1;
constexpr int kExitNoController = 3;

struct Verb {
  const char* name;
  MessageKind kind;  // Hello: status (nothing sent)
  const char* help;
};
constexpr Verb kVerbs[] = {
    {"status", MessageKind::Hello, "print the running job's state: cycle, safe state and its source, pause, the mill's position"},
    {"stop", MessageKind::Stop, "the safe state now: no force, the mill held and stopped (as the terminal's 'stop'); "
                                "before the cut, the end of the wait for 'start' with nothing cut"},
    {"reset", MessageKind::Reset, "leave the safe state (taken only with the handle held still near the tool)"},
    {"pause", MessageKind::Pause, "feed hold: the tool and the mill held where they are"},
    {"resume", MessageKind::Resume, "carry on after a pause"},
    {"start", MessageKind::Start, "turn the spindle on once homed (as the terminal's 'start'; the cut begins)"},
};

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void print_status(const display_link::FeedView& feed) {
  const display_link::FeedHeader& header = feed.header();
  display_link::Figures f{};
  display_link::FeedMachine m{};
  bool read = false;
  for (int attempt = 0; attempt < 100 && !read; ++attempt) {  // a writer mid-publication: read again
    read = feed.read(f) && feed.read(m);
  }
  std::printf("controller: %.*s (pid %u)\n", static_cast<int>(sizeof header.program), header.program, header.controller_pid);
  if (!read) {
    std::printf("state: busy (its figures are being written); ask again\n");
    return;
  }
  if (f.phase == display_link::JobPhase::Ended) {
    std::printf("job: ended: %.*s\n", static_cast<int>(sizeof f.end_text), f.end_text);
  } else if (f.have_record == 0) {
    std::printf("job: not cutting yet (homing, or waiting for 'start': stencil-rig start)\n");
  } else {
    std::printf("job: running, cycle %llu, %.1f s\n", static_cast<unsigned long long>(f.cycle),
                static_cast<double>(f.time_ns - f.first_time_ns) * 1e-9);
  }
  if (f.have_telemetry != 0) {
    const control::Telemetry& t = f.telemetry;
    if (t.safe_reason == control::SafeReason::None) {
      std::printf("safe state: none%s\n", t.paused ? "; PAUSED (feed hold)" : "");
    } else {
      std::printf("safe state: %s (from %s): no force, the mill held and stopped\n", control::safe_reason_name(t.safe_reason),
                  control::command_source_name(t.safe_source));
    }
    std::printf("force: %.2f N; coupling %.2f N/device mm, force limit %.2f N\n",
                std::sqrt(t.force_n[0] * t.force_n[0] + t.force_n[1] * t.force_n[1] + t.force_n[2] * t.force_n[2]),
                t.coupling_n_per_device_mm, t.force_limit_n);
  } else if (f.have_record != 0) {
    std::printf("safe state: %s\n", f.record_safe_reason == control::SafeReason::None
                                        ? "none"
                                        : control::safe_reason_name(f.record_safe_reason));
  }
  if (f.have_record != 0) {
    std::printf("tool: (%.3f, %.3f, %.3f) mm world\n", f.virtual_tip_mm[0], f.virtual_tip_mm[1], f.virtual_tip_mm[2]);
  }
  std::printf("mill: %llu updates, work (%.3f, %.3f, %.3f) mm, machine (%.3f, %.3f, %.3f) mm, lag %.3f mm%s\n",
              static_cast<unsigned long long>(m.updates), m.work_mm[0], m.work_mm[1], m.work_mm[2], m.machine_mm[0],
              m.machine_mm[1], m.machine_mm[2], m.lag_mm, m.held != 0 ? ", held" : "");
  std::printf("touched: %u of %u triangles; displays connected: %llu\n", f.touched_count, header.triangle_count,
              static_cast<unsigned long long>(f.requests.displays_connected));
}

}  // namespace

void add_control_commands(CLI::App& app, ControlOptions& options) {
  for (const Verb& verb : kVerbs) {
    CLI::App* command = app.add_subcommand(verb.name, std::string(verb.help) + " (over the controller's socket)");
    command->add_option("--socket", options.socket_path,
                        "the controller's socket: its --display-socket (the service's: /run/stencil/control.sock)")
        ->capture_default_str();
    command->add_option("--timeout", options.timeout_s, "seconds to wait for the controller's answer")
        ->check(CLI::Range(0.1, 60.0))
        ->capture_default_str();
    command->callback([&options, command] { options.chosen = command; });
  }
}

int run_control(const std::string& verb, const ControlOptions& options) {
  MessageKind kind = MessageKind::Hello;
  for (const Verb& v : kVerbs) {
    if (verb == v.name) {
      kind = v.kind;
    }
  }
  ControllerClient client(options.socket_path, /*control=*/true);
  std::vector<Message> answers;
  const auto start = std::chrono::steady_clock::now();
  while (client.state() != LinkState::Connected && client.state() != LinkState::Refused &&
         seconds_since(start) < options.timeout_s) {
    client.poll(answers, 20);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  if (client.state() != LinkState::Connected || client.feed() == nullptr) {
    const std::string hint = client.state() == LinkState::Waiting
                                 ? " (is the controller running with --display-socket here? the service's socket takes "
                                   "only its own user and root: sudo stencil-rig " + verb + ")"
                                 : "";
    std::string detail = client.detail();
    const std::size_t waiting = detail.rfind(": waiting for one");
    if (waiting != std::string::npos) {
      detail.erase(waiting);  // the display's patience, not a command's
    }
    std::fprintf(stderr, "stencil-rig %s: %s%s\n", verb.c_str(), detail.c_str(), hint.c_str());
    return kExitNoController;
  }
  if (kind == MessageKind::Hello) {
    print_status(*client.feed());
    return 0;
  }
  Message request = display_link::make_message(kind, 1);
  if (!client.send(request)) {
    std::fprintf(stderr, "stencil-rig %s: the controller went away before it took the request\n", verb.c_str());
    return kExitNoController;
  }
  answers.clear();
  while (answers.empty() && client.state() == LinkState::Connected && seconds_since(start) < options.timeout_s) {
    client.poll(answers, 20);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  for (const Message& answer : answers) {
    if (answer.id != request.id) {
      continue;
    }
    if (static_cast<MessageKind>(answer.kind) == MessageKind::Accepted) {
      std::printf("stencil-rig %s: accepted by the controller%s\n", verb.c_str(),
                  kind == MessageKind::Reset ? " (the cycle's reset rule has the last word: see stencil-rig status)" : "");
      return 0;
    }
    std::fprintf(stderr, "stencil-rig %s: refused: %s\n", verb.c_str(), display_link::reason_of(answer).c_str());
    return kExitRefused;
  }
  std::fprintf(stderr, "stencil-rig %s: no answer from the controller within %.1f s (%s)\n", verb.c_str(),
               options.timeout_s, client.detail().c_str());
  return kExitNoController;
}

}  // namespace stencil::app
