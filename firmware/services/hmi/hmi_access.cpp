#include "firmware/services/hmi/hmi_access.hpp"

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
      error = "--hmi-token: at least 8 characters";
      return false;
    }
    for (const char c : token) {
      if (c <= ' ' || c > '~' || c == '&' || c == '#' || c == '%' || c == '?') {
        error = "--hmi-token: printable ASCII only, without spaces or & # % ?";
        return false;
      }
    }
  }
  if (!is_loopback(endpoint.host) && token.empty()) {
    error = "--hmi " + endpoint.host + ": listening beyond this machine needs --hmi-token T (anyone on the network "
            "could change the force limit otherwise)";
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
