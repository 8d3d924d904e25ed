// stencil-display: the operator display, a process of its own. It serves the page to browsers and
// talks to one controller (stencil-sim or stencil-rig) through that controller's Unix socket only:
// whatever a browser does, the controller's process never sees a byte of it.
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <thread>

#include <CLI/CLI.hpp>

#include "firmware/services/report/build_version.hpp"
#include "firmware/services/report/installed_files.hpp"
#include "firmware/services/hmi/display_app.hpp"

namespace {

volatile sig_atomic_t g_stop = 0;
extern "C" void on_signal(int /*signal*/) { g_stop = 1; }

constexpr int kExitOk = 0;
constexpr int kExitBadInput = 2;
constexpr int kExitCannotServe = 3;

}  // namespace

int main(int argc, char** argv) {
  using namespace stencil;
  CLI::App app{
      "stencil-display: the operator display (3-D view, status, plots, parameters) for one controller, in a browser.\n"
      "Start the controller with --display-socket PATH (or let its --hmi start this program for it), then:\n"
      "  stencil-display --controller PATH [--listen HOST:PORT] [--token-file FILE]\n"
      "and open http://HOST:PORT/ (with ?token=T to change parameters or reset). A display started before\n"
      "its controller waits for it; killed and started again, it shows the job again from the feed.",
      "stencil-display"};
  app.set_version_flag("--version", report::version_text("stencil-display"));
  std::string controller, listen = "127.0.0.1:8080", token_file, assets;
  int max_clients = 16, max_connections = 64;
  app.add_option("--controller", controller, "the controller's display socket (it prints 'display link: PATH')")->required();
  app.add_option("--listen", listen, "where browsers reach it: HOST:PORT (port 0: any free one)")->capture_default_str();
  app.add_option("--token-file", token_file,
                 "a file only its owner may read, holding the token on its first line (needed beyond loopback; "
                 "for a service: systemd's LoadCredential=). Only a browser that opens the page with ?token=T "
                 "may change parameters or reset; the others watch");
  app.add_option("--assets", assets, "the built page's folder (default: share/stencil/page beside an installed program, else the build's hmi/)");
  app.add_option("--max-clients", max_clients, "browsers watching at once")->check(CLI::Range(1, 256))->capture_default_str();
  app.add_option("--max-connections", max_connections, "sockets open at once; more are closed at once")
      ->check(CLI::Range(2, 1024))
      ->capture_default_str();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }

  hmi::DisplayAppOptions options;
  options.controller_socket = controller;
  std::string error;
  if (!hmi::parse_endpoint(listen, options.web.endpoint, error)) {
    std::fprintf(stderr, "stencil-display: --listen %s\n", error.c_str());
    return kExitBadInput;
  }
  if (!token_file.empty() && !hmi::read_token_file(token_file, options.web.token, error)) {
    std::fprintf(stderr, "stencil-display: %s\n", error.c_str());
    return kExitBadInput;
  }
  if (!hmi::check_access(options.web.endpoint, options.web.token, error)) {
    std::fprintf(stderr, "stencil-display: %s%s\n", error.c_str(), token_file.empty() ? " (give it with --token-file FILE)" : "");
    return kExitBadInput;
  }
  if (assets.empty()) {
    assets = report::page_folder();
  }
  options.web.assets_dir = assets;
  options.web.max_clients = max_clients;
  options.web.max_connections = max_connections;

  struct sigaction action {};
  action.sa_handler = on_signal;
  for (const int signal_number : {SIGINT, SIGTERM, SIGHUP}) {
    sigaction(signal_number, &action, nullptr);
  }
  signal(SIGPIPE, SIG_IGN);

  hmi::DisplayApp display(options);
  if (!display.start(error)) {
    std::fprintf(stderr, "stencil-display: %s\n", error.c_str());
    return kExitCannotServe;
  }
  std::printf("display: %s%s (pid %d, controller %s)\n", display.url().c_str(),
              options.web.token.empty() ? "" : " (open it with ?token=... to change parameters)", static_cast<int>(getpid()),
              controller.c_str());
  std::printf("display: the page from %s\n", assets.c_str());
  std::fflush(stdout);
  const auto started = std::chrono::steady_clock::now();
  while (g_stop == 0) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  display.stop();
  const hmi::WebServerStats s = display.web_stats();
  const hmi::DisplayCounters c = display.counters();
  const double seconds = std::max(1e-9, std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());
  std::printf("display: %llu frames in %.1f s (%.1f Hz), %llu messages, %.0f bytes/s to all clients; %llu frames dropped "
              "for slow clients, %llu connections refused, %llu clients dropped, %llu malformed messages, %llu requests "
              "refused, %llu accepted\n",
              static_cast<unsigned long long>(s.ticks), seconds, static_cast<double>(s.ticks) / seconds,
              static_cast<unsigned long long>(s.messages_sent), static_cast<double>(s.bytes_sent) / seconds,
              static_cast<unsigned long long>(s.frames_dropped), static_cast<unsigned long long>(s.connections_refused),
              static_cast<unsigned long long>(s.clients_dropped), static_cast<unsigned long long>(s.malformed + c.malformed),
              static_cast<unsigned long long>(c.refused), static_cast<unsigned long long>(c.accepted));
  return kExitOk;
}
