// The editor's server on a free loopback port for a test suite: the server tests (the route tests of
// server_routes_test_util.h, server_stations_test, server_tiles_test, server_jobs_test, server_safety_test) each
// start one with their own options.
#pragma once

#include <chrono>
#include <memory>
#include <string>
#include <thread>

#include "server.h"
// After every Eigen include: httplib pulls in <resolv.h>, whose `_res` macro breaks Eigen's headers.
#include <httplib.h>

namespace lidarshop::server {

// Binds (options.port 0: a free port), runs the server on its own thread and returns once /api/health answers
// with options.token (or after 2 s, when the first request will fail and say so). Stops and joins on
// destruction.
class RunningServer {
 public:
  explicit RunningServer(const ServerOptions& options, int read_timeout_s = 60) : server_(options) {
    server_.Bind();
    thread_ = std::thread([this] { server_.Run(); });
    client_ = std::make_unique<httplib::Client>("127.0.0.1", server_.port());
    client_->set_read_timeout(read_timeout_s, 0);
    const std::string health = "/api/health?token=" + options.token;
    for (int i = 0; i < 100 && !client_->Get(health); ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  ~RunningServer() {
    server_.Stop();
    thread_.join();
  }
  RunningServer(const RunningServer&) = delete;
  RunningServer& operator=(const RunningServer&) = delete;

  EditorServer& server() { return server_; }
  httplib::Client& client() { return *client_; }

 private:
  EditorServer server_;
  std::thread thread_;
  std::unique_ptr<httplib::Client> client_;
};

}  // namespace lidarshop::server
