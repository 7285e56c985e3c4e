// libFuzzer target for the editor's HTTP routes (issue 36): a server on a loopback port with a tiny built-in
// scan; each input opens a fresh document, sends one request with the token — the first byte picks the route,
// the rest is the JSON body (or, for the GET routes, a query value) — waits for the job it started, closes the
// document, and checks that the server answered without a 500 and still answers. A crash, a sanitizer report or
// a 500 (trap) is a finding. One document per input keeps each input's outcome its own.
#include <cctype>
#include <chrono>
#include <memory>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "fuzz/fuzz_util.h"
#include "lidarshop/testing/scenes.h"
#include "server.h"
// After every Eigen include: httplib pulls in <resolv.h>, whose `_res` macro breaks Eigen's headers.
#include <httplib.h>

namespace {

constexpr const char* kToken = "fuzz-token";

const lidarshop::Scan& TinyScan() {
  static const lidarshop::Scan scan = [] {
    lidarshop::test_scenes::GroundAndBoxOptions scene;
    scene.rows = 24;
    scene.columns = 36;
    return lidarshop::test_scenes::ScanScene(lidarshop::test_scenes::MakeGroundAndBoxScene(scene));
  }();
  return scan;
}

struct Running {
  std::unique_ptr<lidarshop::server::EditorServer> server;
  std::thread thread;
  std::unique_ptr<httplib::Client> client;
};

Running& Server() {
  static Running* running = [] {
    auto* r = new Running;  // lives until the process ends (libFuzzer exits without unwinding)
    lidarshop::server::ServerOptions options;
    options.port = 0;
    options.token = kToken;
    options.builtin_scenes = {"tiny"};
    options.scan_builtin = [](const std::string&) { return TinyScan(); };
    r->server = std::make_unique<lidarshop::server::EditorServer>(options);
    r->server->Bind();
    r->thread = std::thread([r] { r->server->Run(); });
    r->client = std::make_unique<httplib::Client>("127.0.0.1", r->server->port());
    r->client->set_keep_alive(true);
    r->client->set_read_timeout(60, 0);
    for (int i = 0; i < 200 && !r->client->Get(std::string("/api/health?token=") + kToken); ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return r;
  }();
  return *running;
}

std::string Api(const std::string& path) {
  return path + (path.find('?') == std::string::npos ? "?" : "&") + "token=" + kToken;
}

// Fails the input: the server crashed, stopped answering or answered 500.
void Check(const httplib::Result& answer) {
  if (!answer || answer->status >= 500 && answer->status != 503 && answer->status != 507) __builtin_trap();
}

// Routes that take a JSON body, then GET routes whose query value is the input.
constexpr const char* kPostRoutes[] = {
    "strokes",         "segment", "remove",      "fill",           "recolor",
    "recolor-station", "align",   "photo-match", "inpaint/review", "inpaint/review/decide",
    "verify",          "undo",    "redo",        "photo-from-e57"};
constexpr const char* kGetRoutes[] = {"points?since=",
                                      "points?step=",
                                      "image.png?channel=range&since=",
                                      "image.png?channel=",
                                      "mask.png?style=overlay&crop=1&layer=",
                                      "save-plan?format="};

// `text` percent-encoded for a query value.
std::string Percent(const std::string& text) {
  static const char* hex = "0123456789ABCDEF";
  std::string out;
  for (const unsigned char c : text) {
    if (std::isalnum(c) || c == '-' || c == '_' || c == '.' || c == '~') {
      out += static_cast<char>(c);
    } else {
      out += '%';
      out += hex[c >> 4];
      out += hex[c & 15];
    }
  }
  return out;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  lidarshop::fuzz::LimitMemory();
  if (size == 0) return 0;
  Running& running = Server();
  httplib::Client& client = *running.client;
  const auto opened = client.Get(Api("/api/open?scene=tiny"));
  Check(opened);
  if (opened->status != 200) __builtin_trap();
  const int id = nlohmann::json::parse(opened->body)["id"].get<int>();
  const std::string doc = "/api/docs/" + std::to_string(id) + "/";
  const std::string body(reinterpret_cast<const char*>(data) + 1, size - 1);
  constexpr size_t kPosts = std::size(kPostRoutes), kGets = std::size(kGetRoutes);
  const size_t pick = data[0] % (kPosts + kGets + 1);
  const auto send = [&]() -> httplib::Result {
    if (pick < kPosts) return client.Post(Api(doc + kPostRoutes[pick]), body, "application/json");
    if (pick < kPosts + kGets) return client.Get(Api(doc + kGetRoutes[pick - kPosts] + Percent(body)));
    return client.Post(Api("/api/models"), body, "application/json");
  };
  const httplib::Result answer = send();
  Check(answer);
  if (answer->status == 202) {  // a job: wait for it, so that it ends with its input
    const auto job = nlohmann::json::parse(answer->body, nullptr, false);
    if (job.is_object() && job.contains("id") && job["id"].is_number_integer()) {
      const std::string poll = Api("/api/jobs/" + std::to_string(job["id"].get<int>()));
      for (int i = 0; i < 6000; ++i) {
        const auto state = client.Get(poll);
        Check(state);
        const auto json = nlohmann::json::parse(state->body, nullptr, false);
        if (!json.is_object() ||
            (json.value("state", "") != "queued" && json.value("state", "") != "running"))
          break;
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
      }
    }
  }
  Check(client.Delete(Api("/api/docs/" + std::to_string(id))));
  Check(client.Get(Api("/api/health")));
  return 0;
}
