#include "firmware/programs/display_option.hpp"

#include <chrono>
#include <cstdio>
#include <filesystem>

#ifdef STENCIL_HAVE_HMI
#include "firmware/services/hmi/hmi_server.hpp"
#else
namespace stencil::hmi {
// Built without civetweb (a cross build without the target's libcivetweb-dev, say): there is no
// server and Display's server_ stays null; this empty class only completes its type for ~Display.
class HmiServer {};
}  // namespace stencil::hmi
#endif

namespace stencil::app {
#ifdef STENCIL_HAVE_HMI
namespace {

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace
#endif

void add_display_options(CLI::App& app, DisplayOptions& options) {
  options.flag = app.add_option("--hmi", options.endpoint,
                                "serve the operator display (3-D view, status, plots, parameters) on HOST:PORT; "
                                "--hmi alone: 127.0.0.1:8080. Open http://HOST:PORT/ in a browser")
                     ->expected(0, 1);
  app.add_option("--hmi-token", options.token,
                 "needed to listen beyond loopback; only a browser that opens the page with ?token=T may change "
                 "parameters or reset (the others watch)");
  app.add_option("--hmi-assets", options.assets_dir, "the built page's folder (default: ../hmi beside the program)");
}

bool check_display_options(const DisplayOptions& options, std::string& error) {
  if (!options.requested()) {
    if (!options.token.empty() || !options.assets_dir.empty()) {
      error = "--hmi-token and --hmi-assets go with --hmi";
      return false;
    }
    return true;
  }
#ifdef STENCIL_HAVE_HMI
  hmi::HmiEndpoint endpoint;
  if (!hmi::parse_endpoint(options.endpoint, endpoint, error)) {
    error = "--hmi " + error;
    return false;
  }
  return hmi::check_access(endpoint, options.token, error);
#else
  error = "--hmi: this program was built without the display's server (civetweb: install libcivetweb-dev and rebuild)";
  return false;
#endif
}

#ifdef STENCIL_HAVE_HMI
Display::Display() = default;
Display::~Display() { stop(); }

bool Display::start(const DisplayOptions& options, const tables::PartTables& part, const control::ControllerConfig& config,
                    std::string& error) {
  if (!options.requested()) {
    return true;
  }
  hmi::HmiServerOptions server_options;
  if (!hmi::parse_endpoint(options.endpoint, server_options.endpoint, error)) {
    error = "--hmi " + error;
    return false;
  }
  server_options.token = options.token;
  server_options.virtual_clock = !config.count_overruns;  // lateness means nothing there
  server_options.assets_dir = options.assets_dir;
  if (server_options.assets_dir.empty()) {
    std::error_code ec;
    const std::filesystem::path program = std::filesystem::read_symlink("/proc/self/exe", ec);
    server_options.assets_dir = (program.parent_path().parent_path() / "hmi").string();
  }
  server_ = std::make_unique<hmi::HmiServer>(server_options, part, config);
  if (!server_->start(error)) {
    server_.reset();
    return false;
  }
  started_s_ = now_s();
  std::printf("display: %s%s\n", server_->url().c_str(),
              options.token.empty() ? "" : " (open it with ?token=... to change parameters)");
  std::fflush(stdout);
  return true;
}

void Display::stop() {
  if (server_ == nullptr) {
    return;
  }
  server_->stop();
  const hmi::HmiServerStats stats = server_->stats();
  const double seconds = std::max(now_s() - started_s_, 1e-9);
  std::printf("display: %llu frames in %.1f s (%.1f Hz), %llu messages, %.0f bytes/s to all clients; %llu frames dropped "
              "for slow clients, %llu malformed messages, %llu requests refused, %llu accepted\n",
              static_cast<unsigned long long>(stats.frames), seconds, static_cast<double>(stats.frames) / seconds,
              static_cast<unsigned long long>(stats.messages_sent), static_cast<double>(stats.bytes_sent) / seconds,
              static_cast<unsigned long long>(stats.frames_dropped), static_cast<unsigned long long>(stats.malformed),
              static_cast<unsigned long long>(stats.refused), static_cast<unsigned long long>(stats.accepted));
  server_.reset();
}

control::DisplayFeed* Display::feed() { return server_.get(); }
#else
Display::Display() = default;
Display::~Display() = default;
bool Display::start(const DisplayOptions& options, const tables::PartTables&, const control::ControllerConfig&,
                    std::string& error) {
  if (!options.requested()) {
    return true;
  }
  error = "--hmi: this program was built without the display's server (civetweb: install libcivetweb-dev and rebuild)";
  return false;
}
void Display::stop() {}
control::DisplayFeed* Display::feed() { return nullptr; }
#endif

}  // namespace stencil::app
