#include "gated_server.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <optional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "lidarshop/util/options.h"
#include "lidarshop/util/text.h"
#include "replies.h"

namespace lidarshop::server {

namespace {

using Clock = std::chrono::steady_clock;

Clock::duration Seconds(double seconds) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
}

// Runs each task at once on the accepting thread: the only task httplib queues is handing over an accepted
// socket, which the gate takes in without blocking.
class InlineQueue : public httplib::TaskQueue {
 public:
  void enqueue(std::function<void()> fn) override { fn(); }
  void shutdown() override {}
};

std::string StatusText(int status) {
  switch (status) {
    case 400:
      return "Bad Request";
    case 408:
      return "Request Timeout";
    case 411:
      return "Length Required";
    case 413:
      return "Payload Too Large";
    case 415:
      return "Unsupported Media Type";
    case 431:
      return "Request Header Fields Too Large";
    case 503:
      return "Service Unavailable";
    default:
      return "Error";
  }
}

std::string Trim(const std::string& text) {
  const size_t first = text.find_first_not_of(" \t");
  if (first == std::string::npos) return "";
  return text.substr(first, text.find_last_not_of(" \t") - first + 1);
}

// The connection limit: the configured one, kept below the file descriptor limit (less what the process
// needs besides: the files it reads and writes, the listening socket, the gate's own descriptors).
int ConnectionLimit(int configured) {
  rlimit limit{};
  int64_t available = configured;
  if (getrlimit(RLIMIT_NOFILE, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY) {
    available = static_cast<int64_t>(limit.rlim_cur) - 128;
  }
  return static_cast<int>(std::max<int64_t>(8, std::min<int64_t>(configured, available)));
}

}  // namespace

struct GatedServer::Connection {
  int fd = -1;
  std::string buffer;       // bytes received and not yet consumed by a request
  size_t header_bytes = 0;  // request line and headers at the front of `buffer` (0 = not complete)
  uint64_t body_bytes = 0;  // the request's Content-Length
  bool busy = false;        // with a request thread
  bool keep = false;        // set by the request thread: back to the gate after the request
  int requests = 0;
  Clock::time_point last_activity;              // accepted, or the last request done
  std::optional<Clock::time_point> first_byte;  // of the request under way
  // Refused: the answer is sent and the client's rest is read and dropped until then, so that a client still
  // sending its body gets to read the answer instead of a reset.
  std::optional<Clock::time_point> lingering_until;
  uint64_t dropped_bytes = 0;
};

namespace {

// httplib's view of a connection whose headers are already in `buffer`: reads come from the buffer first,
// then from the socket, each within the request's deadline; the same for writes.
class GateStream : public httplib::Stream {
 public:
  GateStream(GatedServer::Connection& connection, Clock::time_point deadline)
      : connection_(connection), deadline_(deadline) {}

  bool is_readable() const override { return position_ < connection_.buffer.size() || Wait(POLLIN); }
  bool is_writable() const override { return Wait(POLLOUT); }

  ssize_t read(char* ptr, size_t size) override {
    if (position_ < connection_.buffer.size()) {
      const size_t n = std::min(size, connection_.buffer.size() - position_);
      std::memcpy(ptr, connection_.buffer.data() + position_, n);
      position_ += n;
      return static_cast<ssize_t>(n);
    }
    for (;;) {
      const ssize_t n = recv(connection_.fd, ptr, size, 0);
      if (n >= 0) {
        socket_bytes_ += static_cast<uint64_t>(n);
        return n;
      }
      if (errno == EINTR) continue;
      if ((errno != EAGAIN && errno != EWOULDBLOCK) || !Wait(POLLIN)) return -1;
    }
  }

  ssize_t write(const char* ptr, size_t size) override {
    for (;;) {
      const ssize_t n = send(connection_.fd, ptr, size, MSG_NOSIGNAL);
      if (n >= 0) return n;
      if (errno == EINTR) continue;
      if ((errno != EAGAIN && errno != EWOULDBLOCK) || !Wait(POLLOUT)) return -1;
    }
  }

  void get_remote_ip_and_port(std::string& ip, int& port) const override { Address(getpeername, ip, port); }
  void get_local_ip_and_port(std::string& ip, int& port) const override { Address(getsockname, ip, port); }
  // httplib answers 500 to a socket past FD_SETSIZE (it would select() on it); this stream never lets httplib
  // touch the socket, so it says "none" there.
  socket_t socket() const override { return connection_.fd < FD_SETSIZE ? connection_.fd : INVALID_SOCKET; }

