// stencil-display's web server (Boost.Beast) over real sockets, driven by raw POSIX clients so
// that each bound can be attacked as a hostile client would: the page and the two documents served
// and nothing else, the WebSocket only for this server's own page, hello then a snapshot then
// frames in order, replies, and each limit holding while a good client keeps getting its frames: a
// frame header declaring 2 GiB, sockets beyond max_connections, a slow-loris sender, a client that
// stops reading, and 200 sockets with 50 slow senders among them.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "firmware/services/hmi/web_server.hpp"

// CppUTest last: its leak-detector macros redefine new for what follows.
#include <CppUTest/TestHarness.h>
#include <CppUTest/MemoryLeakWarningPlugin.h>

using namespace stencil::hmi;
using Clock = std::chrono::steady_clock;

namespace {

// A folder with the page's files, removed at the end.
struct Assets {
  std::filesystem::path dir = std::filesystem::temp_directory_path() / ("web-server-tests-" + std::to_string(::getpid()));
  Assets() {
    std::filesystem::create_directories(dir / "sub");
    std::ofstream(dir / "index.html") << "<html>the page</html>";
    std::ofstream(dir / "app.js") << "console.log(1);";
    std::ofstream(dir / "sub" / "secret.txt") << "not served";
  }
  ~Assets() { std::filesystem::remove_all(dir); }
};

// The display's side: numbered frames and snapshots (a frame `frame_padding` bytes longer, to fill
// a stalled client's socket), hello naming may_control, every text message echoed.
struct Display {
  std::atomic<std::uint64_t> sequence{0};
  std::atomic<int> snapshots_asked{0};
  std::size_t frame_padding = 0;
  WebServer* server = nullptr;  // for a late reply

  WebHandlers handlers() {
    WebHandlers h;
    h.tick = [this](bool snapshot_wanted, std::string& frame, std::string& snapshot) {
      const std::string seq = std::to_string(++sequence);
      frame = R"({"type":"frame","seq":)" + seq + R"(,"pad":")" + std::string(frame_padding, 'x') + "\"}";
      if (snapshot_wanted) {
        ++snapshots_asked;
        snapshot = R"({"type":"snapshot","seq":)" + seq + "}";
      }
    };
    h.on_message = [this](ClientId client, bool may_control, std::string_view text) -> std::string {
      if (text == "late") {
        server->send(client, R"({"type":"late"})");
        return {};
      }
      return R"({"type":"reply","may_control":)" + std::string(may_control ? "true" : "false") + R"(,"text":")" +
             std::string(text) + "\"}";
    };
    h.hello = [](bool may_control) {
      return R"({"type":"hello","may_control":)" + std::string(may_control ? "true" : "false") + "}";
    };
    h.part = [] { return std::string(R"({"triangles":24})"); };
    h.status = [] { return std::string(); };  // not yet known: 503
    return h;
  }
};

WebServerOptions options_for(const Assets& assets) {
  WebServerOptions options;
  options.endpoint = {"127.0.0.1", 0};
  options.assets_dir = assets.dir.string();
  return options;
}

int connect_to(int port, int receive_buffer = 0) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  CHECK(fd >= 0);
  if (receive_buffer > 0) {
    setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &receive_buffer, sizeof receive_buffer);
  }
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<std::uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  CHECK(::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) == 0);
  return fd;
}

bool send_all(int fd, const std::string& bytes) {
  return ::send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL) == static_cast<ssize_t>(bytes.size());
}

// Up to `size` bytes within the deadline: 0 closed (or reset), -1 timed out.
ssize_t receive(int fd, char* data, std::size_t size, Clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
  pollfd p{fd, POLLIN, 0};
  if (left <= 0 || ::poll(&p, 1, static_cast<int>(left)) <= 0) {
    return -1;
  }
  const ssize_t n = ::recv(fd, data, size, 0);
  return n < 0 ? 0 : n;
}

bool receive_exactly(int fd, char* data, std::size_t size, Clock::time_point deadline) {
  for (std::size_t got = 0; got < size;) {
    const ssize_t n = receive(fd, data + got, size - got, deadline);
    if (n <= 0) {
      return false;
    }
    got += static_cast<std::size_t>(n);
  }
  return true;
}

// Whether the server closed the socket within `seconds` (anything it sends first is read past).
bool closed_within(int fd, double seconds) {
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  char buffer[65536];
  for (;;) {
    const ssize_t n = receive(fd, buffer, sizeof buffer, deadline);
    if (n == 0) {
      return true;
    }
    if (n < 0) {
      return false;
    }
  }
}

