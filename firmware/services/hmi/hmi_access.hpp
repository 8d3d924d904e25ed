// Where the operator display listens and who may change anything through it: --hmi HOST:PORT and
// --hmi-token T. Plain functions, so the rules are tested without a socket.
#pragma once

#include <string>
#include <string_view>

namespace stencil::hmi {

struct HmiEndpoint {
  std::string host = "127.0.0.1";
  int port = 8080;
};

// "HOST:PORT", "[v6]:PORT" or "" (the default, 127.0.0.1:8080). False with `error` naming what was
// wrong (the port must be 1-65535, or 0 for any free one; the host a numeric address or localhost).
[[nodiscard]] bool parse_endpoint(std::string_view text, HmiEndpoint& endpoint, std::string& error);

// 127.0.0.0/8, ::1 and localhost: only this machine can reach it.
[[nodiscard]] bool is_loopback(const std::string& host);

// Binding anywhere but loopback needs a token; a token is at least 8 characters, printable, no
// spaces. False with the reason.
[[nodiscard]] bool check_access(const HmiEndpoint& endpoint, const std::string& token, std::string& error);

// Whether a client that presented `presented` may change parameters or ask for a reset: on loopback
// with no token set, anyone on this machine may; with a token set, only who presents it (compared
// in constant time). Everyone else watches.
[[nodiscard]] bool may_control(const std::string& token, std::string_view presented);

// Whether a WebSocket's Origin header ("http://127.0.0.1:8080") names the server's own Host header
// ("127.0.0.1:8080"): the page that opened it is this server's, not another site's.
[[nodiscard]] bool same_origin(std::string_view origin, std::string_view host);

}  // namespace stencil::hmi

namespace stencil::hmi {

// The token from a file (its first line, without surrounding blanks) that only its owner, this
// user, may read or write: a token never comes from the command line or the environment, where
// other users' `ps` and /proc would see it. For a service, systemd's LoadCredential= gives the file
// in $CREDENTIALS_DIRECTORY, which systemd makes readable by the unit's user and root only (owned by
// root with an ACL, so its mode shows the ACL's mask): a file there is taken as it is.
// False with the reason (missing, another user's, readable by others, empty).
[[nodiscard]] bool read_token_file(const std::string& path, std::string& token, std::string& error);

}  // namespace stencil::hmi