  // Bytes of the connection the request consumed (buffer and socket).
  uint64_t consumed() const { return position_ + socket_bytes_; }
  size_t buffer_position() const { return position_; }

 private:
  bool Wait(short events) const {
    for (;;) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline_ - Clock::now());
      if (left.count() <= 0) return false;
      pollfd entry{connection_.fd, events, 0};
      const int ready = poll(&entry, 1, static_cast<int>(std::min<int64_t>(left.count(), 1000)));
      if (ready > 0) return (entry.revents & (events | POLLHUP | POLLERR)) != 0;
      if (ready < 0 && errno != EINTR) return false;
    }
  }

  template <class Getter>
  void Address(Getter getter, std::string& ip, int& port) const {
    sockaddr_storage address{};
    socklen_t length = sizeof(address);
    ip.clear();
    port = 0;
    if (getter(connection_.fd, reinterpret_cast<sockaddr*>(&address), &length) != 0) return;
    char text[INET6_ADDRSTRLEN] = {};
    if (address.ss_family == AF_INET) {
      const auto* v4 = reinterpret_cast<const sockaddr_in*>(&address);
      inet_ntop(AF_INET, &v4->sin_addr, text, sizeof(text));
      port = ntohs(v4->sin_port);
    } else if (address.ss_family == AF_INET6) {
      const auto* v6 = reinterpret_cast<const sockaddr_in6*>(&address);
      inet_ntop(AF_INET6, &v6->sin6_addr, text, sizeof(text));
      port = ntohs(v6->sin6_port);
    }
    ip = text;
  }

  GatedServer::Connection& connection_;
  const Clock::time_point deadline_;
  size_t position_ = 0;
  uint64_t socket_bytes_ = 0;
};

}  // namespace

GatedServer::GatedServer() {
  new_task_queue = [] { return new InlineQueue(); };
}

GatedServer::~GatedServer() { StopGate(); }

void GatedServer::StartGate(const GateOptions& options) {
  if (gate_thread_.joinable()) return;
  options_ = options;
  connection_limit_ = ConnectionLimit(options_.max_connections);
  set_payload_max_length(static_cast<size_t>(options_.max_body_bytes));
  // What httplib writes in its Keep-Alive header; the gate enforces both.
  set_keep_alive_timeout(static_cast<time_t>(options_.idle_timeout_s));
  set_keep_alive_max_count(static_cast<size_t>(options_.max_requests_per_connection));
  epoll_fd_ = epoll_create1(EPOLL_CLOEXEC);
  wake_fd_ = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (epoll_fd_ < 0 || wake_fd_ < 0) throw std::runtime_error("the server's gate: epoll/eventfd failed");
  epoll_event event{};
  event.events = EPOLLIN;
  event.data.fd = wake_fd_;
  epoll_ctl(epoll_fd_, EPOLL_CTL_ADD, wake_fd_, &event);
  {
    std::lock_guard lock(mutex_);
    stopping_ = false;
  }
  // Debian's httplib listens with a backlog of 5: a burst of new clients would overflow it. A second listen()
  // on a listening socket only changes its backlog.
  if (svr_sock_ != INVALID_SOCKET) ::listen(svr_sock_, SOMAXCONN);
  gate_thread_ = std::thread([this] { GateLoop(); });
  for (int i = 0; i < std::max(1, options_.threads); ++i) workers_.emplace_back([this] { WorkerLoop(); });
}

void GatedServer::StopGate() {
  if (!gate_thread_.joinable()) return;
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  ready_cv_.notify_all();
  Wake();
  for (std::thread& worker : workers_) worker.join();
  workers_.clear();
  gate_thread_.join();
  for (auto& [fd, connection] : connections_) {
    shutdown(fd, SHUT_RDWR);
    ::close(fd);
  }
  connections_.clear();
  {
    std::lock_guard lock(mutex_);
    for (int fd : incoming_) ::close(fd);
    incoming_.clear();
    ready_.clear();
    returned_.clear();
    open_ = 0;
  }
  ::close(epoll_fd_);
  ::close(wake_fd_);
  epoll_fd_ = wake_fd_ = -1;
}

int GatedServer::open_connections() const {
  std::lock_guard lock(mutex_);
  return open_ + static_cast<int>(incoming_.size());
}

