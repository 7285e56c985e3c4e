// cpp-httplib's server behind a connection gate, so that slow or idle clients cannot starve the others.
//
// Debian's cpp-httplib (0.11.4) gives every accepted connection a request thread for as long as it is open: a
// client sending a header byte every 2 s, or one that connects and says nothing, holds a thread, and the
// 65th such client queues every other request behind it. It also takes `Content-Length: abc` as 0, keeps the
// first of two conflicting Content-Length headers, reads a POST without one until the client closes, and
// inflates gzip bodies past the body limit. The gate fixes all of that without patching the library:
//   - accepted sockets wait in one epoll thread, costing a file descriptor and a small buffer, until the whole
//     request line and headers have arrived (and a body of up to `gate_body_bytes`); only then does a request
//     thread take the connection, serve that one request (httplib's own parsing and routing, through
//     Server::process_request) and give it back;
//   - a request's line, headers and small body must arrive within `header_timeout_s` of its first byte (408
//     after), an idle connection is closed after `idle_timeout_s`, and a request thread's reads and writes
//     must end within `request_timeout_s` plus the body at `min_body_bytes_per_s` (a client sending a large
//     body, or reading the answer, a byte at a time);
//   - at most `max_connections` are open: the oldest idle one is closed to make room for a new one, and when
//     none is idle the new one gets 503;
//   - the headers are checked before any thread sees them: exactly one Content-Length of digits (400), none
//     above the body limit (413), no Transfer-Encoding (411: send a length), no Content-Encoding but identity
//     (415); a request without a length has no body (RFC 9112 §6.3), which httplib is told explicitly.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

// After every Eigen include: httplib pulls in <resolv.h>, whose `_res` macro breaks Eigen's headers.
#include <httplib.h>

namespace lidarshop::server {

struct GateOptions {
  int threads = 64;               // request threads (requests served at once)
  int max_connections = 4096;     // open connections at once; also kept below the file descriptor limit
  double header_timeout_s = 10;   // from a request's first byte to the end of its headers, seconds
  double idle_timeout_s = 5;      // a connection with no request under way is closed after this, seconds
  double request_timeout_s = 30;  // a request thread's reading and writing, seconds, plus the body's time at:
  double min_body_bytes_per_s = 256 << 10;  // the slowest upload served
  size_t gate_body_bytes = 64 << 10;   // bodies up to this are read by the gate, before a thread is taken
  size_t max_header_bytes = 32 << 10;  // request line and headers together
  int64_t max_body_bytes = int64_t{64} << 20;  // Content-Length above this gets 413
  int max_requests_per_connection = 1000;
  double linger_s = 2;  // after a refusal, how long the client's rest is read and dropped
  uint64_t max_linger_bytes = uint64_t{64} << 20;  // ... and how much of it at most
};

class GatedServer : public httplib::Server {
 public:
  GatedServer();
  ~GatedServer() override;
  GatedServer(const GatedServer&) = delete;
  GatedServer& operator=(const GatedServer&) = delete;

  // Sets the limits and starts the gate's threads; call after binding, before listen_after_bind().
  void StartGate(const GateOptions& options);
  // After listen_after_bind() returned (stop()): closes every connection and joins the threads.
  void StopGate();

  // The connection limit in force: max_connections, lowered to fit the file descriptor limit.
  int connection_limit() const { return connection_limit_; }
  // Connections open now (waiting in the gate or with a request thread); for tests and logs.
  int open_connections() const;

  struct Connection;

 private:
  // httplib's accept loop calls this (on its task queue, which runs it at once) for every accepted socket:
  // the socket joins the gate instead of taking a thread.
  bool process_and_close_socket(socket_t sock) override;

  void GateLoop();
  void WorkerLoop();
  void Admit(int fd);
  void ReadInto(Connection& connection);
  // Checks the headers of a complete request; false after answering and closing it.
  bool CheckHeaders(Connection& connection);
  void Dispatch(Connection& connection);
  void Serve(Connection& connection);
  void Close(int fd);
  // Sends a one-line JSON error and ends the sending side.
  void Refuse(int fd, int status, const std::string& message);
  // Refuse, then keep the connection for a moment, dropping what the client still sends (a body it was
  // sending when the answer came), so that it reads the answer instead of a reset.
  void Linger(Connection& connection, int status, const std::string& message);
  void Wake();

  GateOptions options_;
  int connection_limit_ = 0;
  int epoll_fd_ = -1;
  int wake_fd_ = -1;
  bool stopping_ = false;  // guarded by mutex_
  mutable std::mutex mutex_;
  std::condition_variable ready_cv_;
  std::deque<int> incoming_;                                // accepted, not yet in the gate (mutex_)
  std::deque<Connection*> ready_;                           // complete headers, for a request thread (mutex_)
  std::deque<Connection*> returned_;                        // served, back to the gate or to close (mutex_)
  std::map<int, std::unique_ptr<Connection>> connections_;  // by fd; owned by the gate thread
  int open_ = 0;  // connections_.size(), readable from any thread (mutex_)
  std::thread gate_thread_;
  std::vector<std::thread> workers_;
};

}  // namespace lidarshop::server
