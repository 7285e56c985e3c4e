// The editor's server against hostile and careless callers (issue 36, "a server that cannot be knocked
// over"): open documents are never evicted, deep or odd JSON is refused before it is parsed or echoed, only
// the editor's own page may call, every answer says how it may be used, the token travels in a cookie, photos
// are measured before decoding, saves go through a private folder, and non-loopback binds are said.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/inotify.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <thread>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "lidarshop/testing/scenes.h"
#include "lidarshop/util/error.h"
#include "server.h"
// After every Eigen include: httplib pulls in <resolv.h>, whose `_res` macro breaks Eigen's headers.
#include <httplib.h>

namespace lidarshop::server {
namespace {

namespace fs = std::filesystem;

const Scan& TinyScan() {
  static const Scan scan = [] {
    lidarshop::test_scenes::GroundAndBoxOptions scene;
    scene.rows = 40;
    scene.columns = 60;
    return lidarshop::test_scenes::ScanScene(lidarshop::test_scenes::MakeGroundAndBoxScene(scene));
  }();
  return scan;
}

// A server on a free loopback port with the built-in scene "tiny", running until destroyed.
class Running {
 public:
  explicit Running(ServerOptions options = {}) {
    options.port = 0;
    options.token = "secret-token";
    options.builtin_scenes = {"tiny"};
    options.scan_builtin = [](const std::string&) { return TinyScan(); };
    server_ = std::make_unique<EditorServer>(options);
    server_->Bind();
    thread_ = std::thread([this] { server_->Run(); });
    client_ = std::make_unique<httplib::Client>("127.0.0.1", server_->port());
    client_->set_read_timeout(60, 0);
    for (int i = 0; i < 100 && !client_->Get("/api/health?token=secret-token"); ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  ~Running() {
    server_->Stop();
    thread_.join();
  }
  httplib::Client& client() { return *client_; }
  EditorServer& server() { return *server_; }
  int port() const { return server_->port(); }
  static std::string Api(const std::string& path) {
    return path + (path.find('?') == std::string::npos ? "?" : "&") + "token=secret-token";
  }
  int OpenTiny() {
    const auto opened = client_->Get(Api("/api/open?scene=tiny"));
    EXPECT_EQ(opened->status, 200) << opened->body;
    return nlohmann::json::parse(opened->body)["id"].get<int>();
  }

 private:
  std::unique_ptr<EditorServer> server_;
  std::thread thread_;
  std::unique_ptr<httplib::Client> client_;
};

nlohmann::json Json(const httplib::Result& result) { return nlohmann::json::parse(result->body); }

std::string ErrorOf(const httplib::Result& result) { return Json(result)["error"].get<std::string>(); }

TEST(ServerSafetyTest, OneDocumentTooManyIsRefusedNotEvicted) {
  ServerOptions options;
  options.max_documents = 2;
  Running running(options);
  auto& client = running.client();
  const int first = running.OpenTiny();
  const int second = running.OpenTiny();
  // An unsaved edit on the oldest document: it must survive the refused open.
  ASSERT_EQ(client
                .Post(Running::Api(fmt::format("/api/docs/{}/strokes", first)),
                      R"({"object": [[20, 30]], "radius": 1})", "application/json")
                ->status,
            200);
  const auto refused = client.Get(Running::Api("/api/open?scene=tiny"));
  EXPECT_EQ(refused->status, 409) << refused->body;
  EXPECT_NE(ErrorOf(refused).find("2 scans are open"), std::string::npos) << refused->body;
  EXPECT_NE(ErrorOf(refused).find("close one"), std::string::npos) << refused->body;
  const auto listed = Json(client.Get(Running::Api("/api/docs")))["documents"];
  ASSERT_EQ(listed.size(), 2u);
  EXPECT_EQ(listed[0]["id"], first);
  EXPECT_EQ(listed[0]["version"], 1);  // the edit is still there
  EXPECT_EQ(listed[1]["id"], second);
  EXPECT_THROW(running.server().OpenScene("tiny"), InputError);  // `serve --scene` past the limit
  // Closed by the user: room for one more.
  ASSERT_EQ(client.Delete(Running::Api(fmt::format("/api/docs/{}", second)))->status, 200);
  EXPECT_EQ(client.Get(Running::Api("/api/open?scene=tiny"))->status, 200);
}

TEST(ServerSafetyTest, OpeningPastTheMemoryLimitIsRefused) {
  // Room for one tiny scan (its channels and strokes) but not two.
  const Scan& scan = TinyScan();
  int64_t one = static_cast<int64_t>(scan.rows) * scan.cols;  // the strokes
  for (const cv::Mat* mat :
       {&scan.direction, &scan.valid, &scan.range, &scan.point, &scan.intensity, &scan.color, &scan.label,
        &scan.normal, &scan.curvature, &scan.true_range, &scan.synthesized}) {
    one += static_cast<int64_t>(mat->total() * mat->elemSize());
  }
  ServerOptions options;
  options.max_document_bytes = one * 3 / 2;
  Running running(options);
  const int first = running.OpenTiny();
  const auto refused = running.client().Get(Running::Api("/api/open?scene=tiny"));
  EXPECT_EQ(refused->status, 507) << refused->body;
  EXPECT_NE(ErrorOf(refused).find("not enough memory"), std::string::npos) << refused->body;
  const auto listed = Json(running.client().Get(Running::Api("/api/docs")))["documents"];
  ASSERT_EQ(listed.size(), 1u);
  EXPECT_EQ(listed[0]["id"], first);
}

TEST(ServerSafetyTest, AnEditPastTheMemoryLimitIsRefusedAndTheDocumentKept) {
  // Room for the tiny scan and a few strokes buffers (each stroke edit makes a new one, kept for undo), not
  // for the undo depth of them.
  const Scan& scan = TinyScan();
  const int64_t strokes_bytes = static_cast<int64_t>(scan.rows) * scan.cols;
  int64_t one = strokes_bytes;
  for (const cv::Mat* mat :
       {&scan.direction, &scan.valid, &scan.range, &scan.point, &scan.intensity, &scan.color, &scan.label,
        &scan.normal, &scan.curvature, &scan.true_range, &scan.synthesized}) {
    one += static_cast<int64_t>(mat->total() * mat->elemSize());
  }
  ServerOptions options;
  options.max_document_bytes = one + 3 * strokes_bytes + strokes_bytes / 2;
  options.undo_depth = 8;
  Running running(options);
  const int id = running.OpenTiny();
  const std::string strokes = Running::Api(fmt::format("/api/docs/{}/strokes", id));
  int accepted = 0;
  std::optional<httplib::Response> refused;
  for (int i = 0; i < 8; ++i) {
    auto answer = running.client().Post(
        strokes,
        fmt::format(R"({{"object": [[{}, 30]], "background": [[{}, 2]], "radius": 0}})", 28 + i, 34 + i),
        "application/json");
    ASSERT_TRUE(answer);
    if (answer->status != 200) {
      refused = *answer;
      break;
    }
    ++accepted;
  }
  ASSERT_TRUE(refused.has_value()) << "no edit was refused";
  EXPECT_EQ(accepted, 3);  // the scan + the first strokes buffer + 3 more fit, a 4th does not
  EXPECT_EQ(refused->status, 507) << refused->body;
  const std::string message = nlohmann::json::parse(refused->body)["error"].get<std::string>();
  EXPECT_NE(message.find("not enough memory for this edit"), std::string::npos) << message;
  EXPECT_NE(message.find("kept as it was"), std::string::npos) << message;
  // The document is as the last accepted edit left it: its version, its strokes, its undo.
  auto document = Json(running.client().Get(Running::Api(fmt::format("/api/docs/{}", id))));
  EXPECT_EQ(document["version"], accepted);
  EXPECT_EQ(document["object_stroke_cells"], accepted);
  // A job's edit (a segmentation's new object mask) is refused the same way: the job fails with the message.
  const auto job =
      running.client().Post(Running::Api(fmt::format("/api/docs/{}/segment", id)), "{}", "application/json");
  ASSERT_EQ(job->status, 202) << job->body;
  const int job_id = Json(job)["id"].get<int>();
  nlohmann::json state;
  for (int i = 0; i < 600; ++i) {
    state = Json(running.client().Get(Running::Api(fmt::format("/api/jobs/{}", job_id))));
    if (state["state"] != "queued" && state["state"] != "running") break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_EQ(state["state"], "failed") << state.dump();
  EXPECT_NE(state.value("error", "").find("not enough memory for this edit"), std::string::npos)
      << state.dump();
  document = Json(running.client().Get(Running::Api(fmt::format("/api/docs/{}", id))));
  EXPECT_EQ(document["version"], accepted);
  EXPECT_EQ(document["object_cells"], 0);
  // Undo frees nothing but needs nothing: it still works, and the server answers.
  EXPECT_EQ(running.client()
                .Post(Running::Api(fmt::format("/api/docs/{}/undo", id)), "{}", "application/json")
                ->status,
            200);
  document = Json(running.client().Get(Running::Api(fmt::format("/api/docs/{}", id))));
  EXPECT_EQ(document["object_stroke_cells"], accepted - 1);
}

// {"object": [[[...]]]} nested `levels` deep.
std::string DeepJson(int levels) {
  return R"({"object": )" + std::string(levels, '[') + std::string(levels, ']') + "}";
}

TEST(ServerSafetyTest, DeeplyNestedJsonIsRefusedOnEveryRouteAndTheServerStaysUp) {
  Running running;
  const int id = running.OpenTiny();
  const std::string deep = DeepJson(100'000);  // ~200 KB
  for (const std::string& route : {"strokes", "segment", "remove", "fill", "recolor", "verify", "align",
                                   "photo-match", "inpaint/review"}) {
    const auto answer = running.client().Post(Running::Api(fmt::format("/api/docs/{}/{}", id, route)), deep,
                                              "application/json");
    ASSERT_TRUE(answer) << route;
    EXPECT_EQ(answer->status, 400) << route << ": " << answer->body.substr(0, 300);
  }
  EXPECT_EQ(running.client().Post(Running::Api("/api/models"), deep, "application/json")->status, 400);
  EXPECT_EQ(running.client().Get(Running::Api("/api/health"))->status, 200);
  EXPECT_EQ(running.client().Get(Running::Api(fmt::format("/api/docs/{}", id)))->status, 200);
}

TEST(ServerSafetyTest, ErrorsDoNotEchoUnboundedInput) {
  Running running;
  const int id = running.OpenTiny();
  const std::string strokes = Running::Api(fmt::format("/api/docs/{}/strokes", id));
  const std::string long_text(100'000, 'x');
  const auto bad_cell =
      running.client().Post(strokes, nlohmann::json{{"object", {{1, long_text}}}}.dump(), "application/json");
  EXPECT_EQ(bad_cell->status, 400);
  EXPECT_LT(bad_cell->body.size(), 2000u) << bad_cell->body.substr(0, 300);
  const auto not_json = running.client().Post(strokes, "{\"a\": \"" + long_text, "application/json");
  EXPECT_EQ(not_json->status, 400);
  EXPECT_LT(not_json->body.size(), 2000u) << not_json->body.substr(0, 300);
  const auto no_route = running.client().Get(Running::Api("/api/" + std::string(5'000, 'y')));
  EXPECT_EQ(no_route->status, 404);
  EXPECT_LT(no_route->body.size(), 2000u);
  // Bytes that are not UTF-8, quoted back: still a JSON answer, not a 500.
  const auto odd = running.client().Get(Running::Api("/api/open?path=%FF%FEscan.ptx"));
  EXPECT_EQ(odd->status, 403) << odd->body;
  EXPECT_NO_THROW(Json(odd));
}

TEST(ServerSafetyTest, FieldsOfTheWrongTypeAre400) {
  Running running;
  const int id = running.OpenTiny();
  const auto post = [&](const std::string& route, const std::string& body) {
    return running.client().Post(Running::Api(route), body, "application/json")->status;
  };
  const std::string doc = fmt::format("/api/docs/{}/", id);
  EXPECT_EQ(post(doc + "strokes", R"({"radius": "big"})"), 400);
  EXPECT_EQ(post(doc + "strokes", R"({"clear": 3})"), 400);
  EXPECT_EQ(post(doc + "segment", R"({"refine": "yes"})"), 400);
  EXPECT_EQ(post(doc + "fill", R"({"margin_cells": "a"})"), 400);
  EXPECT_EQ(post(doc + "fill", R"({"hole": 7})"), 400);
  EXPECT_EQ(post(doc + "verify", R"({"model": "car"})"), 400);
  EXPECT_EQ(post(doc + "photo-match", R"({"model": 3})"), 400);
  EXPECT_EQ(post("/api/models", R"({"model": 5})"), 400);
}

TEST(ServerSafetyTest, JsonBodiesMustSayTheirType) {
  Running running;
  const std::string strokes = Running::Api(fmt::format("/api/docs/{}/strokes", running.OpenTiny()));
  const std::string body = R"({"object": [[2, 2]]})";
  // What a form or a no-preflight fetch of another page could send.
  for (const char* type : {"text/plain", "application/x-www-form-urlencoded", "text/json"}) {
    const auto refused = running.client().Post(strokes, body, type);
    EXPECT_EQ(refused->status, 415) << type;
  }
  // A form's multipart body (which httplib parses into fields, leaving no body): refused too, not taken as {}.
  const std::string form = "--x\r\nContent-Disposition: form-data; name=\"object\"\r\n\r\n1\r\n--x--\r\n";
  EXPECT_EQ(running.client().Post(strokes, form, "multipart/form-data; boundary=x")->status, 415);
  EXPECT_EQ(running.client().Post(strokes, body, "application/json; charset=utf-8")->status, 200);
  EXPECT_EQ(running.client().Post(strokes, body, "Application/JSON")->status, 200);
}

TEST(ServerSafetyTest, OnlyThisServersNamesAndItsOwnPageMayCall) {
  Running running;
  auto& client = running.client();
  const int port = running.port();
  const std::string health = Running::Api("/api/health");
  const auto status = [&](httplib::Headers headers) { return client.Get(health, headers)->status; };
  EXPECT_EQ(status({}), 200);
  for (const std::string& host : {fmt::format("localhost:{}", port), fmt::format("127.0.0.1:{}", port),
                                  fmt::format("[::1]:{}", port), fmt::format("LOCALHOST:{}", port)}) {
    EXPECT_EQ(status({{"Host", host}}), 200) << host;
  }
  // DNS rebinding: a page of evil.example reaching this port through its own name.
  for (const std::string& host : {fmt::format("evil.example:{}", port), std::string("127.0.0.1"),
                                  fmt::format("127.0.0.1:{}", port + 1)}) {
    EXPECT_EQ(status({{"Host", host}}), 403) << host;
  }
  // Cross-site request forgery: another page posting with the token (a form, a text/plain fetch).
  const std::string strokes = Running::Api(fmt::format("/api/docs/{}/strokes", running.OpenTiny()));
  const auto post = [&](httplib::Headers headers) {
    return client.Post(strokes, headers, R"({"object": [[2, 2]]})", "application/json")->status;
  };
  EXPECT_EQ(post({{"Origin", "http://evil.example"}}), 403);
  EXPECT_EQ(post({{"Origin", "null"}}), 403);
  EXPECT_EQ(post({{"Origin", fmt::format("http://localhost:{}", port + 1)}}), 403);  // another local server
  EXPECT_EQ(post({{"Sec-Fetch-Site", "cross-site"}}), 403);
  EXPECT_EQ(post({{"Sec-Fetch-Site", "same-site"}}), 403);
  EXPECT_EQ(post({{"Origin", fmt::format("http://127.0.0.1:{}", port)}, {"Sec-Fetch-Site", "same-origin"}}),
            200);
  EXPECT_EQ(post({{"Origin", fmt::format("http://localhost:{}", port)}}), 200);
  EXPECT_EQ(client.Delete(Running::Api("/api/docs/1"), {{"Sec-Fetch-Site", "cross-site"}})->status, 403);
  // The page itself is refused under a foreign name too.
  EXPECT_EQ(client.Get("/", {{"Host", "evil.example"}})->status, 403);
}

// A folder holding a stand-in for the built editor.
struct WebDir {
  WebDir() : path(fs::temp_directory_path() / fmt::format("lidarshop_web_{}", getpid())) {
    fs::create_directories(path);
    std::ofstream(path / "index.html") << "<!doctype html><title>editor</title>";
  }
  ~WebDir() { fs::remove_all(path); }
  fs::path path;
};

TEST(ServerSafetyTest, EveryAnswerCarriesTheSecurityHeaders) {
  WebDir web;
  ServerOptions options;
  options.web_dir = web.path.string();
  Running running(options);
  const int id = running.OpenTiny();
  auto& client = running.client();
  const std::vector<std::pair<std::string, httplib::Result>> answers = [&] {
    std::vector<std::pair<std::string, httplib::Result>> all;
    all.emplace_back("json", client.Get(Running::Api("/api/health")));
    all.emplace_back("401", client.Get("/api/health"));
    all.emplace_back("404", client.Get(Running::Api("/api/nothing")));
    all.emplace_back("403", client.Get(Running::Api("/api/health"), {{"Origin", "http://evil.example"}}));
    all.emplace_back("png", client.Get(Running::Api(fmt::format("/api/docs/{}/image.png", id))));
    all.emplace_back("page", client.Get("/"));
    all.emplace_back("missing file", client.Get("/nothing.js"));
    return all;
  }();
  for (const auto& [what, answer] : answers) {
    ASSERT_TRUE(answer) << what;
    EXPECT_EQ(answer->get_header_value("X-Frame-Options"), "DENY") << what;
    EXPECT_EQ(answer->get_header_value("X-Content-Type-Options"), "nosniff") << what;
    EXPECT_EQ(answer->get_header_value("Referrer-Policy"), "no-referrer") << what;
    const std::string policy = answer->get_header_value("Content-Security-Policy");
    EXPECT_NE(policy.find("default-src 'self'"), std::string::npos) << what;
    EXPECT_NE(policy.find("frame-ancestors 'none'"), std::string::npos) << what;
  }
  EXPECT_EQ(answers[5].second->status, 200);
  EXPECT_NE(answers[5].second->body.find("editor"), std::string::npos);
}

TEST(ServerSafetyTest, TheFirstPageLoadMovesTheTokenIntoACookie) {
  WebDir web;
  ServerOptions options;
  options.web_dir = web.path.string();
  Running running(options);
  auto& client = running.client();
  const auto first = client.Get("/?token=secret-token&view=3d");
  ASSERT_EQ(first->status, 303) << first->body;
  EXPECT_EQ(first->get_header_value("Location"), "/?view=3d");  // the token left out of the URL
  const std::string cookie = first->get_header_value("Set-Cookie");
  const std::string name = fmt::format("lidarshop_token_{}", running.port());
  EXPECT_EQ(cookie.rfind(name + "=secret-token;", 0), 0u) << cookie;
  for (const char* attribute : {"HttpOnly", "SameSite=Strict", "Path=/"})
    EXPECT_NE(cookie.find(attribute), std::string::npos) << attribute;
  // The page's calls carry the cookie (and an empty token, as the page without a token in its URL sends).
  EXPECT_EQ(client.Get("/api/health?token=", {{"Cookie", "other=1; " + name + "=secret-token"}})->status,
            200);
  EXPECT_EQ(client.Get("/api/health", {{"Cookie", name + "=wrong-token!"}})->status, 401);
  EXPECT_EQ(client.Get("/api/health", {{"Cookie", "lidarshop_token_1=secret-token"}})->status, 401);
  // Scripts keep the query and the header.
  EXPECT_EQ(client.Get(Running::Api("/api/health"))->status, 200);
  EXPECT_EQ(client.Get("/api/health", {{"Authorization", "Bearer secret-token"}})->status, 200);
  // A wrong token sets nothing: the page loads and its calls will be refused.
  const auto wrong = client.Get("/?token=guess");
  EXPECT_EQ(wrong->status, 200);
  EXPECT_FALSE(wrong->has_header("Set-Cookie"));
}

int Connect(int port) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  EXPECT_EQ(connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)), 0);
  timeval timeout{5, 0};
  setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &timeout, sizeof(timeout));
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof(timeout));
  return fd;
}

TEST(ServerSafetyTest, AChunkedBodyOf100MBIsRefused) {
  Running running;
  const int id = running.OpenTiny();
  const int fd = Connect(running.port());
  const std::string head = fmt::format(
      "POST /api/docs/{}/strokes?token=secret-token HTTP/1.1\r\nHost: 127.0.0.1:{}\r\n"
      "Content-Type: application/json\r\nTransfer-Encoding: chunked\r\n\r\n",
      id, running.port());
  // The answer is read as it comes (before the server closes a connection still sending).
  std::string answer;
  std::thread reader([&] {
    char buffer[4096];
    const ssize_t n = recv(fd, buffer, sizeof(buffer), 0);
    if (n > 0) answer.assign(buffer, static_cast<size_t>(n));
  });
  ASSERT_EQ(send(fd, head.data(), head.size(), MSG_NOSIGNAL), static_cast<ssize_t>(head.size()));
  // 100 chunks of 1 MiB: the server must answer without taking them.
  const std::string chunk = fmt::format("{:x}\r\n", 1 << 20) + std::string(1 << 20, ' ') + "\r\n";
  int64_t sent = 0;
  for (int i = 0; i < 100; ++i) {
    const ssize_t n = send(fd, chunk.data(), chunk.size(), MSG_NOSIGNAL);
    if (n <= 0) break;
    sent += n;
  }
  reader.join();
  close(fd);
  EXPECT_EQ(answer.rfind("HTTP/1.1 411", 0), 0u) << answer;
  EXPECT_LT(sent, int64_t{100} << 20);  // the connection was closed before the body was taken
  EXPECT_EQ(Json(running.client().Get(Running::Api(fmt::format("/api/docs/{}", id))))["version"], 0);
}

// A PNG claiming `width` x `height` (8-bit RGB) in its header, with no pixel data.
std::string PngHeader(uint32_t width, uint32_t height) {
  const uint8_t signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  std::string png(reinterpret_cast<const char*>(signature), 8);
  const auto be32 = [&](uint32_t v) {
    for (int shift = 24; shift >= 0; shift -= 8) png.push_back(static_cast<char>((v >> shift) & 0xff));
  };
  be32(13);
  png += "IHDR";
  be32(width);
  be32(height);
  png += std::string("\x08\x02\x00\x00\x00", 5);
  be32(0);  // CRC (not checked by header readers)
  be32(0);  // an empty IDAT chunk
  png += "IDAT";
  be32(0);
  be32(0);  // and the end
  png += "IEND";
  png += std::string("\xae\x42\x60\x82", 4);
  return png;
}

TEST(ServerSafetyTest, APhotoIsMeasuredByItsHeaderBeforeDecoding) {
  {
    Running running;  // the default limit
    const std::string photo = Running::Api(fmt::format("/api/docs/{}/photo", running.OpenTiny()));
    const auto huge = running.client().Post(photo, PngHeader(16000, 16000), "image/png");
    EXPECT_EQ(huge->status, 413) << huge->body;
    EXPECT_NE(ErrorOf(huge).find("16000 x 16000"), std::string::npos) << huge->body;
  }
  ServerOptions options;
  options.max_photo_pixels = 100'000;
  Running running(options);
  const std::string photo = Running::Api(fmt::format("/api/docs/{}/photo", running.OpenTiny()));
  const auto encode = [](int width, int height) {
    std::vector<uint8_t> png;
    cv::imencode(".png", cv::Mat(height, width, CV_8UC3, cv::Scalar(10, 200, 30)), png);
    return std::string(png.begin(), png.end());
  };
  EXPECT_EQ(running.client().Post(photo, encode(400, 300), "image/png")->status, 413);
  const auto fits = running.client().Post(photo, encode(300, 300), "image/png");
  ASSERT_EQ(fits->status, 200) << fits->body;
  EXPECT_EQ(Json(fits)["width_px"], 300);
}

TEST(ServerSafetyTest, SavesGoThroughAPrivateFolder) {
  Running running;
  const int id = running.OpenTiny();
  // Another user's trap at the old predictable place: /tmp/lidarshop-save-<PID> as a symlink to a folder of
  // theirs, watched for files appearing.
  const fs::path trap = fs::temp_directory_path() / fmt::format("lidarshop_trap_{}", getpid());
  const fs::path predictable = fs::temp_directory_path() / fmt::format("lidarshop-save-{}", getpid());
  fs::remove_all(trap);
  fs::remove(predictable);
  fs::create_directories(trap);
  fs::create_directory_symlink(trap, predictable);
  const int watch = inotify_init1(IN_NONBLOCK);
  ASSERT_GE(watch, 0);
  ASSERT_GE(inotify_add_watch(watch, trap.c_str(), IN_CREATE | IN_MOVED_TO), 0);
  for (const char* format : {"e57", "ply"}) {
    const auto saved =
        running.client().Get(Running::Api(fmt::format("/api/docs/{}/save?format={}", id, format)));
    EXPECT_EQ(saved->status, 200) << format;
    EXPECT_GT(saved->body.size(), 1000u) << format;
  }
  char events[4096];
  const ssize_t read_bytes = read(watch, events, sizeof(events));
  close(watch);
  EXPECT_LE(read_bytes, 0) << "a file was written into the planted folder";
  EXPECT_TRUE(fs::is_empty(trap));
  EXPECT_TRUE(fs::is_symlink(predictable));
  fs::remove(predictable);
  fs::remove_all(trap);
}

// Random JSON bodies, built from the keys the routes read with values of every type and odd sizes, sent to
// every JSON route with the token: each answer is a 2xx or 4xx with a JSON body, never a 500 nor a crash
// (a fuzzer's way over the routes, with a fixed seed; fuzz/ has none for the server).
const std::vector<std::string>& Keys() {
  static const std::vector<std::string> keys = {
      "object",       "background",   "erase",      "radius",         "clear",
      "hole",         "hole_polygon", "erase_hole", "options",        "refine",
      "margin_cells", "pairs",        "pixel",      "cell",           "point",
      "target",       "target_cell",  "with_scale", "apply",          "model",
      "threshold_px", "pose",         "x_m",        "yaw_deg",        "world_from_model",
      "candidate",    "source",       "channel",    "fill",           "method",
      "keep_object",  "pixel_a",      "pixel_b",    "gmm_components", "slot"};
  return keys;
}

const std::string& RandomKey(std::mt19937& random) {
  return Keys()[std::uniform_int_distribution<size_t>(0, Keys().size() - 1)(random)];
}

nlohmann::json RandomValue(std::mt19937& random, int depth) {
  const int kind = std::uniform_int_distribution<int>(0, depth >= 4 ? 5 : 7)(random);
  const auto integer = [&] {
    static const int64_t odd[] = {0, 1, -1, 2, 5, 30, 59, 60, 1000, -2147483648LL, 2147483647LL, 1LL << 40};
    return odd[std::uniform_int_distribution<int>(0, 11)(random)];
  };
  switch (kind) {
    case 0:
      return nullptr;
    case 1:
      return std::uniform_int_distribution<int>(0, 1)(random) == 1;
    case 2:
    case 3:
      return integer();
    case 4:
      return std::uniform_real_distribution<double>(-1e3, 1e3)(random) *
             (std::uniform_int_distribution<int>(0, 5)(random) == 0 ? 1e300 : 1.0);
    case 5:
      return RandomKey(random);
    case 6: {
      nlohmann::json array = nlohmann::json::array();
      const int n = std::uniform_int_distribution<int>(0, 4)(random);
      for (int i = 0; i < n; ++i) array.push_back(RandomValue(random, depth + 1));
      return array;
    }
    default: {
      nlohmann::json object = nlohmann::json::object();
      const int n = std::uniform_int_distribution<int>(0, 4)(random);
      for (int i = 0; i < n; ++i) {
        object[RandomKey(random)] = RandomValue(random, depth + 1);
      }
      return object;
    }
  }
}

TEST(ServerSafetyTest, RandomJsonBodiesOnEveryRouteGetNo500) {
  Running running;
  auto& client = running.client();
  const int id = running.OpenTiny();
  const int other = running.OpenTiny();
  ASSERT_EQ(client.Post(Running::Api("/api/models"), R"({"model": "mailbox"})", "application/json")->status,
            200);
  const std::vector<std::string> routes = {
      "strokes", "segment",     "remove", "fill",           "recolor",
      "align",   "photo-match", "verify", "inpaint/review", "inpaint/review/decide",
      "undo",    "redo"};
  std::mt19937 random(36);
  std::map<int, int> statuses;
  for (int i = 0; i < 1500; ++i) {
    // Mostly objects of the routes' keys (those reach the routes' own checks), sometimes any JSON value.
    nlohmann::json body = nlohmann::json::object();
    if (i % 7 == 0) {
      body = RandomValue(random, 0);
    } else {
      const int keys = std::uniform_int_distribution<int>(1, 4)(random);
      for (int k = 0; k < keys; ++k) body[RandomKey(random)] = RandomValue(random, 1);
    }
    const bool models = i % 13 == 0;
    const std::string path =
        models ? "/api/models"
               : fmt::format("/api/docs/{}/{}", i % 2 ? id : other, routes[i % routes.size()]);
    const auto answer = client.Post(Running::Api(path), body.dump(), "application/json");
    ASSERT_TRUE(answer) << path << " " << body.dump();
    ++statuses[answer->status];
    EXPECT_LT(answer->status, 500) << path << " " << body.dump() << " -> " << answer->body;
    EXPECT_NO_THROW(nlohmann::json::parse(answer->body)) << path << " " << answer->body;
  }
  EXPECT_GT(statuses[400], 50);  // the checks were reached
  EXPECT_EQ(client.Get(Running::Api("/api/health"))->status, 200);
}

TEST(ServerSafetyTest, UrlsAndBindsBeyondLoopback) {
  EXPECT_EQ(EditorUrl("::1", 8080, "t"), "http://[::1]:8080/?token=t");
  EXPECT_EQ(EditorUrl("fe80::1", 80, "t"), "http://[fe80::1]:80/?token=t");
  EXPECT_EQ(EditorUrl("127.0.0.1", 8080, "t"), "http://127.0.0.1:8080/?token=t");
  EXPECT_EQ(EditorUrl("localhost", 1, "t"), "http://localhost:1/?token=t");
  for (const char* loopback : {"127.0.0.1", "127.0.1.1", "localhost", "::1"})
    EXPECT_EQ(BindWarning(loopback), "") << loopback;
  for (const char* beyond : {"0.0.0.0", "::", "192.168.1.5", "10.0.0.2", "2001:db8::1"}) {
    EXPECT_NE(BindWarning(beyond).find("warning"), std::string::npos) << beyond;
    EXPECT_NE(BindWarning(beyond).find("127.0.0.1"), std::string::npos) << beyond;
  }
  // Bound to every address: the warning is printed on stderr, and the machine's own names are accepted.
  ServerOptions options;
  options.host = "0.0.0.0";
  options.port = 0;
  options.token = "t";
  EditorServer server(options);
  testing::internal::CaptureStderr();
  server.Bind();
  const std::string printed = testing::internal::GetCapturedStderr();
  EXPECT_NE(printed.find("warning: listening on 0.0.0.0"), std::string::npos) << printed;
  EXPECT_EQ(server.Url().rfind("http://0.0.0.0:", 0), 0u);
}

}  // namespace
}  // namespace lidarshop::server