bool GatedServer::process_and_close_socket(socket_t sock) {
  {
    std::lock_guard lock(mutex_);
    if (stopping_ || !gate_thread_.joinable()) {
      ::close(sock);
      return false;
    }
    incoming_.push_back(sock);
  }
  Wake();
  return true;
}

void GatedServer::Wake() {
  if (wake_fd_ < 0) return;
  const uint64_t one = 1;
  [[maybe_unused]] const ssize_t written = ::write(wake_fd_, &one, sizeof(one));
}

void GatedServer::Refuse(int fd, int status, const std::string& message) {
  // Bytes that are not UTF-8 (a header value quoted in the message) are replaced, not thrown on.
  const std::string body =
      ToJson(ErrorReply{message}).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  // The security headers every answer of the editor's server carries (security.cc), for these too.
  const std::string response = fmt::format(
      "HTTP/1.1 {} {}\r\nContent-Type: application/json\r\nContent-Length: {}\r\nConnection: close\r\n"
      "Content-Security-Policy: default-src 'none'; frame-ancestors 'none'\r\nX-Frame-Options: DENY\r\n"
      "X-Content-Type-Options: nosniff\r\nReferrer-Policy: no-referrer\r\n\r\n{}",
      status, StatusText(status), body.size(), body);
  // Best effort on a non-blocking socket: a short answer fits its send buffer.
  [[maybe_unused]] const ssize_t sent = send(fd, response.data(), response.size(), MSG_NOSIGNAL);
  shutdown(fd, SHUT_WR);
}

void GatedServer::Linger(Connection& connection, int status, const std::string& message) {
  Refuse(connection.fd, status, message);
  connection.lingering_until = Clock::now() + Seconds(options_.linger_s);
  connection.first_byte.reset();
  connection.buffer.clear();
  connection.buffer.shrink_to_fit();
}

void GatedServer::Close(int fd) {
  epoll_ctl(epoll_fd_, EPOLL_CTL_DEL, fd, nullptr);
  shutdown(fd, SHUT_RDWR);
  ::close(fd);
  connections_.erase(fd);
  std::lock_guard lock(mutex_);
  open_ = static_cast<int>(connections_.size());
}

void GatedServer::Admit(int fd) {
  fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK);
  fcntl(fd, F_SETFD, FD_CLOEXEC);
  if (static_cast<int>(connections_.size()) >= connection_limit_) {
    // Full: make room by closing the connection idle the longest; with none idle, the newcomer is refused
    // (503) rather than left waiting behind the others.
    Connection* oldest = nullptr;
    for (auto& [other_fd, other] : connections_) {
      if (other->busy || !other->buffer.empty()) continue;
      if (oldest == nullptr || other->last_activity < oldest->last_activity) oldest = other.get();
    }
    if (oldest == nullptr) {
      // What the newcomer sent already is read first: closing a socket with unread bytes resets it, and the
      // client would see the reset instead of the answer.
      char chunk[16384];
      while (recv(fd, chunk, sizeof(chunk), 0) > 0) {
      }
      Refuse(fd, 503, "too many connections; retry later");
      ::close(fd);
      return;
    }
    Close(oldest->fd);
  }
  auto connection = std::make_unique<Connection>();
  connection->fd = fd;
  connection->last_activity = Clock::now();
  epoll_event event{};
  event.events = EPOLLIN | EPOLLRDHUP;
  event.data.fd = fd;
  if (epoll_ctl(epoll_fd_, EPOLL_CTL_ADD, fd, &event) != 0) {
    ::close(fd);
    return;
  }
  connections_[fd] = std::move(connection);
  std::lock_guard lock(mutex_);
  open_ = static_cast<int>(connections_.size());
}