// One HTTP/1.1 request over a plain socket; the whole answer (the server closes after it).
std::string http(int port, const std::string& request) {
  const int fd = connect_to(port);
  CHECK(send_all(fd, request));
  std::string answer;
  char buffer[4096];
  const auto deadline = Clock::now() + std::chrono::seconds(2);
  for (ssize_t n; (n = receive(fd, buffer, sizeof buffer, deadline)) > 0;) {
    answer.append(buffer, static_cast<std::size_t>(n));
  }
  ::close(fd);
  return answer;
}

std::string get(int port, const std::string& path) {
  return http(port, "GET " + path + " HTTP/1.1\r\nHost: localhost\r\n\r\n");
}

std::string upgrade_request(int port, const std::string& target, const std::string& origin) {
  const std::string host = "127.0.0.1:" + std::to_string(port);
  return "GET " + target + " HTTP/1.1\r\nHost: " + host + "\r\n" + (origin.empty() ? "" : "Origin: " + origin + "\r\n") +
         "Upgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
         "Sec-WebSocket-Version: 13\r\n\r\n";
}

std::string own_origin(int port) { return "http://127.0.0.1:" + std::to_string(port); }

// A client frame (always masked, as RFC 6455 wants) whose header may declare more than it carries.
std::string client_frame(int opcode, const std::string& payload, std::uint64_t declared) {
  std::string out;
  out.push_back(static_cast<char>(0x80 | opcode));
  if (declared < 126) {
    out.push_back(static_cast<char>(0x80 | declared));
  } else if (declared <= 0xFFFF) {
    out.push_back(static_cast<char>(0x80 | 126));
    out.push_back(static_cast<char>(declared >> 8));
    out.push_back(static_cast<char>(declared & 0xFF));
  } else {
    out.push_back(static_cast<char>(0x80 | 127));
    for (int shift = 56; shift >= 0; shift -= 8) {
      out.push_back(static_cast<char>((declared >> shift) & 0xFF));
    }
  }
  const char mask[4] = {0x11, 0x22, 0x33, 0x44};
  out.append(mask, 4);
  for (std::size_t i = 0; i < payload.size(); ++i) {
    out.push_back(static_cast<char>(payload[i] ^ mask[i % 4]));
  }
  return out;
}

// A WebSocket over a raw socket, read on the test's thread.
struct RawWebSocket {
  int fd = -1;
  std::string status;  // the handshake answer's first line

  RawWebSocket(int port, const std::string& target, const std::string& origin, int receive_buffer = 0) {
    fd = connect_to(port, receive_buffer);
    CHECK(send_all(fd, upgrade_request(port, target, origin)));
    std::string head;
    const auto deadline = Clock::now() + std::chrono::seconds(2);
    char c;
    // Byte by byte, so that no frame after the header is taken with it.
    while (head.find("\r\n\r\n") == std::string::npos && receive(fd, &c, 1, deadline) == 1) {
      head.push_back(c);
    }
    status = head.substr(0, head.find("\r\n"));
  }
  ~RawWebSocket() { ::close(fd); }
  RawWebSocket(const RawWebSocket&) = delete;
  RawWebSocket& operator=(const RawWebSocket&) = delete;

  [[nodiscard]] bool open() const { return status.find(" 101 ") != std::string::npos; }

  void send_text(const std::string& text) const { CHECK(send_all(fd, client_frame(0x1, text, text.size()))); }

  // The next text message; "" on close, timeout or anything but text.
  std::string next(double seconds = 2.0) const {
    const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
    for (;;) {
      unsigned char header[2];
      if (!receive_exactly(fd, reinterpret_cast<char*>(header), 2, deadline)) {
        return {};
      }
      std::uint64_t length = header[1] & 0x7F;
      const int extra = length == 126 ? 2 : length == 127 ? 8 : 0;
      if (extra > 0) {
        unsigned char bytes[8];
        if (!receive_exactly(fd, reinterpret_cast<char*>(bytes), static_cast<std::size_t>(extra), deadline)) {
          return {};
        }
        length = 0;
        for (int i = 0; i < extra; ++i) {
          length = (length << 8) | bytes[i];
        }
      }
      std::string payload(length, '\0');
      if (length > 0 && !receive_exactly(fd, payload.data(), payload.size(), deadline)) {
        return {};
      }
      const int opcode = header[0] & 0x0F;
      if (opcode == 0x1) {
        return payload;
      }
      if (opcode == 0x8) {
        return {};
      }
      // A ping or pong: read on.
    }
  }
};

