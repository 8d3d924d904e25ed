#include "firmware/services/hmi/hmi_access.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include <arpa/inet.h>

#include <charconv>

namespace stencil::hmi {

bool parse_endpoint(std::string_view text, HmiEndpoint& endpoint, std::string& error) {
  if (text.empty()) {
    endpoint = HmiEndpoint{};
    return true;
  }
  std::string_view host, port;
  if (text.front() == '[') {
    const std::size_t close = text.find(']');
    if (close == std::string_view::npos || close + 1 >= text.size() || text[close + 1] != ':') {
      error = "'" + std::string(text) + "': expected [IPv6]:PORT";
      return false;
    }
    host = text.substr(1, close - 1);
    port = text.substr(close + 2);
  } else {
    const std::size_t colon = text.rfind(':');
    if (colon == std::string_view::npos) {
      error = "'" + std::string(text) + "': expected HOST:PORT (for example 127.0.0.1:8080)";
      return false;
    }
    host = text.substr(0, colon);
    port = text.substr(colon + 1);
  }
  int number = -1;
  const auto [end, ec] = std::from_chars(port.data(), port.data() + port.size(), number);
  if (port.empty() || ec != std::errc{} || end != port.data() + port.size() || number < 0 || number > 65535) {
    error = "'" + std::string(text) + "': the port must be a number from 0 to 65535, not '" + std::string(port) + "'";
    return false;
  }
  std::string host_text(host);
  if (host_text == "localhost") {
    host_text = "127.0.0.1";
  }
  unsigned char address[16];
  if (host_text.empty() || (inet_pton(AF_INET, host_text.c_str(), address) != 1 &&
                            inet_pton(AF_INET6, host_text.c_str(), address) != 1)) {
    error = "'" + std::string(text) + "': the host must be a numeric IPv4 or IPv6 address or localhost, not '" +
            std::string(host) + "'";
    return false;
  }
  endpoint.host = host_text;
  endpoint.port = number;
  return true;
}

bool is_loopback(const std::string& host) {
  unsigned char address[16];
  if (inet_pton(AF_INET, host.c_str(), address) == 1) {
    return address[0] == 127;
  }
  if (inet_pton(AF_INET6, host.c_str(), address) == 1) {
    for (int i = 0; i < 15; ++i) {
      if (address[i] != 0) {
        return false;
      }
    }
    return address[15] == 1;
  }
  return host == "localhost";
}

bool check_access(const HmiEndpoint& endpoint, const std::string& token, std::string& error) {
  if (!token.empty()) {
    if (token.size() < 8) {
      error = "the token: at least 8 characters";
      return false;
    }
    for (const char c : token) {
      if (c <= ' ' || c > '~' || c == '&' || c == '#' || c == '%' || c == '?') {
        error = "the token: printable ASCII only, without spaces or & # % ?";
        return false;
      }
    }
  }
  if (!is_loopback(endpoint.host) && token.empty()) {
    error = endpoint.host + ": listening beyond this machine needs a token, from a file only its owner reads "
            "(anyone on the network could change the force limit otherwise)";
    return false;
  }
  return true;
}

bool may_control(const std::string& token, std::string_view presented) {
  if (token.empty()) {
    return true;  // only on loopback: check_access refused anything else
  }
  // Constant time in the presented token's content.
  unsigned difference = token.size() == presented.size() ? 0U : 1U;
  for (std::size_t i = 0; i < presented.size(); ++i) {
    difference |= static_cast<unsigned>(static_cast<unsigned char>(presented[i]) ^ static_cast<unsigned char>(token[i % token.size()]));
  }
  return difference == 0;
}

bool same_origin(std::string_view origin, std::string_view host) {
  for (const std::string_view scheme : {std::string_view("http://"), std::string_view("https://")}) {
    if (origin.substr(0, scheme.size()) == scheme) {
      return !host.empty() && origin.substr(scheme.size()) == host;
    }
  }
  return false;  // "null" (a file:// page, a sandboxed frame) or anything else
}

}  // namespace stencil::hmi

namespace stencil::hmi {

namespace {

// A file directly in the unit's credentials folder (systemd's guarantee: only the unit's user and root).
bool is_systemd_credential(const std::string& path) {
  const char* folder = std::getenv("CREDENTIALS_DIRECTORY");
  if (folder == nullptr || folder[0] != '/') {
    return false;
  }
  const std::string prefix = std::string(folder) + "/";
  return path.size() > prefix.size() && path.compare(0, prefix.size(), prefix) == 0 &&
         path.find('/', prefix.size()) == std::string::npos;
}

}  // namespace

bool read_token_file(const std::string& path, std::string& token, std::string& error) {
  const bool credential = is_systemd_credential(path);
  const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
  if (fd < 0) {
    error = "--token-file " + path + ": " + std::strerror(errno);
    return false;
  }
  struct stat st {};
  std::string text;
  bool ok = fstat(fd, &st) == 0;
  if (!ok || !S_ISREG(st.st_mode)) {
    error = "--token-file " + path + ": not a regular file";
    ok = false;
  } else if (credential) {
    ok = true;  // systemd's own access rule (above): nothing of the owner's or mode's to check
  } else if (st.st_uid != geteuid()) {
    error = "--token-file " + path + ": owned by uid " + std::to_string(st.st_uid) + ", not by this user (" +
            std::to_string(geteuid()) + ")";
    ok = false;
  } else if ((st.st_mode & 077) != 0) {
    char mode[8];
    std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(st.st_mode & 07777));
    error = "--token-file " + path + ": mode " + mode + " lets others read it; chmod 600 " + path;
    ok = false;
  }
  if (ok) {
    char buffer[512];
    const ssize_t got = read(fd, buffer, sizeof buffer);
    text.assign(buffer, got > 0 ? static_cast<std::size_t>(got) : 0);
  }
  close(fd);
  if (!ok) {
    return false;
  }
  const std::size_t line_end = text.find('\n');
  text = text.substr(0, line_end);
  const std::size_t first = text.find_first_not_of(" \t\r");
  const std::size_t last = text.find_last_not_of(" \t\r");
  token = first == std::string::npos ? std::string() : text.substr(first, last - first + 1);
  if (token.empty()) {
    error = "--token-file " + path + ": empty (expected the token on its first line)";
    return false;
  }
  return true;
}

}  // namespace stencil::hmi
