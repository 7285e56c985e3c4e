// Load test of the editor's server: N concurrent clients on loopback for T seconds, each reading the document,
// painting one stroke cell per iteration and fetching pictures and points now and then. Reports requests,
// errors, latency quantiles, and checks that no edit was lost (the document's version grew by exactly the
// number of strokes the server acknowledged).
//
// --catch-up none|whole|delta: after each acknowledged stroke the client also brings its points up to date as
// an editor would: `whole` fetches every point again (what the editor did before deltas), `delta` fetches the
// cells changed since the version it holds (GET /points?since=V, docs/api.md "Deltas"). `bytes_per_edit` is
// the bytes of those fetches per acknowledged stroke (with `delta`, each client's first fetch of the whole
// points apart: `first_points_bytes`).
//
//   editor_load URL [--clients 50] [--seconds 30] [--catch-up none]   URL as `lidarshop serve` printed it
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <httplib.h>  // after every Eigen include (none here); <resolv.h> defines `_res`

int main(int argc, char** argv) {
  if (argc < 2) {
    fmt::print(stderr, "usage: editor_load URL [--clients N] [--seconds T]\n");
    return 2;
  }
  const std::string url = argv[1];
  int clients = 50, seconds = 30;
  std::string catch_up = "none";
  for (int i = 2; i + 1 < argc; i += 2) {
    if (std::string(argv[i]) == "--clients") clients = std::stoi(argv[i + 1]);
    if (std::string(argv[i]) == "--seconds") seconds = std::stoi(argv[i + 1]);
    if (std::string(argv[i]) == "--catch-up") catch_up = argv[i + 1];
  }
  if (catch_up != "none" && catch_up != "whole" && catch_up != "delta") {
    fmt::print(stderr, "editor_load: --catch-up none|whole|delta, got '{}'\n", catch_up);
    return 2;
  }
  const size_t scheme = url.find("://") + 3;
  const size_t path = url.find('/', scheme);
  const std::string host_port = url.substr(scheme, path - scheme);
  const std::string host = host_port.substr(0, host_port.find(':'));
  const int port = std::stoi(host_port.substr(host_port.find(':') + 1));
  const std::string token = url.substr(url.find("token=") + 6);
  const auto api = [&](const std::string& p) {
    return p + (p.find('?') == std::string::npos ? "?" : "&") + "token=" + token;
  };

  httplib::Client probe(host, port);
  const auto docs = probe.Get(api("/api/docs"));
  if (!docs || docs->status != 200) {
    fmt::print(stderr, "editor_load: cannot list documents at {}\n", url);
    return 1;
  }
  const auto document = nlohmann::json::parse(docs->body)["documents"].at(0);
  const int id = document["id"], rows = document["rows"], cols = document["cols"];
  const int64_t version_before = document["version"];

  std::atomic<int64_t> requests{0}, errors{0}, strokes_ok{0}, catch_up_bytes{0}, first_bytes{0};
  std::mutex latency_mutex;
  std::vector<double> latencies_ms;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(seconds);
  std::vector<std::thread> threads;
  for (int k = 0; k < clients; ++k) {
    threads.emplace_back([&, k] {
      httplib::Client client(host, port);
      client.set_read_timeout(60, 0);
      std::vector<double> mine;
      int64_t held_version = -1;  // the version of the points this client holds (-1: none yet)
      for (int i = 0; std::chrono::steady_clock::now() < deadline; ++i) {
        const auto start = std::chrono::steady_clock::now();
        const bool stroke = i % 2 == 1 && i % 10 != 9;
        const std::string body = fmt::format(R"({{"background": [[{}, {}]], "radius": 0}})",
                                             (k * 7 + i) % rows, (k * 13 + i * 3) % cols);
        const httplib::Result result =
            i % 50 == 49  ? client.Get(api(fmt::format("/api/docs/{}/points", id)))
            : i % 10 == 9 ? client.Get(api(fmt::format("/api/docs/{}/image.png?channel=range", id)))
            : !stroke     ? client.Get(api(fmt::format("/api/docs/{}", id)))
                      : client.Post(api(fmt::format("/api/docs/{}/strokes", id)), body, "application/json");
        mine.push_back(
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
        ++requests;
        if (!result || result->status != 200) {
          ++errors;
        } else if (stroke) {
          ++strokes_ok;
          if (catch_up == "none") continue;
          // The editor's refresh after an edit: the points again, whole or the cells changed.
          const auto points_start = std::chrono::steady_clock::now();
          const std::string path = catch_up == "delta" && held_version >= 0
                                       ? fmt::format("/api/docs/{}/points?since={}", id, held_version)
                                       : fmt::format("/api/docs/{}/points", id);
          const httplib::Result points = client.Get(api(path));
          mine.push_back(
              std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - points_start)
                  .count());
          ++requests;
          if (!points || points->status != 200) {
            ++errors;
            continue;
          }
          // A client's first fetch is the whole points in either mode (it holds none): counted apart.
          (catch_up == "delta" && held_version < 0 ? first_bytes : catch_up_bytes) +=
              static_cast<int64_t>(points->body.size());
          const std::string version = points->get_header_value("X-Lidarshop-Version");
          held_version = version.empty() ? -1 : std::stoll(version);
        }
      }
      std::lock_guard lock(latency_mutex);
      latencies_ms.insert(latencies_ms.end(), mine.begin(), mine.end());
    });
  }
  for (std::thread& thread : threads) thread.join();
  const auto after = probe.Get(api(fmt::format("/api/docs/{}", id)));
  const int64_t version_after = nlohmann::json::parse(after->body)["version"];
  std::sort(latencies_ms.begin(), latencies_ms.end());
  const auto quantile = [&](double q) {
    return latencies_ms.empty() ? 0.0 : latencies_ms[static_cast<size_t>(q * (latencies_ms.size() - 1))];
  };
  const bool lost = version_after - version_before != strokes_ok.load();
  nlohmann::ordered_json summary = {
      {"clients", clients},
      {"seconds", seconds},
      {"requests", requests.load()},
      {"requests_per_s", static_cast<double>(requests) / seconds},
      {"errors", errors.load()},
      {"strokes_acknowledged", strokes_ok.load()},
      {"version_growth", version_after - version_before},
      {"lost_edits", lost},
      {"catch_up", catch_up},
      {"first_points_bytes", first_bytes.load()},
      {"bytes_per_edit",
       strokes_ok > 0 ? static_cast<double>(catch_up_bytes.load()) / static_cast<double>(strokes_ok.load())
                      : 0.0},
      {"latency_ms", {{"p50", quantile(0.5)}, {"p99", quantile(0.99)}, {"max", quantile(1.0)}}}};
  fmt::print("{}\n", summary.dump(2));
  return errors == 0 && !lost ? 0 : 1;
}