std::string type_of(const std::string& message) {
  const std::size_t at = message.find(R"("type":")");
  return at == std::string::npos ? std::string() : message.substr(at + 8, message.find('"', at + 8) - at - 8);
}

std::uint64_t seq_of(const std::string& message) {
  const std::size_t at = message.find(R"("seq":)");
  return at == std::string::npos ? 0 : std::stoull(message.substr(at + 6));
}

// A client's frames read so far: how many, and whether every frame followed the message before it
// (a frame or a snapshot one less): never a frame on top of a gap.
struct Frames {
  int count = 0;
  bool in_order = true;
  std::uint64_t last = 0;  // the last frame's or snapshot's sequence
};

// Reads on for `seconds`.
void read_frames(const RawWebSocket& client, double seconds, Frames& out) {
  std::uint64_t& last = out.last;
  const auto until = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  while (Clock::now() < until) {
    const std::string message = client.next(0.5);
    const std::string type = type_of(message);
    if (type == "snapshot") {
      last = seq_of(message);
    } else if (type == "frame") {
      out.in_order = out.in_order && last != 0 && seq_of(message) == last + 1;
      last = seq_of(message);
      ++out.count;
    } else if (message.empty()) {
      out.in_order = false;  // closed, or nothing for half a second
      break;
    }
  }
}

Frames read_frames(const RawWebSocket& client, double seconds) {
  Frames out;
  read_frames(client, seconds, out);
  return out;
}

// This process's resident set (the server runs in it), kB.
long resident_kb() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmRSS:", 0) == 0) {
      return std::stol(line.substr(6));
    }
  }
  return -1;
}

