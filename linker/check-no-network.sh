#!/usr/bin/env bash
# A controller's process faces no network: its executable links no HTTP or WebSocket library
# (ldd) and holds no web server's code (nm: civetweb, Boost.Beast/Asio, libwebsockets) and no JSON
# parser (nlohmann's parse: the controllers only write JSON). Prints each finding; exit 1 on any.
#   check-no-network.sh PROGRAM...
set -euo pipefail
status=0
for program in "$@"; do
  if [ ! -r "$program" ]; then
    echo "check-no-network: cannot read $program" >&2
    exit 2
  fi
  libraries=$(ldd "$program" | grep -Ei 'civetweb|websockets|boost|microhttpd|libcurl|libssl' || true)
  if [ -n "$libraries" ]; then
    echo "$program links a network library:"; echo "$libraries"
    status=1
  fi
  symbols=$(nm -C "$program" | grep -E ' mg_start| mg_websocket|boost::beast|boost::asio|lws_|nlohmann::.*::parse|nlohmann::.*parser' | head -5 || true)
  if [ -n "$symbols" ]; then
    echo "$program holds a web server's or a JSON parser's code:"; echo "$symbols"
    status=1
  fi
  [ "$status" -eq 0 ] && echo "$program: no network library, no web server, no JSON parser"
done
exit "$status"
