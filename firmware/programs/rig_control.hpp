// `stencil-rig status|stop|reset|pause|resume|start`: a controller run as a service has no terminal,
// so what the rig's terminal takes also comes over the controller's Unix socket (the one its
// displays use, --display-socket), from a short-lived client of the same user or root.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

namespace stencil::app {

// Where the packaged service serves its displays and control commands (systemd's RuntimeDirectory).
inline constexpr const char* kServiceSocket = "/run/stencil/control.sock";

struct ControlOptions {
  std::string socket_path = kServiceSocket;
  double timeout_s = 5.0;
  CLI::App* chosen = nullptr;  // the subcommand given, or none (a job)
};

// The subcommands, each with --socket and --timeout.
void add_control_commands(CLI::App& app, ControlOptions& options);

// Connects, does the command and prints what the controller said. Exit status: 0 done (status: the
// controller answered), 1 refused by the controller, 3 no controller (or another user's).
[[nodiscard]] int run_control(const std::string& verb, const ControlOptions& options);

}  // namespace stencil::app
