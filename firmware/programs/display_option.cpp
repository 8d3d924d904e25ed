#include "firmware/programs/display_option.hpp"

#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <cstdlib>
#include <filesystem>
#include <thread>
#include <vector>

#include "firmware/services/display_link/display_link.hpp"
#include "firmware/services/hmi/hmi_access.hpp"

extern char** environ;

namespace stencil::app {
namespace {

// Where --hmi's private socket goes: the user's runtime folder, else the temporary one.
std::string private_socket_dir(std::string& error) {
  const char* runtime = std::getenv("XDG_RUNTIME_DIR");
  std::string base = runtime != nullptr && runtime[0] == '/' ? runtime : std::filesystem::temp_directory_path().string();
  std::string pattern = base + "/stencil-display-XXXXXX";
  std::vector<char> text(pattern.begin(), pattern.end());
  text.push_back('\0');
  if (mkdtemp(text.data()) == nullptr) {  // mode 0700: the socket inside is this user's only
    error = "--hmi: cannot make a private folder under " + base + ": " + std::strerror(errno);
    return "";
  }
  return text.data();
}

bool child_exited(pid_t child, int& status) { return waitpid(child, &status, WNOHANG) == child; }

}  // namespace

void add_display_options(CLI::App& app, DisplayOptions& options) {
  options.flag = app.add_option("--hmi", options.endpoint,
                                "start the operator display (stencil-display, a process of its own) on HOST:PORT; "
                                "--hmi alone: 127.0.0.1:8080. Open http://HOST:PORT/ in a browser")
                     ->expected(0, 1);
  app.add_option("--hmi-token-file", options.token_file,
                 "the display's token, in a file only its owner may read (needed beyond loopback); only a browser "
                 "that opens the page with ?token=T may change parameters or reset (the others watch)");
  app.add_option("--hmi-assets", options.assets_dir, "the built page's folder, for the display (default: its own)");
  options.socket_flag = app.add_option("--display-socket", options.socket_path,
                                       "serve displays at this Unix socket (owner-only); start one with "
                                       "stencil-display --controller PATH");
}

bool check_display_options(const DisplayOptions& options, std::string& error) {
  if (!options.hmi()) {
    if (!options.token_file.empty() || !options.assets_dir.empty()) {
      error = "--hmi-token-file and --hmi-assets go with --hmi";
      return false;
    }
    return true;
  }
  if (options.socket_flag != nullptr && options.socket_flag->count() > 0) {
    error = "--hmi and --display-socket: --hmi makes a socket of its own; use one or the other";
    return false;
  }
  hmi::HmiEndpoint endpoint;
  if (!hmi::parse_endpoint(options.endpoint, endpoint, error)) {
    error = "--hmi " + error;
    return false;
  }
  if (!hmi::is_loopback(endpoint.host) && options.token_file.empty()) {
    error = "--hmi " + endpoint.host + ": listening beyond loopback needs --hmi-token-file FILE";
    return false;
  }
  return true;
}

Display::Display() = default;
Display::~Display() { stop(); }

bool Display::start(const DisplayOptions& options, const tables::PartTables& part, const control::ControllerConfig& config,
                    const std::string& program, std::string& error) {
  if (!options.requested()) {
    return true;
  }
  std::string socket_path = options.socket_path;
  if (options.hmi()) {
    private_dir_ = private_socket_dir(error);
    if (private_dir_.empty()) {
      return false;
    }
    socket_path = private_dir_ + "/display.sock";
  }
  display_link::DisplayLinkOptions link_options;
  link_options.socket_path = socket_path;
  link_options.program = program;
  link_options.virtual_clock = !config.count_overruns;  // lateness means nothing there
  link_ = std::make_unique<display_link::DisplayLink>(part, config, link_options);
  if (!link_->start(error)) {
    error = "the display link: " + error;
    link_.reset();
    return false;
  }
  std::printf("display link: %s\n", socket_path.c_str());
  std::fflush(stdout);
  if (!options.hmi()) {
    return true;
  }
  // The display beside this program, with its own options; it prints its address.
  std::error_code ec;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
  const std::string display = (self.parent_path() / "stencil-display").string();
  std::vector<std::string> arguments{display, "--controller", socket_path, "--listen",
                                     options.endpoint.empty() ? "127.0.0.1:8080" : options.endpoint};
  if (!options.token_file.empty()) {
    arguments.insert(arguments.end(), {"--token-file", options.token_file});
  }
  if (!options.assets_dir.empty()) {
    arguments.insert(arguments.end(), {"--assets", options.assets_dir});
  }
  std::vector<char*> argv;
  for (std::string& argument : arguments) {
    argv.push_back(argument.data());
  }
  argv.push_back(nullptr);
  if (posix_spawn(&child_, display.c_str(), nullptr, nullptr, argv.data(), environ) != 0) {
    child_ = -1;
    error = "--hmi: cannot start " + display + ": " + std::strerror(errno);
    return false;
  }
  // Started when it has connected; a display that exits first (a port taken, a bad token file) has
  // said why on stderr.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (link_->counters().displays_seen == 0) {
    int status = 0;
    if (child_exited(child_, status)) {
      child_ = -1;
      error = "--hmi: stencil-display did not start (" +
              (WIFEXITED(status) ? "exit " + std::to_string(WEXITSTATUS(status)) : std::string("killed")) + ")";
      return false;
    }
    if (std::chrono::steady_clock::now() > deadline) {
      error = "--hmi: stencil-display did not connect within 10 s";
      return false;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return true;
}

void Display::end(const std::string& how) {
  if (link_ != nullptr) {
    link_->end(how);
  }
}

void Display::stop() {
  if (child_ > 0) {
    // Its last frames show the job ended; then it goes.
    std::this_thread::sleep_for(std::chrono::milliseconds(150));
    kill(child_, SIGTERM);
    int status = 0;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(3);
    while (!child_exited(child_, status)) {
      if (std::chrono::steady_clock::now() > deadline) {
        kill(child_, SIGKILL);
        waitpid(child_, &status, 0);
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    child_ = -1;
  }
  if (link_ != nullptr) {
    link_->stop();
    const display_link::RequestCounters c = link_->counters();
    std::printf("display link: %llu display(s) connected, %llu requests accepted, %llu refused (%llu for coming too fast), "
                "%llu malformed, %llu peers refused\n",
                static_cast<unsigned long long>(c.displays_seen), static_cast<unsigned long long>(c.accepted),
                static_cast<unsigned long long>(c.refused + c.rate_limited), static_cast<unsigned long long>(c.rate_limited),
                static_cast<unsigned long long>(c.malformed), static_cast<unsigned long long>(c.peers_refused));
    std::fflush(stdout);
    link_.reset();
  }
  if (!private_dir_.empty()) {
    std::error_code ec;
    std::filesystem::remove_all(private_dir_, ec);
    private_dir_.clear();
  }
}

control::DisplayFeed* Display::feed() { return link_.get(); }

}  // namespace stencil::app
