// The editor's station routes (routes_stations.cc, docs/api.md "Stations"): a file of several scans and the
// built-in site opened as sites, open scans grouped, Clean over the built-in parking_lot_stations (the late
// sedan at station 2 goes, the hatchback two stations saw stays), undo, bad station indices and the
// security checks every state-changing route goes through.
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <map>
#include <random>
#include <thread>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "lidarshop/io/scan_io.h"
#include "lidarshop/scanner/scene.h"
#include "lidarshop/scanner/site_scan.h"
#include "server.h"
#include "server_test_util.h"

namespace lidarshop::server {
namespace {

namespace fs = std::filesystem;

constexpr int32_t kHatchbackLabel = 3, kLateSedanLabel = 7;  // data/scenes/parking_lot_stations.json

// One server for the suite, with the built-in site parking_lot_stations (on a coarser grid than the built-in
// 960 x 560, for time) and a root folder holding it as one E57 of three data3D.
class StationsServerTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    base_ = fs::temp_directory_path() / fmt::format("lidarshop_server_stations_test_{}", getpid());
    fs::remove_all(base_);
    fs::create_directories(base_ / "root");
    SceneDescription scene = LoadScene(LIDARSHOP_SOURCE_DIR "/data/scenes/parking_lot_stations.json");
    for (ScannerOptions& station : scene.stations) {
      station.columns = 480;
      station.rows = 280;
    }
    site_ = new std::vector<Scan>(ScanStations(scene));
    WriteScanFile((base_ / "root" / "site.e57").string(), *site_);
    ServerOptions options;
    options.port = 0;
    options.token = "secret-token";
    options.roots = {(base_ / "root").string()};
    options.max_documents = 100;
    options.builtin_scenes = {"parking_lot_stations"};
    options.scan_builtin = [](const std::string&) { return (*site_)[0]; };
    options.scan_builtin_stations = [](const std::string&) { return *site_; };
    running_ = new RunningServer(options, 120);
    server_ = &running_->server();
    client_ = &running_->client();
  }
  static void TearDownTestSuite() {
    delete running_;
    delete site_;
    fs::remove_all(base_);
  }

