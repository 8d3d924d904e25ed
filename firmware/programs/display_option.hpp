// --hmi, --hmi-token and --hmi-assets for both programs: the operator display's server, started
// before the job and stopped after it.
#pragma once

#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "firmware/core/control/controller.hpp"
#include "firmware/core/control/display_feed.hpp"
#include "firmware/core/tables/part_tables.hpp"

namespace stencil::hmi {
class HmiServer;
}

namespace stencil::app {

struct DisplayOptions {
  std::string endpoint;    // HOST:PORT; "" with the flag alone: 127.0.0.1:8080
  std::string token;
  std::string assets_dir;  // "": the page built beside the program (<bin>/../hmi)
  CLI::Option* flag = nullptr;
  [[nodiscard]] bool requested() const { return flag != nullptr && flag->count() > 0; }
};

void add_display_options(CLI::App& app, DisplayOptions& options);

// Right after parsing, before anything is opened: a bad endpoint or token (or --hmi-token without
// --hmi) is bad input. False with the reason.
[[nodiscard]] bool check_display_options(const DisplayOptions& options, std::string& error);

// The display's server while a job runs. start() does nothing when --hmi was not given.
class Display {
 public:
  Display();
  ~Display();
  Display(const Display&) = delete;
  Display& operator=(const Display&) = delete;

  // False with the reason (a bad endpoint or token, no page built, the port taken, or a program
  // built without civetweb); prints where to open it.
  [[nodiscard]] bool start(const DisplayOptions& options, const tables::PartTables& part,
                           const control::ControllerConfig& config, std::string& error);
  void stop();  // prints the frames, bytes and drops it served
  [[nodiscard]] control::DisplayFeed* feed();

 private:
  std::unique_ptr<hmi::HmiServer> server_;
  double started_s_ = 0.0;
};

}  // namespace stencil::app
