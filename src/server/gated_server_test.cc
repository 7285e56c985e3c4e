// The connection gate under hostile clients (loopback only, bounded in count and time): idle and slow
// connections do not starve the health route, the connection limit sheds the oldest idle connection or refuses
// with 503, bad framing headers get 4xx, and a huge JSON body is refused without holding memory.
#include "server.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

// After every Eigen include (server.h): httplib pulls in <resolv.h>, whose `_res` macro breaks Eigen's headers.
#include "gated_server.h"

namespace lidarshop::server {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// A connected loopback socket (blocking), or -1.
int Connect(int port) {
  const int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (fd < 0 || connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0) {
    if (fd >= 0) close(fd);
    return -1;
  }
  return fd;
}

void SendAll(int fd, const std::string& bytes) {
  size_t sent = 0;
  while (sent < bytes.size()) {
    const ssize_t n = send(fd, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) return;
    sent += static_cast<size_t>(n);
  }
}

// What the server sends on `fd` until it closes, the response is complete (by Content-Length) or `timeout_s`.
std::string Receive(int fd, double timeout_s) {
  std::string received;
  const Clock::time_point start = Clock::now();
  char chunk[65536];
  for (;;) {
    const size_t header_end = received.find("\r\n\r\n");
    if (header_end != std::string::npos) {
      const size_t length_at = received.find("Content-Length: ");
      if (length_at != std::string::npos && length_at < header_end &&
          received.size() >= header_end + 4 + std::stoul(received.substr(length_at + 16))) {
        return received;
      }
    }
    const int left_ms = static_cast<int>(1000 * (timeout_s - SecondsSince(start)));
    if (left_ms <= 0) return received;
    pollfd entry{fd, POLLIN, 0};
    if (poll(&entry, 1, left_ms) <= 0) return received;
    const ssize_t n = recv(fd, chunk, sizeof(chunk), 0);
    if (n <= 0) return received;
    received.append(chunk, static_cast<size_t>(n));
  }
}

// One request on a new connection; the response (empty when none came within `timeout_s`).
std::string Exchange(int port, const std::string& request, double timeout_s = 5) {
  const int fd = Connect(port);
  if (fd < 0) return "";
  SendAll(fd, request);
  std::string response = Receive(fd, timeout_s);
  close(fd);
  return response;
}

std::string Health() { return "GET /api/health HTTP/1.1\r\nHost: test\r\n\r\n"; }

// True when the server closes `fd` within `timeout_s` (the client reads the end of the stream).
bool ClosedWithin(int fd, double timeout_s) {
  pollfd entry{fd, POLLIN, 0};
  if (poll(&entry, 1, static_cast<int>(1000 * timeout_s)) != 1) return false;
  char byte;
  return recv(fd, &byte, 1, MSG_DONTWAIT) == 0;
}

bool RaiseFileLimit(rlim_t wanted) {
  rlimit limit{};
  if (getrlimit(RLIMIT_NOFILE, &limit) != 0) return false;
  if (limit.rlim_cur >= wanted) return true;
  limit.rlim_cur = std::min(wanted, limit.rlim_max);
  return setrlimit(RLIMIT_NOFILE, &limit) == 0 && limit.rlim_cur >= wanted;
}

// A GatedServer with a health route and an echo route (answers the body's size) on a free loopback port.
class Gate {
 public:
  explicit Gate(const GateOptions& options) {
    server_.Get("/api/health", [](const httplib::Request&, httplib::Response& response) {
      response.set_content("ok", "text/plain");
    });
    server_.Post("/api/echo", [](const httplib::Request& request, httplib::Response& response) {
      response.set_content(std::to_string(request.body.size()), "text/plain");
    });
    server_.Get("/script.js", [](const httplib::Request&, httplib::Response& response) {
      std::string script;
      for (int i = 0; script.size() < 200000; ++i)
        script += "const value" + std::to_string(i) + " = " + std::to_string(i * 7919 % 1000) + ";\n";
      response.set_content(script, "text/javascript");
    });
    port_ = server_.bind_to_any_port("127.0.0.1");
    server_.StartGate(options);
    thread_ = std::thread([this] { server_.listen_after_bind(); });
    for (int i = 0; i < 100 && Exchange(port_, Health(), 1).empty(); ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  ~Gate() {
    server_.stop();
    thread_.join();
    server_.StopGate();
  }
  int port() const { return port_; }
  GatedServer& server() { return server_; }

 private:
  GatedServer server_;
  int port_ = 0;
  std::thread thread_;
};

// Answers "HTTP/1.1 200" with body "ok" within a second.
void ExpectHealthyWithinASecond(int port) {
  const Clock::time_point start = Clock::now();
  const std::string response = Exchange(port, Health(), 1.0);
  EXPECT_LT(SecondsSince(start), 1.0);
  EXPECT_EQ(response.rfind("HTTP/1.1 200", 0), 0u) << response;
  EXPECT_EQ(response.substr(response.size() - 2), "ok") << response;
}

TEST(GatedServerTest, IdleAndSlowClientsDoNotStarveTheHealthRoute) {
  // 3,000 idle and 80 slow connections, both ends in this process.
  ASSERT_TRUE(RaiseFileLimit(8192)) << "the test needs 8192 file descriptors (ulimit -Hn)";
  GateOptions options;
  options.header_timeout_s = 4;
  options.idle_timeout_s = 6;
  Gate gate(options);
  std::vector<int> idle, slow;
  for (int i = 0; i < 3000; ++i) {
    const int fd = Connect(gate.port());
    ASSERT_GE(fd, 0) << "connection " << i;
    idle.push_back(fd);
  }
  const std::string request = "GET /api/health HTTP/1.1\r\nHost: test\r\nX-Pad: ";
  for (int i = 0; i < 80; ++i) {
    const int fd = Connect(gate.port());
    ASSERT_GE(fd, 0);
    SendAll(fd, request.substr(0, 5));
    slow.push_back(fd);
  }
  // The slow clients send one more header byte every 2 s (never ending their headers) while the health route
  // is asked 6 times over 3 s.
  const Clock::time_point start = Clock::now();
  std::thread dribble([&] {
    for (size_t next = 5; SecondsSince(start) < 3.5; ++next) {
      for (int fd : slow) SendAll(fd, std::string(1, request[std::min(next, request.size() - 1)]));
      std::this_thread::sleep_for(std::chrono::seconds(2));
    }
  });
  for (int i = 0; i < 6; ++i) {
    ExpectHealthyWithinASecond(gate.port());
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
  }
  dribble.join();
  EXPECT_GE(gate.server().open_connections(), 3000);
  // Past the header timeout, a slow client gets 408 and is closed.
  const std::string late = Receive(slow.front(), 5);
  EXPECT_EQ(late.rfind("HTTP/1.1 408", 0), 0u) << late;
  // Past the idle timeout, the idle connections are closed (the client reads the end of the stream).
  EXPECT_TRUE(ClosedWithin(idle.front(), 5));
  EXPECT_TRUE(ClosedWithin(idle.back(), 3));
  for (int fd : idle) close(fd);
  for (int fd : slow) close(fd);
  ExpectHealthyWithinASecond(gate.port());
}

TEST(GatedServerTest, AtTheLimitTheOldestIdleConnectionMakesRoomElseA503) {
  GateOptions options;
  options.max_connections = 40;
  options.header_timeout_s = 20;
  options.idle_timeout_s = 20;
  Gate gate(options);
  ASSERT_EQ(gate.server().connection_limit(), 40);
  std::vector<int> idle;
  for (int i = 0; i < 40; ++i) {
    idle.push_back(Connect(gate.port()));
    std::this_thread::sleep_for(std::chrono::milliseconds(2));  // an order of age
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  // A new client is served; the oldest idle connection was closed to make room.
  ExpectHealthyWithinASecond(gate.port());
  EXPECT_TRUE(ClosedWithin(idle.front(), 2));
  EXPECT_FALSE(ClosedWithin(idle.back(), 0.2));  // the youngest is still open
  for (int fd : idle) close(fd);
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  // 40 connections each in the middle of their headers: none is idle, so a newcomer gets 503 at once.
  std::vector<int> busy;
  for (int i = 0; i < 40; ++i) {
    busy.push_back(Connect(gate.port()));
    SendAll(busy.back(), "GET /api/health HTTP/1.1\r\n");
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const Clock::time_point start = Clock::now();
  const std::string refused = Exchange(gate.port(), Health(), 2);
  EXPECT_LT(SecondsSince(start), 1.0);
  EXPECT_EQ(refused.rfind("HTTP/1.1 503", 0), 0u) << refused;
  for (int fd : busy) close(fd);
}

// Brotli is never chosen (httplib's quality 11 took 5 s for the editor's script on a loaded machine): gzip when
// the client also takes it, else no compression.
TEST(GatedServerTest, AnswersAreNotCompressedWithBrotli) {
  Gate gate(GateOptions{});
  const auto get = [&](const std::string& accept) {
    return Exchange(gate.port(),
                    "GET /script.js HTTP/1.1\r\nHost: test\r\nConnection: close\r\nAccept-Encoding: " +
                        accept + "\r\n\r\n");
  };
  const std::string both = get("gzip, deflate, br, zstd");
  EXPECT_EQ(both.rfind("HTTP/1.1 200", 0), 0u) << both.substr(0, 200);
  EXPECT_NE(both.find("Content-Encoding: gzip\r\n"), std::string::npos) << both.substr(0, 400);
  const std::string brotli = get("br");
  EXPECT_EQ(brotli.rfind("HTTP/1.1 200", 0), 0u) << brotli.substr(0, 200);
  EXPECT_EQ(brotli.find("Content-Encoding"), std::string::npos) << brotli.substr(0, 400);
  EXPECT_NE(brotli.find("const value1 = 919;"), std::string::npos);
}

TEST(GatedServerTest, FramingHeadersAreCheckedStrictly) {
  GateOptions options;
  options.max_body_bytes = 1 << 20;
  Gate gate(options);
  const int port = gate.port();
  const std::string post = "POST /api/echo HTTP/1.1\r\nHost: test\r\n";
  EXPECT_EQ(Exchange(port, post + "Content-Length: abc\r\n\r\n").rfind("HTTP/1.1 400", 0), 0u);
  EXPECT_EQ(Exchange(port, post + "Content-Length: -1\r\n\r\n").rfind("HTTP/1.1 400", 0), 0u);
  EXPECT_EQ(Exchange(port, post + "Content-Length: 3 4\r\n\r\nabc").rfind("HTTP/1.1 400", 0), 0u);
  const std::string twice = Exchange(port, post + "Content-Length: 3\r\nContent-Length: 5\r\n\r\nabcde");
  EXPECT_EQ(twice.rfind("HTTP/1.1 400", 0), 0u) << twice;
  EXPECT_NE(twice.find("more than one Content-Length"), std::string::npos);
  EXPECT_NE(twice.find("X-Content-Type-Options: nosniff\r\n"), std::string::npos) << twice;
  EXPECT_NE(twice.find("X-Frame-Options: DENY\r\n"), std::string::npos) << twice;
  EXPECT_EQ(Exchange(port, post + "Transfer-Encoding: chunked\r\n\r\n3\r\nabc\r\n0\r\n\r\n")
                .rfind("HTTP/1.1 411", 0),
            0u);
  EXPECT_EQ(Exchange(port, post + "Content-Encoding: gzip\r\nContent-Length: 3\r\n\r\nabc")
                .rfind("HTTP/1.1 415", 0),
            0u);
  EXPECT_EQ(Exchange(port, post + "Content-Length: 99999999999\r\n\r\n").rfind("HTTP/1.1 413", 0), 0u);
  // Good requests: a body, none at all (no length: no body, answered at once), and two on one connection.
  const std::string echoed = Exchange(port, post + "Content-Length: 5\r\n\r\nhello");
  EXPECT_EQ(echoed.substr(echoed.size() - 1), "5") << echoed;
  const Clock::time_point start = Clock::now();
  const std::string empty = Exchange(port, post + "\r\n", 3);
  EXPECT_LT(SecondsSince(start), 1.0);
  EXPECT_EQ(empty.rfind("HTTP/1.1 200", 0), 0u) << empty;
  EXPECT_EQ(empty.substr(empty.size() - 1), "0");
  const int fd = Connect(port);
  SendAll(fd, post + "Content-Length: 2\r\n\r\nhi");
  const std::string first = Receive(fd, 3);
  SendAll(fd, Health());
  const std::string second = Receive(fd, 3);
  close(fd);
  EXPECT_EQ(first.substr(first.size() - 1), "2") << first;
  EXPECT_EQ(second.rfind("HTTP/1.1 200", 0), 0u) << second;
}

int64_t StatusKiB(const std::string& field) {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind(field + ":", 0) == 0) return std::stoll(line.substr(field.size() + 1));
  }
  return -1;
}

TEST(GatedServerTest, AHugeJsonBodyIsRefusedWithoutHoldingMemory) {
  ServerOptions options;
  options.port = 0;
  options.token = "t";
  EditorServer editor(options);
  editor.Bind();
  std::thread thread([&] { editor.Run(); });
  for (int i = 0; i < 100 && Exchange(editor.port(), Health(), 1).empty(); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  const int64_t peak_before = StatusKiB("VmHWM");
  auto post = [&](size_t bytes) {
    std::string request = fmt::format(
        "POST /api/models?token=t HTTP/1.1\r\nHost: 127.0.0.1:{}\r\nContent-Type: application/json\r\n"
        "Content-Length: {}\r\n\r\n",
        editor.port(), bytes);
    request.append(bytes, '[');
    return Exchange(editor.port(), request, 30);
  };
  // 60 MB (under the 64 MiB body limit): past the JSON limit; 4 MB: nested past the depth limit.
  const std::string big = post(60'000'000);
  EXPECT_EQ(big.rfind("HTTP/1.1 413", 0), 0u) << big.substr(0, 200);
  const std::string deep = post(4'000'000);
  EXPECT_EQ(deep.rfind("HTTP/1.1 400", 0), 0u) << deep.substr(0, 200);
  EXPECT_NE(deep.find("deeper than"), std::string::npos);
  // The bodies themselves (60 MB in the client, 60 MB in the server) and no parse of them: the peak grows by
  // far less than the 1.9 GB the parse took.
  EXPECT_LT(StatusKiB("VmHWM") - peak_before, 400 << 10);
  editor.Stop();
  thread.join();
  EXPECT_LT(StatusKiB("VmRSS"), peak_before + (200 << 10));
}

}  // namespace
}  // namespace lidarshop::server