  static std::string Api(const std::string& path) {
    return path + (path.find('?') == std::string::npos ? "?" : "&") + "token=secret-token";
  }
  static nlohmann::json Json(const httplib::Result& result) { return nlohmann::json::parse(result->body); }
  static httplib::Result Post(const std::string& path, const nlohmann::json& body) {
    return client_->Post(Api(path), body.dump(), "application/json");
  }
  // Opens a site; returns its JSON (with "document", the station shown).
  static nlohmann::json OpenSite(const nlohmann::json& body) {
    const auto result = Post("/api/sites", body);
    EXPECT_EQ(result->status, 200) << result->body;
    return Json(result);
  }
  static nlohmann::json Wait(const nlohmann::json& job) {
    for (int i = 0; i < 1200; ++i) {
      const auto json = Json(client_->Get(Api(fmt::format("/api/jobs/{}", job["id"].get<int>()))));
      const std::string state = json["state"];
      if (state != "queued" && state != "running") return json;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    ADD_FAILURE() << "job did not finish";
    return {};
  }
  static std::vector<int64_t> Removed(int document) {
    return Json(client_->Get(Api(fmt::format("/api/docs/{}/removed", document))))["cells"]
        .get<std::vector<int64_t>>();
  }

  static inline fs::path base_;
  static inline std::vector<Scan>* site_ = nullptr;
  static inline EditorServer* server_ = nullptr;
  static inline RunningServer* running_ = nullptr;
  static inline httplib::Client* client_ = nullptr;
};

TEST_F(StationsServerTest, AMultiScanE57OpensAsASiteWithItsStationsListed) {
  const nlohmann::json site = OpenSite({{"path", "site.e57"}, {"station", 1}});
  ASSERT_EQ(site["stations"].size(), 3u);
  EXPECT_EQ(site["station"], 1);
  const int document = site["document"];
  EXPECT_EQ(site["stations"][1]["document"], document);
  EXPECT_TRUE(site["stations"][1]["current"]);
  EXPECT_FALSE(site["stations"][0]["current"]);
  // Where each station stands and looks (the scene's stations: x = 0, -8, +8; yaw 0, -30, +30 degrees).
  const double x[] = {0, -8, 8}, heading[] = {0, -30, 30};
  for (int i = 0; i < 3; ++i) {
    const auto& station = site["stations"][i];
    EXPECT_EQ(station["index"], i);
    EXPECT_EQ(station["name"], fmt::format("station{}", i));
    EXPECT_NEAR(station["position_m"][0].get<double>(), x[i], 1e-6);
    EXPECT_NEAR(station["position_m"][2].get<double>(), 1.6, 1e-6);
    EXPECT_NEAR(station["heading_deg"].get<double>(), heading[i], 1e-6);
    EXPECT_EQ(station["returns"].get<int64_t>(), (*site_)[i].CountValid());
    EXPECT_TRUE(station["open"]);
  }
  // Every station is an open scan of its own, named FILE#N; each lists the same site with itself current.
  const auto info = Json(client_->Get(Api(fmt::format("/api/docs/{}", document))));
  EXPECT_EQ(info["name"], "site.e57#1");
  const int other = site["stations"][2]["document"];
  const auto listed = Json(client_->Get(Api(fmt::format("/api/docs/{}/stations", other))));
  EXPECT_EQ(listed["site"], site["site"]);
  EXPECT_EQ(listed["station"], 2);
  EXPECT_TRUE(listed["stations"][2]["current"]);
  // A scan opened alone is in no site.
  const auto alone = client_->Get(Api("/api/open?path=site.e57&scan=0"));
  ASSERT_EQ(alone->status, 200);
  const auto none =
      Json(client_->Get(Api(fmt::format("/api/docs/{}/stations", Json(alone)["id"].get<int>()))));
  EXPECT_TRUE(none["site"].is_null());
  EXPECT_EQ(none["stations"].size(), 0u);
  // Open scans grouped into a site by the user.
  const int a = Json(alone)["id"];
  const nlohmann::json grouped = OpenSite({{"documents", {a, other}}, {"name", "mine"}});
  EXPECT_EQ(grouped["name"], "mine");
  ASSERT_EQ(grouped["stations"].size(), 2u);
  EXPECT_NEAR(grouped["stations"][1]["position_m"][0].get<double>(), 8.0, 1e-6);
  const auto sites = Json(client_->Get(Api("/api/sites")));
  EXPECT_GE(sites["sites"].size(), 2u);
}

TEST_F(StationsServerTest, CleanOnTheBuiltinSiteRemovesTheLateSedanAndUndoes) {
  const nlohmann::json site = OpenSite({{"scene", "parking_lot_stations"}, {"station", 2}});
  ASSERT_EQ(site["stations"].size(), 3u);
  const int document = site["document"];
  std::vector<int> documents;
  for (const auto& station : site["stations"]) documents.push_back(station["document"]);
  const auto started = Post(fmt::format("/api/docs/{}/clean", document), nlohmann::json::object());
  ASSERT_EQ(started->status, 202) << started->body;
  const nlohmann::json job = Wait(Json(started));
  ASSERT_EQ(job["state"], "done") << job.dump();
  const nlohmann::json& result = job["result"];
  EXPECT_EQ(result["station"], 2);
  ASSERT_EQ(result["stations"].size(), 3u);

  // Station 2: the removed cells are the late sedan's (it parked after stations 0 and 1 looked there).
  const Scan& station2 = (*site_)[2];
  const std::vector<int64_t> removed = Removed(document);
  EXPECT_EQ(static_cast<int64_t>(removed.size()), result["removed_cells"].get<int64_t>());
  int64_t sedan_cells = 0, removed_sedan = 0;
  for (int r = 0; r < station2.rows; ++r)
    for (int c = 0; c < station2.cols; ++c)
      sedan_cells += station2.valid.at<uint8_t>(r, c) && station2.label.at<int32_t>(r, c) == kLateSedanLabel;
  for (const int64_t cell : removed)
    removed_sedan +=
        station2.label.at<int32_t>(int(cell / station2.cols), int(cell % station2.cols)) == kLateSedanLabel;
  ASSERT_GT(sedan_cells, 100);
  EXPECT_GT(removed_sedan, 0.8 * sedan_cells) << removed_sedan << " of " << sedan_cells;
  EXPECT_GT(removed_sedan, 0.9 * removed.size()) << removed_sedan << " of " << removed.size();
  EXPECT_TRUE(result["stations"][2]["changed"]);
  // The hatchback, there at stations 0 and 1 (each confirms the other), stays at both: at most a few rim cells
  // of it go (mixed pixels at its edges that the other station saw past).
  for (int i = 0; i < 2; ++i) {
    const Scan& station = (*site_)[i];
    int64_t hatchback_cells = 0, removed_hatchback = 0;
    for (int r = 0; r < station.rows; ++r)
      for (int c = 0; c < station.cols; ++c)
        hatchback_cells +=
            station.valid.at<uint8_t>(r, c) && station.label.at<int32_t>(r, c) == kHatchbackLabel;
    for (const int64_t cell : Removed(documents[i]))
      removed_hatchback +=
          station.label.at<int32_t>(int(cell / station.cols), int(cell % station.cols)) == kHatchbackLabel;
    ASSERT_GT(hatchback_cells, 1000) << "station " << i;
    EXPECT_LT(removed_hatchback, 0.05 * hatchback_cells) << "station " << i << ": " << removed_hatchback;
  }
  // One edit of station 2's scan: its list says so, and undo takes it back (the removed cells with it).
  const auto listed = Json(client_->Get(Api(fmt::format("/api/docs/{}/stations", document))));
  EXPECT_EQ(listed["stations"][2]["removed_cells"], result["removed_cells"]);
  const auto info = Json(client_->Get(Api(fmt::format("/api/docs/{}", document))));
  EXPECT_TRUE(info["can_undo"]);
  EXPECT_GT(info["synthesized_cells"].get<int64_t>(), 0);  // the holes filled
  ASSERT_EQ(Post(fmt::format("/api/docs/{}/undo", document), nlohmann::json::object())->status, 200);
  EXPECT_TRUE(Removed(document).empty());
  const auto undone = Json(client_->Get(Api(fmt::format("/api/docs/{}", document))));
  EXPECT_EQ(undone["valid_cells"].get<int64_t>(), station2.CountValid());
  EXPECT_EQ(undone["synthesized_cells"], 0);
}

TEST_F(StationsServerTest, BadStationIndicesAre400) {
  EXPECT_EQ(Post("/api/sites", {{"scene", "parking_lot_stations"}, {"station", 3}})->status, 400);
  EXPECT_EQ(Post("/api/sites", {{"path", "site.e57"}, {"station", -1}})->status, 400);
  EXPECT_EQ(Post("/api/sites", {{"path", "site.e57"}, {"station", "one"}})->status, 400);
  EXPECT_EQ(Post("/api/sites", nlohmann::json::object())->status, 400);
  EXPECT_EQ(Post("/api/sites", {{"scene", "nowhere"}})->status, 404);
  EXPECT_EQ(Post("/api/sites", {{"path", "../site.e57"}})->status, 403);
  EXPECT_EQ(Post("/api/sites", {{"documents", nlohmann::json::array({1})}})->status, 400);
  EXPECT_EQ(Post("/api/sites", {{"documents", {1, 1}}})->status, 400);
  EXPECT_EQ(Post("/api/sites", {{"documents", {1, 99999}}})->status, 404);
  const nlohmann::json site = OpenSite({{"path", "site.e57"}});
  const std::string clean = fmt::format("/api/docs/{}/clean", site["document"].get<int>());
  for (const nlohmann::json& stations :
       {nlohmann::json{0, 3}, nlohmann::json{-1, 0}, nlohmann::json{0, 0}, nlohmann::json{1},
        nlohmann::json("all"), nlohmann::json{0, "1"}, nlohmann::json{0, 1.5}}) {
    const auto refused = Post(clean, {{"stations", stations}});
    EXPECT_EQ(refused->status, 400) << stations.dump() << " " << refused->body;
  }
  EXPECT_NE(Post(clean, {{"stations", {0, 3}}})->body.find("station 3 is out of range"), std::string::npos);
  EXPECT_EQ(Post(clean, {{"options", {{"margin_cells", -4}}}})->status, 400);
  EXPECT_EQ(Post("/api/docs/99999/clean", nlohmann::json::object())->status, 404);
  // A scan in no site cannot be cleaned.
  const auto alone = client_->Get(Api("/api/open?path=site.e57&scan=1"));
  const auto refused =
      Post(fmt::format("/api/docs/{}/clean", Json(alone)["id"].get<int>()), nlohmann::json::object());
  EXPECT_EQ(refused->status, 422);
  EXPECT_NE(refused->body.find("not a station of a site"), std::string::npos) << refused->body;
}

TEST_F(StationsServerTest, StateChangingStationRoutesGoThroughTheSecurityChecks) {
  const nlohmann::json site = OpenSite({{"path", "site.e57"}});
  const std::string clean = fmt::format("/api/docs/{}/clean", site["document"].get<int>());
  const std::string body = R"({"path": "site.e57"})";
  for (const std::string& path : {std::string("/api/sites"), clean}) {
    // No token: 401 before routing.
    EXPECT_EQ(client_->Post(path, body, "application/json")->status, 401) << path;
    // Another page (CSRF): 403.
    EXPECT_EQ(client_->Post(Api(path), {{"Origin", "http://evil.example"}}, body, "application/json")->status,
              403)
        << path;
    EXPECT_EQ(client_->Post(Api(path), {{"Sec-Fetch-Site", "cross-site"}}, body, "application/json")->status,
              403)
        << path;
    // What a form or a no-preflight fetch could send: 415.
    for (const char* type : {"text/plain", "application/x-www-form-urlencoded"})
      EXPECT_EQ(client_->Post(Api(path), body, type)->status, 415) << path << " " << type;
  }
  // Reading needs the token too.
  EXPECT_EQ(client_->Get("/api/sites")->status, 401);
  EXPECT_EQ(client_->Get(fmt::format("/api/docs/{}/stations", site["document"].get<int>()))->status, 401);
}

// Fill from stations: the late sedan's cells of station 2 painted as a hole and filled with what stations 0 and
// 1 measured behind it (marked from_station, their own layer in the points), one undoable edit.
TEST_F(StationsServerTest, FillFromStationsTakesTheOtherStationsPoints) {
  const nlohmann::json site = OpenSite({{"path", "site.e57"}, {"station", 2}});
  const int document = site["document"];
  const Scan& station2 = (*site_)[2];
  nlohmann::json cells = nlohmann::json::array();
  for (int r = 0; r < station2.rows; ++r)
    for (int c = 0; c < station2.cols; ++c)
      if (station2.valid.at<uint8_t>(r, c) && station2.label.at<int32_t>(r, c) == kLateSedanLabel)
        cells.push_back({r, c});
  ASSERT_GT(cells.size(), 100u);
  ASSERT_EQ(Post(fmt::format("/api/docs/{}/strokes", document), {{"hole", cells}, {"radius", 1}})->status,
            200);
  const std::string fill = fmt::format("/api/docs/{}/fill-from-stations", document);
  EXPECT_EQ(Post(fill, {{"hole", "painted"}, {"stations", {2}}})->status, 400);  // itself
  EXPECT_EQ(Post(fill, {{"hole", "painted"}, {"stations", {0, 5}}})->status, 400);
  EXPECT_EQ(Post(fill, {{"hole", "nothing"}})->status, 400);
  EXPECT_EQ(client_->Post(Api(fill), R"({"hole": "painted"})", "text/plain")->status, 415);
  const auto started = Post(fill, {{"hole", "painted"}});
  ASSERT_EQ(started->status, 202) << started->body;
  const nlohmann::json job = Wait(Json(started));
  ASSERT_EQ(job["state"], "done") << job.dump();
  const nlohmann::json& result = job["result"];
  // Stations 0 and 1 saw the bay empty: a real share of the hole comes from them (the rest is synthesized).
  EXPECT_GT(result["from_station_cells"].get<int64_t>(), 100) << result.dump();
  ASSERT_EQ(result["stations"].size(), 2u);
  // The points carry the layer's flag (8) on the cells filled from another station.
  const auto points = client_->Get(Api(fmt::format("/api/docs/{}/points", document)));
  ASSERT_EQ(points->status, 200);
  uint32_t count = 0;
  std::memcpy(&count, points->body.data() + 4, 4);
  const uint8_t* flags = reinterpret_cast<const uint8_t*>(points->body.data()) + 16 + size_t{count} * 19;
  int64_t flagged = 0;
  for (uint32_t i = 0; i < count; ++i) flagged += (flags[i] & 8) != 0;
  EXPECT_EQ(flagged, result["from_station_cells"].get<int64_t>());
  ASSERT_EQ(Post(fmt::format("/api/docs/{}/undo", document), nlohmann::json::object())->status, 200);
  EXPECT_EQ(Json(client_->Get(Api(fmt::format("/api/docs/{}", document))))["valid_cells"].get<int64_t>(),
            station2.CountValid());
}

// Malformed bodies of every shape on the station routes: a 4xx naming the problem, never a 500.
TEST_F(StationsServerTest, RandomBodiesOnTheStationRoutesGetNo500) {
  const nlohmann::json site = OpenSite({{"path", "site.e57"}});
  const int document = site["document"];
  std::mt19937 random(31);
  const std::vector<std::string> keys = {"path", "scene", "documents", "station", "stations", "name", "x"};
  const auto value = [&random]() {
    nlohmann::json values[] = {nullptr,
                               true,
                               -1,
                               0,
                               1,
                               2,
                               3,
                               1 << 30,
                               -2.5,
                               1e300,
                               "",
                               "site.e57",
                               "../site.e57",
                               "/etc/passwd",
                               "parking_lot_stations",
                               nlohmann::json::array(),
                               nlohmann::json::object(),
                               nlohmann::json{0, 1},
                               nlohmann::json{0, 0},
                               nlohmann::json{-1, 5},
                               nlohmann::json{"a", nullptr},
                               nlohmann::json{{"margin_cells", "x"}},
                               nlohmann::json{{"nope", 1}}};
    return values[std::uniform_int_distribution<size_t>(0, std::size(values) - 1)(random)];
  };
  std::map<int, int> statuses;
  for (int i = 0; i < 300; ++i) {
    nlohmann::json body = nlohmann::json::object();
    const int count = std::uniform_int_distribution<int>(1, 3)(random);
    for (int k = 0; k < count; ++k)
      body[keys[std::uniform_int_distribution<size_t>(0, keys.size() - 1)(random)]] = value();
    const bool clean = i % 2 == 1;
    // A clean with options that are not CleanOptions is refused before any job starts.
    if (clean) body["options"] = i % 4 == 1 ? value() : nlohmann::json{{"margin_cells", -1}};
    if (clean && body["options"].is_object() && body["options"].empty())
      body["options"] = nlohmann::json{{"nope", 1}};
    if (!clean && body.contains("scene") && body["scene"] == "parking_lot_stations") body["station"] = 7;
    const std::string path = clean ? fmt::format("/api/docs/{}/clean", document) : "/api/sites";
    const auto answer = Post(path, body);
    ASSERT_TRUE(answer) << path << " " << body.dump();
    ++statuses[answer->status];
    EXPECT_LT(answer->status, 500) << path << " " << body.dump() << " -> " << answer->body;
    EXPECT_NE(answer->status, 202) << path << " " << body.dump();
    EXPECT_TRUE(nlohmann::json::accept(answer->body)) << answer->body;
  }
  EXPECT_GT(statuses[400], 100);
}

}  // namespace
}  // namespace lidarshop::server