template <class Predicate>
bool eventually(Predicate predicate, double seconds) {
  const auto until = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  while (!predicate()) {
    if (Clock::now() > until) {
      return false;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

}  // namespace

// The server's thread allocates beside the test's, which CppUTest's leak detector does not take:
// it is off here, and the ASan preset's LeakSanitizer checks these tests instead.
TEST_GROUP(WebServer) {
  void setup() override { MemoryLeakWarningPlugin::saveAndDisableNewDeleteOverloads(); }
  void teardown() override { MemoryLeakWarningPlugin::restoreNewDeleteOverloads(); }
};

TEST(WebServer, RefusesToStartWithoutThePageBeyondLoopbackWithoutATokenOrOnATakenPort) {
  Assets assets;
  Display display;
  std::string error;
  WebServerOptions options = options_for(assets);
  options.assets_dir = "/nonexistent/hmi";
  WebServer no_page(options, display.handlers());
  CHECK_FALSE(no_page.start(error));
  STRCMP_CONTAINS("not built: no /nonexistent/hmi/index.html", error.c_str());
  options = options_for(assets);
  options.endpoint = {"0.0.0.0", 0};
  WebServer open(options, display.handlers());
  CHECK_FALSE(open.start(error));
  STRCMP_CONTAINS("needs a token", error.c_str());
  // A port some other socket listens on: named, with the system's reason.
  const int taken = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  CHECK(::bind(taken, reinterpret_cast<sockaddr*>(&address), sizeof address) == 0 && ::listen(taken, 1) == 0);
  socklen_t length = sizeof address;
  ::getsockname(taken, reinterpret_cast<sockaddr*>(&address), &length);
  options = options_for(assets);
  options.endpoint.port = ntohs(address.sin_port);
  WebServer busy(options, display.handlers());
  CHECK_FALSE(busy.start(error));
  STRCMP_CONTAINS(("127.0.0.1:" + std::to_string(options.endpoint.port)).c_str(), error.c_str());
  STRCMP_CONTAINS("in use", error.c_str());
  ::close(taken);
  busy.stop();  // never started: nothing to do, twice
  busy.stop();
}

TEST(WebServer, ServesThePageAndItsDocumentsAndNothingElse) {
  Assets assets;
  Display display;
  WebServer server(options_for(assets), display.handlers());
  std::string error;
  CHECK_TEXT(server.start(error), error.c_str());
  const int port = server.port();
  CHECK(port > 0);
  STRCMP_EQUAL(("http://127.0.0.1:" + std::to_string(port) + "/").c_str(), server.url().c_str());
  const std::string page = get(port, "/");
  STRCMP_CONTAINS("HTTP/1.1 200 OK", page.c_str());
  STRCMP_CONTAINS("<html>the page</html>", page.c_str());
  STRCMP_CONTAINS("Content-Type: text/html; charset=utf-8", page.c_str());
  STRCMP_CONTAINS("Cache-Control: no-store", page.c_str());
  STRCMP_CONTAINS("X-Content-Type-Options: nosniff", page.c_str());
  STRCMP_CONTAINS("Content-Security-Policy: default-src 'self'", page.c_str());
  STRCMP_CONTAINS("Connection: close", page.c_str());
  STRCMP_CONTAINS("text/javascript", get(port, "/app.js?v=2").c_str());
  const std::string head = http(port, "HEAD /app.js HTTP/1.1\r\nHost: x\r\n\r\n");
  STRCMP_CONTAINS("Content-Length: 15", head.c_str());
  CHECK(head.find("console.log") == std::string::npos);
  const std::string part = get(port, "/api/part");
  STRCMP_CONTAINS("200 OK", part.c_str());
  STRCMP_CONTAINS(R"({"triangles":24})", part.c_str());
  STRCMP_CONTAINS("503", get(port, "/api/status").c_str());
  STRCMP_CONTAINS("404", get(port, "/sub/secret.txt").c_str());
  STRCMP_CONTAINS("404", get(port, "/../../etc/passwd").c_str());
  STRCMP_CONTAINS("404", get(port, "/%2e%2e/etc/passwd").c_str());
  STRCMP_CONTAINS("405", http(port, "POST / HTTP/1.1\r\nHost: x\r\nContent-Length: 0\r\n\r\n").c_str());
  // A header past the size bound is refused, and the server goes on.
  const std::string refused = http(port, "GET / HTTP/1.1\r\nHost: x\r\nX-Pad: " + std::string(20000, 'a') + "\r\n\r\n");
  CHECK(refused.find("200 OK") == std::string::npos);
  STRCMP_CONTAINS("200 OK", get(port, "/").c_str());
  CHECK(eventually([&] { return server.stats().connections == 0; }, 1.0));
  server.stop();
  server.stop();  // twice is harmless
}

TEST(WebServer, OnlyThisServersOwnPageMayOpenAWebSocketWhileThereIsRoom) {
  Assets assets;
  Display display;
  WebServerOptions options = options_for(assets);
  options.max_clients = 1;
  WebServer server(options, display.handlers());
  std::string error;
  CHECK_TEXT(server.start(error), error.c_str());
  const int port = server.port();
  const RawWebSocket no_origin(port, "/ws", "");
  STRCMP_CONTAINS("403", no_origin.status.c_str());
  const RawWebSocket foreign(port, "/ws", "http://evil.example");
  STRCMP_CONTAINS("403", foreign.status.c_str());
  const RawWebSocket elsewhere(port, "/app.js", own_origin(port));
  STRCMP_CONTAINS("403", elsewhere.status.c_str());
  const RawWebSocket first(port, "/ws", own_origin(port));
  CHECK_TEXT(first.open(), first.status.c_str());
  const RawWebSocket second(port, "/ws", own_origin(port));
  STRCMP_CONTAINS("503", second.status.c_str());
  CHECK_EQUAL(4U, server.stats().connections_refused);
  CHECK_EQUAL(1U, server.stats().clients);
}

TEST(WebServer, AClientGetsHelloThenASnapshotThenFramesInOrderAndItsReplies) {
  Assets assets;
  Display display;
  WebServerOptions options = options_for(assets);
  options.token = "s3cret-token";
  WebServer server(options, display.handlers());
  display.server = &server;
  std::string error;
  CHECK_TEXT(server.start(error), error.c_str());
  const int port = server.port();
  const RawWebSocket watcher(port, "/ws", own_origin(port));
  const RawWebSocket operator_(port, "/ws?token=s3cret%2Dtoken", own_origin(port));
  CHECK_TEXT(watcher.open(), watcher.status.c_str());
  CHECK_TEXT(operator_.open(), operator_.status.c_str());
  STRCMP_EQUAL(R"({"type":"hello","may_control":false})", watcher.next().c_str());
  STRCMP_EQUAL(R"({"type":"hello","may_control":true})", operator_.next().c_str());
  const std::string snapshot = watcher.next();
  STRCMP_EQUAL("snapshot", type_of(snapshot).c_str());
  Frames frames;
  frames.last = seq_of(snapshot);
  read_frames(watcher, 0.5, frames);
  CHECK(frames.in_order);
  CHECK(frames.count >= 5);  // 20 Hz for half a second is 10
  watcher.send_text("hi");
  std::string answer;
  while (type_of(answer = watcher.next()) == "frame" || type_of(answer) == "snapshot") {
  }
  STRCMP_EQUAL(R"({"type":"reply","may_control":false,"text":"hi"})", answer.c_str());
  operator_.send_text("late");  // answered by send(), from inside the handler
  while (type_of(answer = operator_.next()) == "frame" || type_of(answer) == "snapshot") {
  }
  STRCMP_EQUAL(R"({"type":"late"})", answer.c_str());
  // A binary message is answered and counted; the client stays.
  CHECK(send_all(watcher.fd, client_frame(0x2, "\x01\x02", 2)));
  while (type_of(answer = watcher.next()) == "frame" || type_of(answer) == "snapshot") {
  }
  STRCMP_EQUAL(R"({"type":"error","error":"expected one text message of JSON"})", answer.c_str());
  CHECK(read_frames(watcher, 0.2).count > 0);
  const WebServerStats stats = server.stats();
  CHECK_EQUAL(2U, stats.messages_received);
  CHECK_EQUAL(1U, stats.malformed);
  CHECK_EQUAL(2U, stats.clients);
  CHECK(stats.snapshots_sent >= 2);
  CHECK(stats.ticks >= 10);
  server.stop();
  CHECK(closed_within(watcher.fd, 1.0));
  CHECK_EQUAL(0U, server.stats().clients);
}

TEST(WebServer, AFrameHeaderDeclaringTwoGibibytesClosesOnlyThatClientAndAllocatesNothingForIt) {
  Assets assets;
  Display display;
  WebServer server(options_for(assets), display.handlers());
  std::string error;
  CHECK_TEXT(server.start(error), error.c_str());
  const int port = server.port();
  const RawWebSocket good(port, "/ws", own_origin(port));
  CHECK(good.open());
  STRCMP_EQUAL("hello", type_of(good.next()).c_str());
  const long before_kb = resident_kb();
  const RawWebSocket attacker(port, "/ws", own_origin(port));
  CHECK(attacker.open());
  CHECK(send_all(attacker.fd, client_frame(0x1, std::string(60000, 'a'), 2ULL << 30)));
  CHECK(closed_within(attacker.fd, 1.0));  // at once, not after some timeout
  // Counted just after the socket is closed, on the server's thread.
  CHECK(eventually([&] { return server.stats().malformed == 1 && server.stats().clients == 1; }, 0.5));
  const Frames frames = read_frames(good, 0.5);
  CHECK(frames.in_order);
  CHECK(frames.count >= 5);
  const long grown_kb = resident_kb() - before_kb;
  std::printf("\n  2 GiB frame header: resident set grew %ld kB\n", grown_kb);
  CHECK(grown_kb < 10 * 1024);
}

TEST(WebServer, SocketsBeyondMaxConnectionsAreClosedAtOnce) {
  Assets assets;
  Display display;
  WebServerOptions options = options_for(assets);
  options.max_connections = 4;
  WebServer server(options, display.handlers());
  std::string error;
  CHECK_TEXT(server.start(error), error.c_str());
  const int port = server.port();
  std::vector<int> held;
  for (int i = 0; i < 4; ++i) {
    held.push_back(connect_to(port));
  }
  CHECK(eventually([&] { return server.stats().connections == 4; }, 1.0));
  for (int i = 0; i < 3; ++i) {
    const int excess = connect_to(port);
    CHECK(closed_within(excess, 0.5));
    ::close(excess);
  }
  CHECK_EQUAL(3U, server.stats().connections_refused);
  for (const int fd : held) {
    ::close(fd);
  }
  CHECK(eventually([&] { return server.stats().connections == 0; }, 1.0));
  STRCMP_CONTAINS("200 OK", get(port, "/").c_str());
}

TEST(WebServer, ASlowLorisSenderIsDroppedAfterTheHeaderTimeout) {
  Assets assets;
  Display display;
  WebServerOptions options = options_for(assets);
  options.header_timeout_ms = 500;
  WebServer server(options, display.handlers());
  std::string error;
  CHECK_TEXT(server.start(error), error.c_str());
  const int port = server.port();
  const int slow = connect_to(port);
  const std::string request = "GET / HTTP/1.1\r\nHost: localhost\r\nX-Slow: " + std::string(100, 'a') + "\r\n\r\n";
  const auto start = Clock::now();
  bool cut = false;
  char byte;
  // One byte each 100 ms: the whole header would take 12 s.
  for (std::size_t i = 0; i < request.size() && !cut; ++i) {
    cut = !send_all(slow, request.substr(i, 1)) || receive(slow, &byte, 1, Clock::now() + std::chrono::milliseconds(100)) == 0;
  }
  const double after_s = std::chrono::duration<double>(Clock::now() - start).count();
  ::close(slow);
  CHECK(cut);
  CHECK(after_s > 0.4 && after_s < 1.5);
  CHECK(eventually([&] { return server.stats().clients_dropped == 1; }, 0.5));
  STRCMP_CONTAINS("200 OK", get(port, "/").c_str());
}

TEST(WebServer, AClientThatStopsReadingIsDroppedAfterTheWriteTimeoutWhileAnotherKeepsItsFrames) {
  Assets assets;
  Display display;
  WebServerOptions options = options_for(assets);
  options.write_timeout_ms = 500;
  display.frame_padding = 200'000;  // a stalled socket fills within a frame or two
  WebServer server(options, display.handlers());
  std::string error;
  CHECK_TEXT(server.start(error), error.c_str());
  const int port = server.port();
  const RawWebSocket good(port, "/ws", own_origin(port));
  const RawWebSocket stalled(port, "/ws", own_origin(port), 4096);
  CHECK(good.open() && stalled.open());
  const auto start = Clock::now();
  Frames frames;
  bool dropped = false;
  // The good client reads on; the stalled one never does.
  while (Clock::now() - start < std::chrono::seconds(2)) {
    read_frames(good, 0.1, frames);
    dropped = dropped || server.stats().clients == 1;
  }
  const WebServerStats stats = server.stats();
  std::printf("\n  stalled client: good client's frames over 2 s %d; %llu frames dropped, %llu clients dropped\n",
              frames.count, static_cast<unsigned long long>(stats.frames_dropped),
              static_cast<unsigned long long>(stats.clients_dropped));
  CHECK(dropped);
  CHECK_EQUAL(1U, stats.clients_dropped);
  CHECK(frames.in_order);
  CHECK(frames.count >= 25);  // 20 Hz over 2 s is 40, less its snapshots
}

TEST(WebServer, UnderAFloodOfSocketsAndSlowSendersTheDisplayKeepsItsFrames) {
  Assets assets;
  Display display;
  WebServerOptions options = options_for(assets);
  options.header_timeout_ms = 1000;
  WebServer server(options, display.handlers());
  std::string error;
  CHECK_TEXT(server.start(error), error.c_str());
  const int port = server.port();
  const RawWebSocket good(port, "/ws", own_origin(port));
  CHECK(good.open());
  const long before_kb = resident_kb();
  // 200 sockets at once against max_connections 64; the first 50 send one header byte each 100 ms.
  std::vector<int> flood;
  for (int i = 0; i < 200; ++i) {
    flood.push_back(connect_to(port));
  }
  std::atomic<bool> done{false};
  std::thread slow_senders([&] {
    while (!done) {
      for (int i = 0; i < 50; ++i) {
        static_cast<void>(send_all(flood[static_cast<std::size_t>(i)], "G"));
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  });
  Frames frames;
  read_frames(good, 1.5, frames);
  done = true;
  slow_senders.join();
  const long grown_kb = resident_kb() - before_kb;
  const WebServerStats stats = server.stats();
  std::printf("\n  flood: good client's frames over 1.5 s %d; %llu refused, %llu dropped; resident set grew %ld kB\n",
              frames.count, static_cast<unsigned long long>(stats.connections_refused),
              static_cast<unsigned long long>(stats.clients_dropped), grown_kb);
  for (const int fd : flood) {
    ::close(fd);
  }
  CHECK(frames.in_order);
  CHECK(frames.count >= 22);  // 15 Hz over 1.5 s
  CHECK(stats.connections_refused >= 200 - 63);
  CHECK(stats.clients_dropped >= 50);  // every slow sender cut at its header timeout
  CHECK(grown_kb < 20 * 1024);
}