void GatedServer::ReadInto(Connection& connection) {
  const int fd = connection.fd;
  char chunk[16384];
  if (connection.lingering_until) {
    for (;;) {
      const ssize_t n = recv(fd, chunk, sizeof(chunk), 0);
      if (n > 0 && (connection.dropped_bytes += static_cast<uint64_t>(n)) <= options_.max_linger_bytes)
        continue;
      if (n < 0 && errno == EINTR) continue;
      if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return;
      Close(fd);  // the client is done (or sends too much)
      return;
    }
  }
  for (;;) {
    if (connection.header_bytes == 0) {
      if (connection.buffer.find("\r\n\r\n") != std::string::npos) {
        if (!CheckHeaders(connection)) return;  // answered (lingering)
        continue;
      }
      if (connection.buffer.size() > options_.max_header_bytes) {
        Linger(connection, 431,
               fmt::format("the request line and headers exceed {} bytes", options_.max_header_bytes));
        return;
      }
    } else if (connection.body_bytes > options_.gate_body_bytes ||
               connection.buffer.size() >= connection.header_bytes + connection.body_bytes) {
      // The headers, and a small body whole: a request thread takes it from here.
      Dispatch(connection);
      return;
    }
    const ssize_t n = recv(fd, chunk, sizeof(chunk), 0);
    if (n > 0) {
      if (!connection.first_byte) connection.first_byte = Clock::now();
      connection.buffer.append(chunk, static_cast<size_t>(n));
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return;
    Close(fd);  // the client closed (0) or the connection failed
    return;
  }
}

bool GatedServer::CheckHeaders(Connection& connection) {
  std::string& buffer = connection.buffer;
  const size_t end = buffer.find("\r\n\r\n");
  if (end > options_.max_header_bytes) {
    Linger(connection, 431,
           fmt::format("the request line and headers exceed {} bytes", options_.max_header_bytes));
    return false;
  }
  int lengths = 0;
  std::string length_text;
  std::string problem;
  int status = 400;
  size_t line_start = buffer.find("\r\n") + 2;  // after the request line
  while (line_start < end + 2 && problem.empty()) {
    const size_t line_end = buffer.find("\r\n", line_start);
    const std::string line = buffer.substr(line_start, line_end - line_start);
    line_start = line_end + 2;
    const size_t colon = line.find(':');
    if (colon == std::string::npos) continue;  // httplib rejects it (400)
    const std::string name = AsciiLower(line.substr(0, colon));
    const std::string value = Trim(line.substr(colon + 1));
    if (name == "accept-encoding") {
      // No Brotli: httplib compresses with it at quality 11, which took 5 s for the editor's 0.5 MB script on a
      // loaded 2-core machine (the page's first picture waited for it); gzip takes 0.08 s. The token is blanked
      // in place (same length: the offsets into the buffer stay true).
      const size_t line_begin = line_start - 2 - line.size();
      const std::string lower = AsciiLower(line);
      const auto separator = [&](size_t i) {
        return i >= line.size() || line[i] == ',' || line[i] == ' ' || line[i] == ';' || line[i] == ':';
      };
      for (size_t at = lower.find("br", colon + 1); at != std::string::npos; at = lower.find("br", at + 2)) {
        if (separator(at - 1) && separator(at + 2)) buffer.replace(line_begin + at, 2, "  ");
      }
    } else if (name == "content-length") {
      if (++lengths > 1) problem = "more than one Content-Length header";
      length_text = value;
    } else if (name == "transfer-encoding") {
      status = 411;
      problem =
          fmt::format("Transfer-Encoding '{}' is not accepted: send the body with a Content-Length", value);
    } else if (name == "content-encoding" && AsciiLower(value) != "identity") {
      status = 415;
      problem = fmt::format("Content-Encoding '{}' is not accepted: send the body uncompressed", value);
    }
  }
  uint64_t length = 0;
  if (problem.empty() && lengths == 1) {
    const bool digits =
        !length_text.empty() && length_text.size() <= 18 &&
        std::all_of(length_text.begin(), length_text.end(), [](char c) { return c >= '0' && c <= '9'; });
    if (!digits) {
      problem = fmt::format("Content-Length '{}' is not a whole number of bytes",
                            length_text.substr(0, std::min<size_t>(length_text.size(), 40)));
    } else {
      length = std::stoull(length_text);
      if (length > static_cast<uint64_t>(options_.max_body_bytes)) {
        status = 413;
        problem = fmt::format("the body of {} bytes exceeds the limit of {} bytes", length,
                              options_.max_body_bytes);
      }
    }
  }
  if (!problem.empty()) {
    Linger(connection, status, problem);
    return false;
  }
  if (lengths == 0) {
    // No length and no Transfer-Encoding: no body (RFC 9112 §6.3). httplib would read a POST until the client
    // closes; told the length, it reads none.
    buffer.insert(end + 2, "Content-Length: 0\r\n");
  }
  connection.header_bytes = buffer.find("\r\n\r\n") + 4;
  connection.body_bytes = length;
  return true;
}

void GatedServer::Dispatch(Connection& connection) {
  epoll_ctl(epoll_fd_, EPOLL_CTL_DEL, connection.fd, nullptr);
  connection.busy = true;
  {
    std::lock_guard lock(mutex_);
    ready_.push_back(&connection);
  }
  ready_cv_.notify_one();
}

void GatedServer::GateLoop() {
  std::vector<epoll_event> events(256);
  for (;;) {
    const int count = epoll_wait(epoll_fd_, events.data(), static_cast<int>(events.size()), 100);
    std::deque<int> incoming;
    std::deque<Connection*> returned;
    bool stopping = false;
    {
      std::lock_guard lock(mutex_);
      incoming.swap(incoming_);
      returned.swap(returned_);
      stopping = stopping_;
    }
    if (stopping) {
      for (int fd : incoming) ::close(fd);
      return;
    }
    for (Connection* connection : returned) {
      connection->busy = false;
      if (!connection->keep) {
        Close(connection->fd);
        continue;
      }
      connection->last_activity = Clock::now();
      connection->first_byte.reset();
      connection->header_bytes = 0;
      connection->body_bytes = 0;
      epoll_event event{};
      event.events = EPOLLIN | EPOLLRDHUP;
      event.data.fd = connection->fd;
      epoll_ctl(epoll_fd_, EPOLL_CTL_ADD, connection->fd, &event);
      if (!connection->buffer.empty()) {  // a pipelined request
        connection->first_byte = Clock::now();
        ReadInto(*connection);
      }
    }
    for (int fd : incoming) Admit(fd);
    for (int i = 0; i < count; ++i) {
      const int fd = events[i].data.fd;
      if (fd == wake_fd_) {
        uint64_t value = 0;
        [[maybe_unused]] const ssize_t got = ::read(wake_fd_, &value, sizeof(value));
        continue;
      }
      const auto it = connections_.find(fd);
      if (it == connections_.end() || it->second->busy) continue;
      ReadInto(*it->second);
    }
    // Deadlines: a request whose headers are late gets 408; an idle connection is closed.
    const Clock::time_point now = Clock::now();
    std::vector<int> late, idle;
    std::vector<int> lingered;
    for (const auto& [fd, connection] : connections_) {
      if (connection->busy) continue;
      if (connection->lingering_until) {
        if (now > *connection->lingering_until) lingered.push_back(fd);
      } else if (connection->first_byte) {
        if (now - *connection->first_byte > Seconds(options_.header_timeout_s)) late.push_back(fd);
      } else if (now - connection->last_activity > Seconds(options_.idle_timeout_s)) {
        idle.push_back(fd);
      }
    }
    for (int fd : late) {
      Linger(*connections_.at(fd), 408,
             fmt::format("the request's headers took longer than {} s", options_.header_timeout_s));
    }
    for (int fd : idle) Close(fd);
    for (int fd : lingered) Close(fd);
  }
}

void GatedServer::WorkerLoop() {
  for (;;) {
    Connection* connection = nullptr;
    {
      std::unique_lock lock(mutex_);
      ready_cv_.wait(lock, [&] { return stopping_ || !ready_.empty(); });
      if (stopping_) return;
      connection = ready_.front();
      ready_.pop_front();
    }
    Serve(*connection);
    {
      std::lock_guard lock(mutex_);
      returned_.push_back(connection);
    }
    Wake();
  }
}

void GatedServer::Serve(Connection& connection) {
  const int fd = connection.fd;
  fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK);
  ++connection.requests;
  bool closing = connection.requests >= options_.max_requests_per_connection;
  {
    std::lock_guard lock(mutex_);
    closing = closing || stopping_;
  }
  const double seconds =
      options_.request_timeout_s + static_cast<double>(connection.body_bytes) / options_.min_body_bytes_per_s;
  GateStream stream(connection, Clock::now() + Seconds(seconds));
  bool connection_closed = false;
  const bool ok = process_request(stream, closing, connection_closed, nullptr);
  // Kept only when the request was read to its end: a body a route did not read (a 401, a 404) would be
  // taken for the next request.
  const bool whole = stream.consumed() >= connection.header_bytes + connection.body_bytes;
  connection.keep = ok && !closing && !connection_closed && whole;
  if (connection.keep) {
    connection.buffer.erase(0, std::min(connection.buffer.size(), stream.buffer_position()));
  } else {
    connection.buffer.clear();
  }
  connection.buffer.shrink_to_fit();
}

}  // namespace lidarshop::server
