// The operator display, for both controllers: --display-socket PATH serves displays (stencil-display,
// a process of its own) at a Unix socket; --hmi [HOST:PORT] does that on a private socket and
// starts a stencil-display for it (--hmi-token-file and --hmi-assets go to that display). The
// controller's process holds only the link (display_link): no web server, no browser's bytes.
#pragma once

#include <sys/types.h>

#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "firmware/core/control/controller.hpp"
#include "firmware/core/control/display_feed.hpp"
#include "firmware/core/tables/part_tables.hpp"

namespace stencil::display_link {
class DisplayLink;
}

namespace stencil::app {

struct DisplayOptions {
  std::string endpoint;    // HOST:PORT; "" with the flag alone: 127.0.0.1:8080
  std::string token_file;
  std::string assets_dir;  // "": the display's default (the page built beside it)
  std::string socket_path; // --display-socket
  CLI::Option* flag = nullptr;
  CLI::Option* socket_flag = nullptr;
  [[nodiscard]] bool hmi() const { return flag != nullptr && flag->count() > 0; }
  [[nodiscard]] bool requested() const { return hmi() || (socket_flag != nullptr && socket_flag->count() > 0); }
};

void add_display_options(CLI::App& app, DisplayOptions& options);

// Right after parsing, before anything is opened: a bad endpoint, a token file missing where one is
// needed, or --hmi-token-file without --hmi is bad input. False with the reason.
[[nodiscard]] bool check_display_options(const DisplayOptions& options, std::string& error);

// The link while a job runs, and the display process --hmi started. start() does nothing when
// neither option was given.
class Display {
 public:
  Display();
  ~Display();
  Display(const Display&) = delete;
  Display& operator=(const Display&) = delete;

  // False with the reason (a socket in use, a display that would not start); prints where the link
  // is (and, from the display, where to open it).
  [[nodiscard]] bool start(const DisplayOptions& options, const tables::PartTables& part,
                           const control::ControllerConfig& config, const std::string& program, std::string& error);
  void end(const std::string& how);  // the displays show the job ended, with its last state
  void stop();  // closes the link, ends the display --hmi started; prints what the link did
  [[nodiscard]] control::DisplayFeed* feed();
  [[nodiscard]] display_link::DisplayLink* link() { return link_.get(); }  // null: no display asked for

 private:
  std::unique_ptr<display_link::DisplayLink> link_;
  std::string private_dir_;
  pid_t child_ = -1;
};

}  // namespace stencil::app
