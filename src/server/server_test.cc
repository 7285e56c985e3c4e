#include "server.h"

#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <thread>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include "lidarshop/geometry/camera.h"
#include "lidarshop/io/e57.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/scanner/photo.h"
#include "lidarshop/testing/scenes.h"
// After every Eigen include: httplib (in server_test_util.h) pulls in <resolv.h>, whose `_res` macro breaks
// Eigen's headers.
#include "server_test_util.h"

namespace lidarshop::server {
namespace {

namespace fs = std::filesystem;

// One server for the whole suite, on a free loopback port, with a root folder holding a scan, a broken file
// and a symlink leading out of the root.
class ServerTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    base_ = fs::temp_directory_path() / fmt::format("lidarshop_server_test_{}", getpid());
    fs::remove_all(base_);
    fs::create_directories(base_ / "root" / "sub");
    fs::create_directories(base_ / "outside");
    lidarshop::test_scenes::GroundAndBoxOptions scene;
    scene.rows = 60;
    scene.columns = 90;
    scan_ = new Scan(lidarshop::test_scenes::ScanScene(lidarshop::test_scenes::MakeGroundAndBoxScene(scene)));
    WriteScanFile((base_ / "root" / "sub" / "box.ptx").string(), {*scan_});
    WriteScanFile((base_ / "outside" / "secret.ptx").string(), {*scan_});
    // The same scan with its pose moved (2 m along x, 1 m along y, turned 20 degrees about z): registering
    // it to the box's scan with landmarks must bring the pose back.
    Scan moved = *scan_;
    moved.world_from_scanner = MovedPose() * scan_->world_from_scanner;
    WriteScanFile((base_ / "root" / "sub" / "moved.ptx").string(), {moved});
    std::ofstream(base_ / "root" / "broken.ptx") << "12\nnot a ptx\n";
    // A mesh whose MTL file is missing: read with a warning.
    std::ofstream(base_ / "root" / "sub" / "quad.obj")
        << "mtllib missing.mtl\nv 0 0 0\nv 2 0 0\nv 2 2 0\nv 0 2 0\nf 1 2 3 4\n";
    fs::create_symlink(base_ / "outside" / "secret.ptx", base_ / "root" / "link.ptx");
    ServerOptions options;
    options.port = 0;
    options.token = "secret-token";
    options.roots = {(base_ / "root").string()};
    options.max_body_bytes = 1 << 20;
    options.max_documents = 100;  // the tests open more than the default 16 and close none
    options.builtin_scenes = {"tiny"};
    options.scan_builtin = [](const std::string&) { return *scan_; };
    running_ = new RunningServer(options, 60);
    server_ = &running_->server();
    client_ = &running_->client();
  }
  static void TearDownTestSuite() {
    delete running_;
    delete scan_;
    fs::remove_all(base_);
  }

  static Eigen::Matrix4d MovedPose() {
    Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();
    const double angle = 20.0 * M_PI / 180.0;
    pose.topLeftCorner<2, 2>() << std::cos(angle), -std::sin(angle), std::sin(angle), std::cos(angle);
    pose(0, 3) = 2.0;
    pose(1, 3) = 1.0;
    return pose;
  }
  static std::string Api(const std::string& path) {
    return path + (path.find('?') == std::string::npos ? "?" : "&") + "token=secret-token";
  }
  static nlohmann::json Json(const httplib::Result& result) { return nlohmann::json::parse(result->body); }
  static int OpenBox() {
    const auto result = client_->Get(Api("/api/open?path=sub/box.ptx"));
    EXPECT_EQ(result->status, 200) << result->body;
    return Json(result)["id"].get<int>();
  }
  // Polls a job until it ends; returns its last JSON.
  static nlohmann::json Wait(const nlohmann::json& job) {
    for (int i = 0; i < 600; ++i) {
      const auto json = Json(client_->Get(Api(fmt::format("/api/jobs/{}", job["id"].get<int>()))));
      const std::string state = json["state"];
      if (state != "queued" && state != "running") return json;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    ADD_FAILURE() << "job did not end";
    return {};
  }
  // Strokes: a few object cells on the box (label 1), background cells on the ground (label 0).
  static std::string StrokesBody() {
    nlohmann::json object = nlohmann::json::array(), background = nlohmann::json::array();
    for (int r = 0; r < scan_->rows; ++r) {
      for (int c = 0; c < scan_->cols; ++c) {
        if (scan_->valid.at<uint8_t>(r, c) == 0 || (r + c) % 7 != 0) continue;
        (scan_->label.at<int32_t>(r, c) == 1 ? object : background).push_back({r, c});
      }
    }
    return nlohmann::json{{"object", object}, {"background", background}, {"radius", 0}}.dump();
  }

  static inline fs::path base_;
  static inline Scan* scan_ = nullptr;
  static inline EditorServer* server_ = nullptr;
  static inline RunningServer* running_ = nullptr;
  static inline httplib::Client* client_ = nullptr;
};

TEST_F(ServerTest, TokenIsRequiredBeforeRouting) {
  EXPECT_EQ(client_->Get("/api/health")->status, 401);
  EXPECT_EQ(client_->Get("/api/health?token=wrong-token!")->status, 401);
  EXPECT_EQ(client_->Get("/api/no/such/route")->status, 401);  // no route is revealed without the token
  EXPECT_EQ(client_->Get(Api("/api/health"))->status, 200);
  httplib::Headers bearer = {{"Authorization", "Bearer secret-token"}};
  EXPECT_EQ(client_->Get("/api/health", bearer)->status, 200);
  EXPECT_EQ(client_->Get(Api("/api/no/such/route"))->status, 404);
}

TEST_F(ServerTest, FilesOnlyUnderTheRoots) {
  EXPECT_EQ(client_->Get(Api("/api/open?path=../outside/secret.ptx"))->status, 403);
  EXPECT_EQ(client_->Get(Api("/api/open?path=sub/../../outside/secret.ptx"))->status, 403);
  EXPECT_EQ(client_->Get(Api("/api/open?path=" + (base_ / "outside" / "secret.ptx").string()))->status, 403);
  EXPECT_EQ(client_->Get(Api("/api/open?path=/etc/passwd"))->status, 403);
  EXPECT_EQ(client_->Get(Api("/api/open?path=link.ptx"))->status, 403);  // a symlink leading out
  EXPECT_EQ(client_->Get(Api("/api/open?path=missing.ptx"))->status, 403);
  const auto broken = client_->Get(Api("/api/open?path=broken.ptx"));
  EXPECT_EQ(broken->status, 422);
  EXPECT_NE(Json(broken)["error"].get<std::string>().find("broken.ptx"), std::string::npos);
  // The temporary of a writer killed mid-way (util/atomic_file.h) is no file to open.
  std::ofstream(base_ / "root" / "sub" / ".box.tmp99999-0.ptx") << "half";
  const auto files = Json(client_->Get(Api("/api/files")));
  EXPECT_EQ(files["files"].size(), 4u);  // box, moved, broken, link (listed; opening the link fails)
  // In name order, each saying whether it opens: the dialog starts on the first that does, not on broken.ptx.
  std::vector<std::string> readable;
  for (size_t i = 0; i < files["files"].size(); ++i) {
    const auto& file = files["files"][i];
    if (i > 0) EXPECT_LT(files["files"][i - 1]["path"].get<std::string>(), file["path"].get<std::string>());
    if (file["readable"].get<bool>())
      readable.push_back(fs::path(file["path"].get<std::string>()).filename());
    else
      EXPECT_FALSE(file["error"].get<std::string>().empty());
  }
  EXPECT_EQ(readable, (std::vector<std::string>{"box.ptx", "moved.ptx"}));
  fs::remove(base_ / "root" / "sub" / ".box.tmp99999-0.ptx");
  const auto opened = client_->Get(Api("/api/open?path=" + (base_ / "root" / "sub" / "box.ptx").string()));
  ASSERT_EQ(opened->status, 200);
  EXPECT_EQ(Json(opened)["rows"], 60);
  EXPECT_EQ(Json(opened)["cols"], 90);
}

TEST_F(ServerTest, ImagesAndPoints) {
  const int id = OpenBox();
  const auto png = client_->Get(Api(fmt::format("/api/docs/{}/image.png?channel=range", id)));
  ASSERT_EQ(png->status, 200);
  EXPECT_EQ(png->body.substr(1, 3), "PNG");
  EXPECT_EQ(client_->Get(Api(fmt::format("/api/docs/{}/image.png?channel=bogus", id)))->status, 400);
  EXPECT_EQ(client_->Get(Api("/api/docs/9999/image.png"))->status, 404);
  const auto points = client_->Get(Api(fmt::format("/api/docs/{}/points", id)));
  ASSERT_EQ(points->status, 200);
  uint32_t header[4];
  std::memcpy(header, points->body.data(), sizeof(header));
  EXPECT_EQ(std::string(points->body.data(), 4), "LSP1");
  EXPECT_EQ(header[1], static_cast<uint32_t>(scan_->CountValid()));
  EXPECT_EQ(points->body.size(), 16 + header[1] * (12 + 4 + 3 + 1));
}

TEST_F(ServerTest, MalformedRequestsGet4xx) {
  const int id = OpenBox();
  const std::string strokes = fmt::format("/api/docs/{}/strokes", id);
  EXPECT_EQ(client_->Post(Api(strokes), "{not json", "application/json")->status, 400);
  EXPECT_EQ(client_->Post(Api(strokes), "[1,2]", "application/json")->status, 400);
  EXPECT_EQ(client_->Post(Api(strokes), R"({"radius": 1e999})", "application/json")->status, 400);
  EXPECT_EQ(client_->Post(Api(strokes), R"({"object": [[1000, 5]]})", "application/json")->status, 400);
  EXPECT_EQ(client_->Post(Api(strokes), R"({"object": [["a", 5]]})", "application/json")->status, 400);
  const auto bad_option = client_->Post(Api(fmt::format("/api/docs/{}/segment", id)),
                                        R"({"options": {"gmm_component": 3}})", "application/json");
  EXPECT_EQ(bad_option->status, 400);
  EXPECT_NE(Json(bad_option)["error"].get<std::string>().find("did you mean 'gmm_components'"),
            std::string::npos);
  EXPECT_EQ(client_->Post(Api(strokes), std::string(2 << 20, ' '), "application/json")->status, 413);
  EXPECT_EQ(client_->Get(Api(fmt::format("/api/docs/{}/save?format=asc", id)))->status, 400);
  EXPECT_EQ(client_->Post(Api(fmt::format("/api/docs/{}/undo", OpenBox())), "", "application/json")->status,
            409);
}

TEST_F(ServerTest, SegmentRemoveUndoSave) {
  const int id = OpenBox();
  ASSERT_EQ(
      client_->Post(Api(fmt::format("/api/docs/{}/strokes", id)), StrokesBody(), "application/json")->status,
      200);
  const auto started = client_->Post(Api(fmt::format("/api/docs/{}/segment", id)), "{}", "application/json");
  ASSERT_EQ(started->status, 202) << started->body;
  const auto segmented = Wait(Json(started));
  ASSERT_EQ(segmented["state"], "done") << segmented.dump();
  EXPECT_GT(segmented["result"]["object_cells"].get<int>(), 50);
  EXPECT_FALSE(segmented["result"]["refined"]);
  // A live refinement after one more background stroke: the session's incremental cut.
  ASSERT_EQ(client_
                ->Post(Api(fmt::format("/api/docs/{}/strokes", id)), R"({"background": [[2, 2]]})",
                       "application/json")
                ->status,
            200);
  const auto refined = Wait(Json(client_->Post(Api(fmt::format("/api/docs/{}/segment", id)),
                                               R"({"refine": true})", "application/json")));
  ASSERT_EQ(refined["state"], "done") << refined.dump();
  EXPECT_TRUE(refined["result"]["refined"]);
  EXPECT_NEAR(refined["result"]["object_cells"].get<double>(),
              segmented["result"]["object_cells"].get<double>(),
              0.05 * segmented["result"]["object_cells"].get<double>());
  const auto removed =
      Wait(Json(client_->Post(Api(fmt::format("/api/docs/{}/remove", id)),
                              R"({"options": {"fill": {"method": "laplace"}}})", "application/json")));
  ASSERT_EQ(removed["state"], "done") << removed.dump();
  const auto after = Json(client_->Get(Api(fmt::format("/api/docs/{}", id))));
  EXPECT_GT(after["synthesized_cells"].get<int>(), 50);
  EXPECT_TRUE(after["can_undo"]);
  ASSERT_EQ(client_->Post(Api(fmt::format("/api/docs/{}/undo", id)), "", "application/json")->status, 200);
  EXPECT_EQ(Json(client_->Get(Api(fmt::format("/api/docs/{}", id))))["synthesized_cells"], 0);
  ASSERT_EQ(client_->Post(Api(fmt::format("/api/docs/{}/redo", id)), "", "application/json")->status, 200);
  EXPECT_GT(Json(client_->Get(Api(fmt::format("/api/docs/{}", id))))["synthesized_cells"].get<int>(), 50);
  const auto saved = client_->Get(Api(fmt::format("/api/docs/{}/save?format=e57", id)));
  ASSERT_EQ(saved->status, 200);
  EXPECT_EQ(saved->body.substr(0, 8), "ASTM-E57");
}

// Undo restores the strokes a removal cleared: its snapshot's stroke buffer was zeroed in place when the
// removal made its next state, so a second removal after undo found no object stroke.
TEST_F(ServerTest, RemoveUndoRemoveKeepsTheStrokes) {
  const int id = OpenBox();
  const std::string strokes = Api(fmt::format("/api/docs/{}/strokes", id));
  const auto painted = client_->Post(strokes, StrokesBody(), "application/json");
  ASSERT_EQ(painted->status, 200);
  const int object_strokes = Json(painted)["object_stroke_cells"];
  ASSERT_GT(object_strokes, 10);
  const std::string remove = Api(fmt::format("/api/docs/{}/remove", id));
  const std::string options = R"({"options": {"fill": {"method": "laplace"}}})";
  const auto first = Wait(Json(client_->Post(remove, options, "application/json")));
  ASSERT_EQ(first["state"], "done") << first.dump();
  const int synthesized = Json(client_->Get(Api(fmt::format("/api/docs/{}", id))))["synthesized_cells"];
  EXPECT_GT(synthesized, 50);
  EXPECT_EQ(Json(client_->Post(strokes, "{}", "application/json"))["object_stroke_cells"], 0);  // cleared
  // Undo both: the empty strokes edit and the removal; the strokes are back as they were painted.
  for (int i = 0; i < 2; ++i) {
    ASSERT_EQ(client_->Post(Api(fmt::format("/api/docs/{}/undo", id)), "", "application/json")->status, 200);
  }
  EXPECT_EQ(Json(client_->Get(Api(fmt::format("/api/docs/{}", id))))["synthesized_cells"], 0);
  const auto again = Wait(Json(client_->Post(remove, options, "application/json")));
  ASSERT_EQ(again["state"], "done") << again.dump();
  EXPECT_EQ(Json(client_->Get(Api(fmt::format("/api/docs/{}", id))))["synthesized_cells"], synthesized);
  // And once more through redo: the history holds each state as it was.
  ASSERT_EQ(client_->Post(Api(fmt::format("/api/docs/{}/undo", id)), "", "application/json")->status, 200);
  const auto repainted = client_->Post(strokes, "{}", "application/json");
  EXPECT_EQ(Json(repainted)["object_stroke_cells"], object_strokes);
}

// The stroke counts are kept with the strokes and changed only where an edit paints (a station's strokes are
// not counted again): after painting over other strokes, erasing, clearing and undo they equal a count of the
// strokes the server holds (mask.png?layer=strokes), and the cropped overlay's box is the strokes' box.
TEST_F(ServerTest, StrokeCountsFollowEveryPaint) {
  const int id = OpenBox();
  const std::string strokes = Api(fmt::format("/api/docs/{}/strokes", id));
  const auto recount = [&](const std::string& what) {
    const auto grey = client_->Get(Api(fmt::format("/api/docs/{}/mask.png?layer=strokes", id)));
    ASSERT_EQ(grey->status, 200);
    const cv::Mat held =
        cv::imdecode(std::vector<uint8_t>(grey->body.begin(), grey->body.end()), cv::IMREAD_UNCHANGED);
    const nlohmann::json document = Json(client_->Get(Api(fmt::format("/api/docs/{}", id))));
    EXPECT_EQ(document["object_stroke_cells"], cv::countNonZero(held == 1)) << what;
    EXPECT_EQ(document["background_stroke_cells"], cv::countNonZero(held == 2)) << what;
    const auto cropped =
        client_->Get(Api(fmt::format("/api/docs/{}/mask.png?layer=strokes&style=overlay&crop=1", id)));
    ASSERT_EQ(cropped->status, 200);
    const cv::Rect box = cv::boundingRect(held);
    EXPECT_EQ(cropped->get_header_value("X-Lidarshop-Box"),
              fmt::format("{},{},{},{}", box.x, box.y, box.width, box.height))
        << what;
  };
  ASSERT_EQ(client_->Post(strokes, StrokesBody(), "application/json")->status, 200);
  recount("painted");
  const int rows = scan_->rows, cols = scan_->cols;
  // Object strokes of radius 5 over background and object strokes alike, then an erased disc.
  ASSERT_EQ(client_
                ->Post(strokes,
                       nlohmann::json{{"object", {{rows / 2, cols / 3}, {rows / 2 + 3, cols / 3 + 4}}},
                                      {"radius", 5}}
                           .dump(),
                       "application/json")
                ->status,
            200);
  recount("painted over");
  ASSERT_EQ(client_
                ->Post(strokes, nlohmann::json{{"erase", {{rows / 2, cols / 3}}}, {"radius", 4}}.dump(),
                       "application/json")
                ->status,
            200);
  recount("erased");
  ASSERT_EQ(client_->Post(Api(fmt::format("/api/docs/{}/undo", id)), "", "application/json")->status, 200);
  recount("undone");
  ASSERT_EQ(
      client_
          ->Post(strokes, nlohmann::json{{"clear", true}, {"background", {{1, 1}}}, {"radius", 0}}.dump(),
                 "application/json")
          ->status,
      200);
  recount("cleared and painted");
}

// The first stroke has a job build the cut's session in the background (PrepareCut): it is queued before the
// cut a stroke later, ends before it, and the cut that uses it equals a full cut with a session made then.
TEST_F(ServerTest, TheFirstCutUsesTheSessionPreparedAtTheFirstStroke) {
  const int id = OpenBox();
  const auto painted =
      client_->Post(Api(fmt::format("/api/docs/{}/strokes", id)), StrokesBody(), "application/json");
  ASSERT_EQ(painted->status, 200);
  const std::string segment = Api(fmt::format("/api/docs/{}/segment", id));
  const nlohmann::json first = Json(client_->Post(segment, R"({"refine": true})", "application/json"));
  const nlohmann::json prepared =
      Json(client_->Get(Api(fmt::format("/api/jobs/{}", first["id"].get<int>() - 1))));
  EXPECT_EQ(prepared["kind"], "prepare segment");
  EXPECT_EQ(prepared["document"], id);
  const nlohmann::json cut = Wait(first);
  ASSERT_EQ(cut["state"], "done") << cut.dump();
  EXPECT_EQ(Json(client_->Get(Api(fmt::format("/api/jobs/{}", prepared["id"].get<int>()))))["state"], "done");
  EXPECT_FALSE(cut["result"]["refined"].get<bool>());
  EXPECT_TRUE(cut["result"]["prepared"].get<bool>());
  const auto mask = [&] { return client_->Get(Api(fmt::format("/api/docs/{}/mask.png", id)))->body; };
  const std::string prepared_mask = mask();
  // A full cut (not a refinement) makes its own session: the same strokes give the same object.
  const nlohmann::json again = Wait(Json(client_->Post(segment, R"({"refine": false})", "application/json")));
  ASSERT_EQ(again["state"], "done") << again.dump();
  EXPECT_FALSE(again["result"]["prepared"].get<bool>());
  EXPECT_EQ(again["result"]["object_cells"], cut["result"]["object_cells"]);
  EXPECT_GT(cut["result"]["object_cells"].get<int>(), 50);
  EXPECT_EQ(mask(), prepared_mask);
}

// The points as a map from key (cell, + 2^31 for the layer behind a kept object) to the point's bytes (xyz,
// rgb, flags): from a whole LSP1 answer, or an LSD1 delta applied to `points`.
using PointMap = std::map<uint32_t, std::string>;
void ApplyPoints(const std::string& body, PointMap& points, int64_t* from = nullptr, int64_t* to = nullptr) {
  ASSERT_GE(body.size(), 16u);
  uint32_t header[6] = {};
  std::memcpy(header, body.data(), std::min(body.size(), sizeof(header)));
  const size_t n = header[1];
  const auto record = [&](const char* xyz, const char* rgb, const char* flags) {
    return std::string(xyz, 12) + std::string(rgb, 3) + std::string(flags, 1);
  };
  if (body.compare(0, 4, "LSP1") == 0) {
    ASSERT_EQ(body.size(), 16 + n * 20);
    points.clear();
    const char* base = body.data() + 16;
    for (size_t i = 0; i < n; ++i) {
      uint32_t cell;
      std::memcpy(&cell, base + 12 * n + 4 * i, 4);
      const char* flags = base + 19 * n + i;
      points[cell | ((*flags & 4) != 0 ? 0x80000000u : 0u)] =
          record(base + 12 * i, base + 16 * n + 3 * i, flags);
    }
    return;
  }
  ASSERT_EQ(body.compare(0, 4, "LSD1"), 0);
  ASSERT_EQ(body.size(), 24 + n * 21);
  if (from) *from = header[4];
  if (to) *to = header[5];
  const char* base = body.data() + 24;
  for (size_t i = 0; i < n; ++i) {
    uint32_t key;
    std::memcpy(&key, base + 4 * i, 4);
    if (base[20 * n + i] == 0) {
      points.erase(key);
    } else {
      points[key] = record(base + 4 * n + 12 * i, base + 16 * n + 3 * i, base + 19 * n + i);
    }
  }
}

// An edit sends only what it changed: the deltas since the client's version, applied in order, give exactly
// the whole points of each version; a stroke changes no point; an unknown version gets the whole points.
TEST_F(ServerTest, PointDeltasPatchToTheWholePoints) {
  const int id = OpenBox();
  const auto get = [&](const std::string& path) {
    return client_->Get(Api(fmt::format(fmt::runtime(path), id)));
  };
  const auto version = [&] { return Json(get("/api/docs/{}"))["version"].get<int64_t>(); };
  PointMap client;
  ApplyPoints(get("/api/docs/{}/points")->body, client);
  const size_t whole_bytes = get("/api/docs/{}/points")->body.size();
  int64_t shown = version();
  // Brings the client to the current version with a delta; checks it against the whole points.
  const auto catch_up = [&](const char* what) -> size_t {
    const auto delta = get(fmt::format("/api/docs/{{}}/points?since={}", shown));
    EXPECT_EQ(delta->status, 200) << what;
    EXPECT_EQ(delta->body.substr(0, 4), "LSD1") << what;
    int64_t from = -1, to = -1;
    ApplyPoints(delta->body, client, &from, &to);
    EXPECT_EQ(from, shown) << what;
    shown = to;
    EXPECT_EQ(to, version()) << what;
    PointMap whole;
    ApplyPoints(get("/api/docs/{}/points")->body, whole);
    EXPECT_TRUE(client == whole) << what << ": the patched points differ from the whole points";
    return delta->body.size();
  };
  ASSERT_EQ(
      client_->Post(Api(fmt::format("/api/docs/{}/strokes", id)), StrokesBody(), "application/json")->status,
      200);
  EXPECT_EQ(catch_up("stroke"), 24u);  // the header only: a stroke moves no point
  // The strokes as the server holds them, drawn over the ray image (object green, background red).
  const auto overlay = get("/api/docs/{}/mask.png?layer=strokes&style=overlay");
  ASSERT_EQ(overlay->status, 200);
  const cv::Mat strokes =
      cv::imdecode(std::vector<uint8_t>(overlay->body.begin(), overlay->body.end()), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(strokes.type(), CV_8UC4);
  std::vector<cv::Mat> bgra;
  cv::split(strokes, bgra);
  EXPECT_EQ(cv::countNonZero(bgra[1] == 220), Json(get("/api/docs/{}"))["object_stroke_cells"]);
  const auto segmented =
      Wait(Json(client_->Post(Api(fmt::format("/api/docs/{}/segment", id)), "{}", "application/json")));
  ASSERT_EQ(segmented["state"], "done");
  const size_t segment_bytes = catch_up("segment");
  EXPECT_EQ(segment_bytes,
            24 + 21 * segmented["result"]["object_cells"].get<size_t>());  // their flags changed
  const auto removed =
      Wait(Json(client_->Post(Api(fmt::format("/api/docs/{}/remove", id)),
                              R"({"options": {"fill": {"method": "laplace"}}})", "application/json")));
  ASSERT_EQ(removed["state"], "done");
  EXPECT_LT(catch_up("remove"), whole_bytes / 2);
  ASSERT_EQ(client_->Post(Api(fmt::format("/api/docs/{}/undo", id)), "", "application/json")->status, 200);
  catch_up("undo");
  ASSERT_EQ(client_->Post(Api(fmt::format("/api/docs/{}/redo", id)), "", "application/json")->status, 200);
  catch_up("redo");
  // Many strokes (other clients painting) do not push the client's version out: they share its point state.
  for (int i = 0; i < 3 * 8; ++i) {
    ASSERT_EQ(client_
                  ->Post(Api(fmt::format("/api/docs/{}/strokes", id)), R"({"background": [[1, 1]]})",
                         "application/json")
                  ->status,
              200);
  }
  EXPECT_EQ(catch_up("24 strokes"), 24u);
  // Two versions at once (a client that missed one) and a version no longer kept.
  const int64_t two_back = shown - 2;
  PointMap older;
  ApplyPoints(get(fmt::format("/api/docs/{{}}/points?since={}", 999999))->body, older);  // whole: LSP1
  EXPECT_TRUE(older == client);
  EXPECT_EQ(get(fmt::format("/api/docs/{{}}/points?since={}", two_back))->body.substr(0, 4), "LSD1");
  EXPECT_EQ(get("/api/docs/{}/points?since=abc")->status, 400);
  EXPECT_EQ(get("/api/docs/{}/points?since=-1")->status, 400);
  // The picture route reads `since` the same way (version_param.h).
  EXPECT_EQ(get("/api/docs/{}/image.png?channel=range&since=abc")->status, 400);
  EXPECT_EQ(get("/api/docs/{}/image.png?channel=range&since=-1")->status, 400);
}

// A level of detail (every step-th row and column) and a box of cells (a part of the scan seen closer): the
// whole points' cells that the level and the box hold, whole and as a delta; a malformed or outside box is
// refused.
TEST_F(ServerTest, PointsOfALevelAndABox) {
  const int id = OpenBox();
  const auto get = [&](const std::string& path) {
    return client_->Get(Api(fmt::format(fmt::runtime(path), id)));
  };
  const int rows = scan_->rows, cols = scan_->cols;
  const auto kept = [&](const PointMap& all, int step, const cv::Rect& box) {
    PointMap inside;
    for (const auto& [key, bytes] : all) {
      const int cell = static_cast<int>(key & 0x7fffffffu), r = cell / cols, c = cell % cols;
      if (r % step == 0 && c % step == 0 && box.contains(cv::Point(c, r))) inside[key] = bytes;
    }
    return inside;
  };
  PointMap whole;
  ApplyPoints(get("/api/docs/{}/points")->body, whole);
  PointMap level;
  const auto level_answer = get("/api/docs/{}/points?step=3");
  EXPECT_EQ(level_answer->get_header_value("X-Lidarshop-Step"), "3");
  EXPECT_FALSE(level_answer->has_header("X-Lidarshop-Box"));
  ApplyPoints(level_answer->body, level);
  EXPECT_TRUE(level == kept(whole, 3, cv::Rect(0, 0, cols, rows)));
  EXPECT_GT(level.size(), whole.size() / 12);
  EXPECT_LT(level.size(), whole.size() / 6);
  // The box around the object (label 1), from an odd row and column: the level's first cells are inside it.
  const cv::Rect object = cv::boundingRect((scan_->label == 1) & (scan_->valid != 0));
  const cv::Rect box(object.x | 1, object.y | 1, object.width + 2, object.height + 2);
  const std::string box_param = fmt::format("box={},{},{},{}", box.x, box.y, box.width, box.height);
  for (const int step : {1, 2}) {
    const auto answer = get(fmt::format("/api/docs/{{}}/points?step={}&{}", step, box_param));
    ASSERT_EQ(answer->status, 200) << answer->body;
    EXPECT_EQ(answer->get_header_value("X-Lidarshop-Box"),
              fmt::format("{},{},{},{}", box.x, box.y, box.width, box.height));
    PointMap boxed;
    ApplyPoints(answer->body, boxed);
    EXPECT_TRUE(boxed == kept(whole, step, box)) << "step " << step;
    EXPECT_FALSE(boxed.empty());
  }
  // A box past the grid's end is clipped to it.
  const auto clipped = get(fmt::format("/api/docs/{{}}/points?box={},{},100,100", cols - 10, rows - 5));
  ASSERT_EQ(clipped->status, 200);
  EXPECT_EQ(clipped->get_header_value("X-Lidarshop-Box"), fmt::format("{},{},10,5", cols - 10, rows - 5));
  // The box's delta after a cut: the box of the whole points after it.
  PointMap client;
  ApplyPoints(get("/api/docs/{}/points?step=2&" + box_param)->body, client);
  const int64_t before = Json(get("/api/docs/{}"))["version"].get<int64_t>();
  ASSERT_EQ(
      client_->Post(Api(fmt::format("/api/docs/{}/strokes", id)), StrokesBody(), "application/json")->status,
      200);
  ASSERT_EQ(Wait(Json(client_->Post(Api(fmt::format("/api/docs/{}/segment", id)), "{}",
                                    "application/json")))["state"],
            "done");
  const auto delta = get(fmt::format("/api/docs/{{}}/points?step=2&{}&since={}", box_param, before));
  ASSERT_EQ(delta->body.substr(0, 4), "LSD1");
  const PointMap held = client;
  ApplyPoints(delta->body, client);
  PointMap after;
  ApplyPoints(get("/api/docs/{}/points")->body, after);
  EXPECT_TRUE(client == kept(after, 2, box));
  EXPECT_FALSE(client == held);  // the cut flagged the object's points
  for (const char* bad :
       {"1,2,3", "1,2,3,0", "-1,0,5,5", "0,0,5,5,", "a,b,c,d", " 1,2,3,4", "1,2,3,4x", "99999999999,0,5,5"}) {
    EXPECT_EQ(get(fmt::format("/api/docs/{{}}/points?box={}", bad))->status, 400) << bad;
  }
  EXPECT_EQ(get(fmt::format("/api/docs/{{}}/points?box={},0,5,5", cols))->status, 400);  // outside
  EXPECT_EQ(get(fmt::format("/api/docs/{{}}/points?box=0,{},5,5", rows))->status, 400);
  for (const char* bad : {"0", "65", "2x", ""}) {
    EXPECT_EQ(get(fmt::format("/api/docs/{{}}/points?step={}", bad))->status, 400) << "step " << bad;
  }
}

// A scan opened from E57 and edited keeps its photo, scan guid and the file's other metadata when saved as
// E57; the save plan of another format says the photo is lost; the recolour tool can take the photo.
TEST_F(ServerTest, E57PhotoAndGuidSurviveAnEditAndASave) {
  fs::copy_file(LIDARSHOP_SHARED_DATA_DIR "/e57/pumpA.e57", base_ / "root" / "pump.e57",
                fs::copy_options::overwrite_existing);
  const E57File original = ReadE57(LIDARSHOP_SHARED_DATA_DIR "/e57/pumpA.e57");
  const auto opened = client_->Get(Api("/api/open?path=pump.e57"));
  ASSERT_EQ(opened->status, 200) << opened->body;
  const auto doc = Json(opened);
  const int id = doc["id"];
  ASSERT_EQ(doc["e57_images"].size(), 1u);
  EXPECT_EQ(doc["e57_images"][0]["name"], "pumpVisual");
  EXPECT_TRUE(doc["e57_images"][0]["usable"]);
  // An edit that changes the scan: a painted hole filled.
  ASSERT_EQ(
      client_
          ->Post(Api(fmt::format("/api/docs/{}/strokes", id)),
                 R"({"hole_polygon": [[500, 100], [500, 140], [540, 140], [540, 100]]})", "application/json")
          ->status,
      200);
  const auto filled = Wait(
      Json(client_->Post(Api(fmt::format("/api/docs/{}/fill", id)),
                         R"({"hole": "painted", "options": {"method": "laplace"}})", "application/json")));
  ASSERT_EQ(filled["state"], "done") << filled.dump();
  const auto ptx_plan = Json(client_->Get(Api(fmt::format("/api/docs/{}/save-plan?format=ptx", id))));
  EXPECT_NE(ptx_plan["dropped"].dump().find("photo(s) of the E57 file"), std::string::npos)
      << ptx_plan.dump();
  const auto saved = client_->Get(Api(fmt::format("/api/docs/{}/save?format=e57", id)));
  ASSERT_EQ(saved->status, 200);
  const E57File back =
      ReadE57Bytes(std::vector<uint8_t>(saved->body.begin(), saved->body.end()), "saved.e57");
  ASSERT_EQ(back.images.size(), 1u);
  EXPECT_EQ(back.images[0].encoded, original.images[0].encoded);  // the photo bit for bit
  EXPECT_EQ(back.images[0].guid, original.images[0].guid);
  EXPECT_EQ(back.scans[0].source_metadata.at("e57.guid"), original.scans[0].source_metadata.at("e57.guid"));
  ASSERT_FALSE(back.scans[0].synthesized.empty());
  EXPECT_GT(cv::countNonZero(back.scans[0].synthesized), 0);  // the edit is in it
  // The recolour tool's photo from the file.
  const auto photo = client_->Post(Api(fmt::format("/api/docs/{}/photo-from-e57", id)), R"({"image": 0})",
                                   "application/json");
  ASSERT_EQ(photo->status, 200) << photo->body;
  EXPECT_EQ(Json(photo)["width_px"], 3072);
  EXPECT_EQ(client_->Get(Api(fmt::format("/api/docs/{}/photo.png", id)))->status, 200);
  EXPECT_EQ(
      client_
          ->Post(Api(fmt::format("/api/docs/{}/photo-from-e57", id)), R"({"image": 1})", "application/json")
          ->status,
      400);
  EXPECT_EQ(
      client_
          ->Post(Api(fmt::format("/api/docs/{}/photo-from-e57", id)), R"({"image": "x"})", "application/json")
          ->status,
      400);
  // pumpA's photo is a visual one (no camera): colouring from the station's photos says why it cannot.
  const auto station =
      client_->Post(Api(fmt::format("/api/docs/{}/recolor-station", id)), "{}", "application/json");
  EXPECT_EQ(station->status, 400);
  EXPECT_NE(station->body.find("pumpVisual"), std::string::npos) << station->body;
  client_->Delete(Api(fmt::format("/api/docs/{}", id)));
}

TEST_F(ServerTest, HoleBrushLassoAndFillShadow) {
  const int id = OpenBox();
  const std::string strokes = Api(fmt::format("/api/docs/{}/strokes", id));
  const auto lasso = client_->Post(strokes, R"({"hole_polygon": [[40, 10], [40, 30], [55, 30], [55, 10]]})",
                                   "application/json");
  ASSERT_EQ(lasso->status, 200) << lasso->body;
  const int lasso_cells = Json(lasso)["hole_cells"];
  EXPECT_NEAR(lasso_cells, 16 * 21, 40);  // the filled quadrilateral, boundary included
  EXPECT_EQ(client_->Post(strokes, R"({"hole_polygon": [[1, 1], [2, 2]]})", "application/json")->status, 400);
  const auto brushed = client_->Post(strokes, R"({"hole": [[20, 60]], "radius": 3})", "application/json");
  EXPECT_GT(Json(brushed)["hole_cells"].get<int>(), lasso_cells);
  const auto filled = Wait(
      Json(client_->Post(Api(fmt::format("/api/docs/{}/fill", id)),
                         R"({"hole": "painted", "options": {"method": "laplace"}})", "application/json")));
  ASSERT_EQ(filled["state"], "done") << filled.dump();
  EXPECT_GT(filled["result"]["synthesized_cells"].get<int>(), 0);
  const auto after_fill = Json(client_->Get(Api(fmt::format("/api/docs/{}", id))));
  EXPECT_EQ(after_fill["hole_cells"], 0);
  EXPECT_EQ(
      client_->Post(Api(fmt::format("/api/docs/{}/fill", id)), R"({"hole": "painted"})", "application/json")
          ->status,
      400);  // nothing painted any more

  // Fill shadow: the object stays, the surface behind it becomes a second layer, saved as a second return.
  ASSERT_EQ(client_->Post(strokes, StrokesBody(), "application/json")->status, 200);
  const auto shadow = Wait(Json(client_->Post(
      Api(fmt::format("/api/docs/{}/remove", id)),
      R"({"options": {"keep_object": true, "fill": {"method": "laplace"}}})", "application/json")));
  ASSERT_EQ(shadow["state"], "done") << shadow.dump();
  const auto doc = Json(client_->Get(Api(fmt::format("/api/docs/{}", id))));
  EXPECT_GT(doc["behind_cells"].get<int>(), 50);
  EXPECT_GT(doc["object_cells"].get<int>(), 50);  // the object is still there
  EXPECT_EQ(client_->Get(Api(fmt::format("/api/docs/{}/save?format=ptx", id)))->status, 400);
  // The editor asks first: PTX would be refused (the registry's reason), E57 holds the layer.
  const auto ptx_plan = Json(client_->Get(Api(fmt::format("/api/docs/{}/save-plan?format=ptx", id))));
  EXPECT_EQ(ptx_plan["refused"], "PTX cannot hold two returns per cell; write E57, PLY, PCD or LAS");
  const auto e57_plan = Json(client_->Get(Api(fmt::format("/api/docs/{}/save-plan?format=e57", id))));
  EXPECT_EQ(e57_plan["refused"], "");
  const auto e57 = client_->Get(Api(fmt::format("/api/docs/{}/save?format=e57", id)));
  ASSERT_EQ(e57->status, 200);
  const fs::path saved = base_ / "shadow.e57";
  std::ofstream(saved, std::ios::binary) << e57->body;
  const ScanFile file = ReadScanFile(saved.string());
  ASSERT_FALSE(file.scans.empty());
  EXPECT_EQ(file.scans[0].rows, scan_->rows);
}

TEST_F(ServerTest, ReadersWarningsComeBackInTheReply) {
  const auto opened = client_->Get(Api("/api/open?path=sub/box.ptx"));
  ASSERT_EQ(opened->status, 200) << opened->body;
  ASSERT_TRUE(Json(opened).contains("warnings"));
  EXPECT_EQ(Json(opened)["warnings"], nlohmann::json::array());  // a PTX file read whole
  const auto placed = client_->Post(Api("/api/models"), R"({"model": "sub/quad.obj"})", "application/json");
  ASSERT_EQ(placed->status, 200) << placed->body;
  const nlohmann::json warnings = Json(placed)["warnings"];
  ASSERT_EQ(warnings.size(), 1u) << placed->body;
  EXPECT_NE(warnings[0].get<std::string>().find("quad.obj: "), std::string::npos);
  EXPECT_NE(warnings[0].get<std::string>().find("missing.mtl"), std::string::npos);
}

TEST_F(ServerTest, PlaceAndVerifyAModel) {
  const int id = OpenBox();
  const auto models = Json(client_->Get(Api("/api/models")));
  EXPECT_EQ(models["builtin"][0], "car:sedan");
  const auto placed = client_->Post(Api("/api/models"), R"({"model": "car:sedan"})", "application/json");
  ASSERT_EQ(placed->status, 200) << placed->body;
  const int model = Json(placed)["id"];
  EXPECT_NEAR(Json(placed)["size_m"][1].get<double>(), 4.6, 0.25);  // a sedan is 4.6 m long (+ mirrors)
  const auto mesh = client_->Get(Api(fmt::format("/api/models/{}/mesh", model)));
  uint32_t header[4];
  std::memcpy(header, mesh->body.data(), sizeof(header));
  EXPECT_EQ(mesh->body.size(), 16 + header[1] * 12 + header[2] * 12);
  // A model in other units: "options" takes ModelOptions (here the sedan in decimetres ÷ 10).
  const auto small = client_->Post(
      Api("/api/models"), R"({"model": "car:sedan", "options": {"model_scale": 0.1}})", "application/json");
  ASSERT_EQ(small->status, 200) << small->body;
  EXPECT_NEAR(Json(small)["size_m"][1].get<double>(), 0.46, 0.025);
  EXPECT_EQ(client_
                ->Post(Api("/api/models"), R"({"model": "car:sedan", "options": {"model_scale": -1}})",
                       "application/json")
                ->status,
            400);
  EXPECT_EQ(client_->Post(Api("/api/models"), R"({"model": "car:limo"})", "application/json")->status, 403);
  EXPECT_EQ(client_->Post(Api("/api/models"), R"({"model": "/etc/passwd"})", "application/json")->status,
            403);
  // A car standing where the 1 m box is seen: the scan sees the box's front face where the car's surface would
  // hide it, so the pose is mostly inconsistent; the same car far to the side, out of view, is not comparable.
  const std::string verify = Api(fmt::format("/api/docs/{}/verify", id));
  const auto at_box = Json(client_->Post(
      verify, fmt::format(R"({{"model": {}, "pose": {{"x_m": 0, "y_m": 8.5, "yaw_deg": 90}}}})", model),
      "application/json"));
  ASSERT_TRUE(at_box["has_comparable_pairs"]) << at_box.dump();
  EXPECT_LT(at_box["consistency"].get<double>(), 0.5) << at_box.dump();
  const auto behind =
      Json(client_->Post(verify, fmt::format(R"({{"model": {}, "pose": {{"x_m": 0, "y_m": -20}}}})", model),
                         "application/json"));
  EXPECT_FALSE(behind["has_comparable_pairs"]) << behind.dump();
  EXPECT_TRUE(behind["consistency"].is_null());
  EXPECT_EQ(client_
                ->Post(verify, fmt::format(R"({{"model": {}, "pose": {{"x_m": "left"}}}})", model),
                       "application/json")
                ->status,
            400);
  EXPECT_EQ(client_->Post(verify, R"({"model": 999})", "application/json")->status, 404);
}

TEST_F(ServerTest, RecolourFromAPhotoWithPickedPairs) {
  const int id = OpenBox();
  const std::string recolor = Api(fmt::format("/api/docs/{}/recolor", id));
  EXPECT_EQ(client_->Post(recolor, R"({"pairs": []})", "application/json")->status, 400);  // no photo yet
  EXPECT_EQ(client_->Post(Api(fmt::format("/api/docs/{}/photo", id)), "not an image", "image/png")->status,
            422);
  // A photo of the same scene from beside the scanner, and pairs of scan cells with their true pixels.
  lidarshop::test_scenes::GroundAndBoxOptions scene;
  const PinholeCamera camera = CameraLookingAt({1.0, 0.5, 1.7}, {0, 8, 0.5}, 320, 240, 60);
  const Photo photo = RenderPhoto(lidarshop::test_scenes::MakeGroundAndBoxScene(scene), camera);
  cv::Mat bgr;
  cv::cvtColor(photo.image, bgr, cv::COLOR_RGB2BGR);
  std::vector<uint8_t> png;
  cv::imencode(".png", bgr, png);
  const auto uploaded = client_->Post(Api(fmt::format("/api/docs/{}/photo", id)),
                                      std::string(png.begin(), png.end()), "image/png");
  ASSERT_EQ(uploaded->status, 200) << uploaded->body;
  EXPECT_EQ(Json(uploaded)["width_px"], 320);
  nlohmann::json pairs = nlohmann::json::array();
  for (int r = 0; r < scan_->rows && pairs.size() < 40; r += 3) {
    for (int c = 0; c < scan_->cols && pairs.size() < 40; c += 7) {
      if (scan_->valid.at<uint8_t>(r, c) == 0) continue;
      const cv::Vec3f p = scan_->point.at<cv::Vec3f>(r, c);
      const Eigen::Vector4d world = scan_->world_from_scanner * Eigen::Vector4d(p[0], p[1], p[2], 1);
      Eigen::Vector2d pixel;
      if (!ProjectWorldPoint(camera, world.head<3>(), &pixel) || !InsideImage(camera, pixel)) continue;
      pairs.push_back({{"pixel", {pixel.x(), pixel.y()}}, {"cell", {r, c}}});
    }
  }
  ASSERT_GE(pairs.size(), 12u);
  EXPECT_EQ(client_->Post(recolor, R"({"pairs": [{"pixel": [1, 1], "cell": [0, 9999]}]})", "application/json")
                ->status,
            400);
  const auto done =
      Wait(Json(client_->Post(recolor, nlohmann::json{{"pairs", pairs}}.dump(), "application/json")));
  ASSERT_EQ(done["state"], "done") << done.dump();
  EXPECT_LT(done["result"]["rms_px"].get<double>(), 1.0) << done.dump();
  EXPECT_GT(done["result"]["recolored_count"].get<int>(), 100) << done.dump();
  EXPECT_EQ(client_->Get(Api(fmt::format("/api/docs/{}/photo.png", id)))->status, 200);
}

TEST_F(ServerTest, SaveOffersTheLibrarysWriteFormats) {
  const auto formats = Json(client_->Get(Api("/api/formats")));
  for (const char* format : {"e57", "ptx", "ply", "pcd"}) {
    EXPECT_NE(std::find(formats["write"].begin(), formats["write"].end(), format), formats["write"].end());
    EXPECT_NE(std::find(formats["read"].begin(), formats["read"].end(), format), formats["read"].end());
  }
  const int id = OpenBox();
  for (const auto& format : formats["write"]) {
    const auto saved =
        client_->Get(Api(fmt::format("/api/docs/{}/save?format={}", id, format.get<std::string>())));
    EXPECT_EQ(saved->status, 200) << format;
    EXPECT_GT(saved->body.size(), 1000u) << format;
  }
  // Before saving, the plan says what a format drops (the box, read from PTX, is a grid: XYZ drops it, PLY
  // keeps it), from the same registry as convert's warnings.
  const auto xyz_plan = Json(client_->Get(Api(fmt::format("/api/docs/{}/save-plan?format=xyz", id))));
  ASSERT_EQ(xyz_plan["dropped"].size(), 1u) << xyz_plan.dump();
  EXPECT_NE(xyz_plan["dropped"][0].get<std::string>().find("and the scanner pose are not kept"),
            std::string::npos);
  EXPECT_EQ(Json(client_->Get(Api(fmt::format("/api/docs/{}/save-plan?format=ply", id))))["dropped"].size(),
            0u);
  EXPECT_EQ(client_->Get(Api(fmt::format("/api/docs/{}/save-plan?format=laz", id)))->status, 400);
  EXPECT_EQ(formats["formats"].size(), formats["read"].size());  // the registry, one entry per format
  const auto refused = client_->Get(Api(fmt::format("/api/docs/{}/save?format=asc", id)));
  EXPECT_EQ(refused->status, 400);
  // The message lists the library's formats (whatever they are when a writer is added).
  EXPECT_NE(Json(refused)["error"].get<std::string>().find(
                fmt::format("expected one of {}", formats["write"][0].get<std::string>())),
            std::string::npos)
      << refused->body;
  EXPECT_EQ(client_->Get("/api/formats")->status, 401);
}

// The patch review: strict acceptance makes every target a review point; accept a listed candidate, place one
// by hand, close; then a fill without acceptance runs to the end and becomes one undoable colour edit.
TEST_F(ServerTest, InpaintingReviewAcceptPlaceAndFinish) {
  const int id = OpenBox();
  const std::string review = Api(fmt::format("/api/docs/{}/inpaint/review", id));
  const std::string decide = Api(fmt::format("/api/docs/{}/inpaint/review/decide", id));
  EXPECT_EQ(client_->Post(fmt::format("/api/docs/{}/inpaint/review", id), "{}", "application/json")->status,
            401);
  const auto no_hole = client_->Post(review, "{}", "application/json");
  EXPECT_EQ(no_hole->status, 400);
  EXPECT_NE(Json(no_hole)["error"].get<std::string>().find("paint a hole first"), std::string::npos);
  EXPECT_EQ(client_->Get(review)->status, 404);  // none started
  ASSERT_EQ(client_
                ->Post(Api(fmt::format("/api/docs/{}/strokes", id)),
                       R"({"hole_polygon": [[40, 10], [40, 30], [55, 30], [55, 10]]})", "application/json")
                ->status,
            200);
  EXPECT_EQ(client_->Post(review, R"({"channel": "range"})", "application/json")->status, 400);
  EXPECT_EQ(client_->Post(review, R"({"options": {"patch_radiuss": 4}})", "application/json")->status, 400);
  EXPECT_EQ(client_->Post(review, R"({"options": {"patch_radius": 0}})", "application/json")->status, 400);
  const std::string strict =
      R"({"options": {"review_candidates": 30, "acceptance": {"auto_accept_hole_fraction": 0,
          "representative": {"enabled": true, "max_difference": 1e-6}}}})";
  const auto started = client_->Post(review, strict, "application/json");
  ASSERT_EQ(started->status, 202) << started->body;
  EXPECT_EQ(Json(started)["kind"], "review");
  const auto stopped = Wait(Json(started));
  ASSERT_EQ(stopped["state"], "done") << stopped.dump();
  ASSERT_EQ(stopped["result"]["state"], "review") << stopped.dump();
  const auto pending = client_->Get(review);
  ASSERT_EQ(pending->status, 200) << pending->body;
  const auto first = Json(pending);
  EXPECT_EQ(first["channel"], "color");
  EXPECT_EQ(first["review"]["review_point"], 0);
  EXPECT_EQ(first["review"]["patch_radius"], 4);
  ASSERT_EQ(first["review"]["candidates"].size(), 30u);
  EXPECT_FALSE(first["review"]["candidates"][0]["accepted"]);
  EXPECT_FALSE(first["review"]["candidates"][0]["test"].get<std::string>().empty());
  EXPECT_GE(first["review"]["clusters"].size(), 1u);
  const int target_row = first["review"]["target"][0], target_col = first["review"]["target"][1];
  EXPECT_TRUE(target_row >= 38 && target_row <= 57 && target_col >= 8 && target_col <= 32)
      << first["review"]["target"];
  for (const char* layer : {"canvas", "tentative"}) {
    const auto png =
        client_->Get(Api(fmt::format("/api/docs/{}/inpaint/review/image.png?layer={}", id, layer)));
    ASSERT_EQ(png->status, 200) << layer;
    const cv::Mat image =
        cv::imdecode(std::vector<uint8_t>(png->body.begin(), png->body.end()), cv::IMREAD_COLOR);
    EXPECT_EQ(image.rows, scan_->rows);
    EXPECT_EQ(image.cols, scan_->cols);
  }
  EXPECT_EQ(client_->Get(Api(fmt::format("/api/docs/{}/inpaint/review/image.png?layer=x", id)))->status, 400);

  // Bad decisions: 400 with a message, and the review stays where it was.
  EXPECT_EQ(client_->Post(decide, R"({"candidate": 30})", "application/json")->status, 400);
  EXPECT_EQ(client_->Post(decide, R"({"candidate": 1, "source": [10, 60]})", "application/json")->status,
            400);
  const auto outside = client_->Post(decide, R"({"source": [0, 0]})", "application/json");
  EXPECT_EQ(outside->status, 400);
  EXPECT_NE(Json(outside)["error"].get<std::string>().find("(0, 0) is not the centre"), std::string::npos)
      << outside->body;
  EXPECT_EQ(client_->Post(decide, R"({"source": [45, 20]})", "application/json")->status,
            400);  // in the hole
  EXPECT_EQ(Json(client_->Get(review))["review"]["review_point"], 0);

  // Accept candidate 2: the fill goes on to the next review point with that decision recorded.
  const auto accepted = Wait(Json(client_->Post(decide, R"({"candidate": 2})", "application/json")));
  ASSERT_EQ(accepted["result"]["state"], "review") << accepted.dump();
  const auto second = Json(client_->Get(review));
  EXPECT_EQ(second["review"]["review_point"], 1);
  ASSERT_EQ(second["decisions"].size(), 1u);
  EXPECT_EQ(second["decisions"][0]["source"], first["review"]["candidates"][2]["source"]);
  // Place by hand: the centre of a patch the user clicked, anywhere wholly outside the hole.
  const auto placed = Wait(Json(client_->Post(decide, R"({"source": [30, 60]})", "application/json")));
  ASSERT_EQ(placed["result"]["state"], "review") << placed.dump();
  const auto third = Json(client_->Get(review));
  ASSERT_EQ(third["decisions"].size(), 2u);
  EXPECT_EQ(third["decisions"][1]["source"], nlohmann::json::array({30, 60}));
  const int64_t version = Json(client_->Get(Api(fmt::format("/api/docs/{}", id))))["version"];
  ASSERT_EQ(client_->Delete(review)->status, 200);
  EXPECT_EQ(client_->Get(review)->status, 404);
  EXPECT_EQ(client_->Post(decide, R"({"candidate": 0})", "application/json")->status, 404);
  EXPECT_EQ(Json(client_->Get(Api(fmt::format("/api/docs/{}", id))))["version"], version);  // nothing applied

  // Without acceptance nothing stops: the fill runs to its end and is one undoable edit of the colours in the
  // hole; every other cell keeps its colour.
  const Scan before = ReadScanFile((base_ / "root" / "sub" / "box.ptx").string()).scans[0];
  const auto finished = Wait(
      Json(client_->Post(review, R"({"options": {"acceptance": {"enabled": false}}})", "application/json")));
  ASSERT_EQ(finished["state"], "done") << finished.dump();
  ASSERT_EQ(finished["result"]["state"], "done") << finished.dump();
  EXPECT_EQ(finished["result"]["version"].get<int64_t>(), version + 1);
  EXPECT_EQ(client_->Get(review)->status, 404);
  EXPECT_EQ(Json(client_->Get(Api(fmt::format("/api/docs/{}", id))))["hole_cells"], 0);  // the hole is filled
  const auto saved = client_->Get(Api(fmt::format("/api/docs/{}/save?format=ply", id)));
  ASSERT_EQ(saved->status, 200);
  const fs::path file = base_ / "reviewed.ply";
  std::ofstream(file, std::ios::binary) << saved->body;
  const Scan after = ReadScanFile(file.string()).scans[0];
  cv::Mat hole = cv::Mat::zeros(before.rows, before.cols, CV_8U);
  cv::fillPoly(hole, std::vector<std::vector<cv::Point>>{{{10, 40}, {30, 40}, {30, 55}, {10, 55}}}, 255);
  cv::Mat changed;
  cv::Mat difference;
  cv::absdiff(after.color, before.color, difference);
  const cv::Mat differs = difference > 0;
  cv::reduce(differs.reshape(1, before.rows * before.cols), changed, 1, cv::REDUCE_MAX);
  changed = changed.reshape(1, before.rows);
  EXPECT_GT(cv::countNonZero(changed & hole), 20);
  EXPECT_EQ(cv::countNonZero(changed & ~hole), 0);
  EXPECT_EQ(after.CountValid(), before.CountValid());  // the points did not move or appear
  ASSERT_EQ(client_->Post(Api(fmt::format("/api/docs/{}/undo", id)), "", "application/json")->status, 200);
}

TEST_F(ServerTest, LandmarksRegisterOneScanToAnother) {
  const int box = OpenBox();
  const auto opened = client_->Get(Api("/api/open?path=sub/moved.ptx"));
  ASSERT_EQ(opened->status, 200);
  const int moved = Json(opened)["id"];
  nlohmann::json pairs = nlohmann::json::array();
  for (int r = 20; r < scan_->rows; r += 9) {
    for (int c = 3; c < scan_->cols; c += 17) {
      if (scan_->valid.at<uint8_t>(r, c) == 0) continue;
      pairs.push_back({{"cell", {r, c}}, {"target_cell", {r, c}}});
    }
  }
  ASSERT_GE(pairs.size(), 6u);
  const std::string align = Api(fmt::format("/api/docs/{}/align", moved));
  EXPECT_EQ(client_->Post(align, nlohmann::json{{"pairs", pairs}}.dump(), "application/json")->status, 400);
  EXPECT_EQ(
      client_->Post(align, nlohmann::json{{"target", moved}, {"pairs", pairs}}.dump(), "application/json")
          ->status,
      400);
  EXPECT_EQ(
      client_->Post(align, nlohmann::json{{"target", 9999}, {"pairs", pairs}}.dump(), "application/json")
          ->status,
      404);
  EXPECT_EQ(client_
                ->Post(align, nlohmann::json{{"target", box}, {"pairs", pairs}, {"with_scale", true}}.dump(),
                       "application/json")
                ->status,
            400);
  const nlohmann::json two = nlohmann::json::array({pairs[0], pairs[1]});
  EXPECT_EQ(client_->Post(align, nlohmann::json{{"target", box}, {"pairs", two}}.dump(), "application/json")
                ->status,
            400);
  const auto sky = client_->Post(
      align, nlohmann::json{{"target", box}, {"pairs", {{{"cell", {0, 0}}, {"target_cell", {0, 0}}}}}}.dump(),
      "application/json");
  EXPECT_EQ(sky->status, 400);
  EXPECT_NE(Json(sky)["error"].get<std::string>().find("has no return"), std::string::npos) << sky->body;
  const auto similarity = client_->Post(
      align, nlohmann::json{{"target", box}, {"pairs", pairs}, {"with_scale", true}, {"apply", false}}.dump(),
      "application/json");
  ASSERT_EQ(similarity->status, 200) << similarity->body;
  EXPECT_NEAR(Json(similarity)["scale"].get<double>(), 1.0, 1e-6);
  EXPECT_FALSE(Json(similarity)["applied"]);
  const auto fitted =
      client_->Post(align, nlohmann::json{{"target", box}, {"pairs", pairs}}.dump(), "application/json");
  ASSERT_EQ(fitted->status, 200) << fitted->body;
  EXPECT_LT(Json(fitted)["rms_m"].get<double>(), 1e-4);
  // The moved scan's pose is the box scan's again: T undid the move.
  const auto pose =
      Json(client_->Get(Api(fmt::format("/api/docs/{}", moved))))["world_from_scanner_column_major"];
  for (int k = 0; k < 16; ++k)
    EXPECT_NEAR(pose[k].get<double>(), scan_->world_from_scanner.data()[k], 1e-4) << k;
  const Eigen::Matrix4d expected_t = MovedPose().inverse();
  const auto t = Json(fitted)["target_from_source_column_major"];
  for (int k = 0; k < 16; ++k) EXPECT_NEAR(t[k].get<double>(), expected_t.data()[k], 1e-4) << k;
  ASSERT_EQ(client_->Post(Api(fmt::format("/api/docs/{}/undo", moved)), "", "application/json")->status, 200);
  const auto undone =
      Json(client_->Get(Api(fmt::format("/api/docs/{}", moved))))["world_from_scanner_column_major"];
  const Eigen::Matrix4d moved_pose = MovedPose() * scan_->world_from_scanner;
  for (int k = 0; k < 16; ++k) EXPECT_NEAR(undone[k].get<double>(), moved_pose.data()[k], 1e-6) << k;
}

// Photo <-> photo: ground points (z = 0) seen by two cameras are related by a homography.
TEST_F(ServerTest, PhotoPairsGiveAHomography) {
  const int id = OpenBox();
  const std::string match = Api(fmt::format("/api/docs/{}/photo-match", id));
  EXPECT_EQ(client_->Post(match, R"({"pairs": []})", "application/json")->status, 400);  // no photos yet
  lidarshop::test_scenes::GroundAndBoxOptions scene;
  const PinholeCamera a = CameraLookingAt({1.0, 0.5, 1.7}, {0, 8, 0.5}, 320, 240, 60);
  const PinholeCamera b = CameraLookingAt({-1.5, 1.0, 2.0}, {0.5, 9, 0.3}, 300, 200, 55);
  for (const auto& [camera, slot] : {std::pair{a, "a"}, std::pair{b, "b"}}) {
    const Photo photo = RenderPhoto(lidarshop::test_scenes::MakeGroundAndBoxScene(scene), camera);
    cv::Mat bgr;
    cv::cvtColor(photo.image, bgr, cv::COLOR_RGB2BGR);
    std::vector<uint8_t> png;
    cv::imencode(".png", bgr, png);
    const auto uploaded = client_->Post(Api(fmt::format("/api/docs/{}/photo?slot={}", id, slot)),
                                        std::string(png.begin(), png.end()), "image/png");
    ASSERT_EQ(uploaded->status, 200) << uploaded->body;
  }
  EXPECT_EQ(client_->Post(Api(fmt::format("/api/docs/{}/photo?slot=c", id)), "x", "image/png")->status, 400);
  EXPECT_EQ(client_->Get(Api(fmt::format("/api/docs/{}/photo.png?slot=b", id)))->status, 200);
  nlohmann::json pairs = nlohmann::json::array();
  for (double x = -3; x <= 3; x += 1.5) {
    for (double y = 5; y <= 12; y += 2.5) {
      Eigen::Vector2d pa, pb;
      if (!ProjectWorldPoint(a, {x, y, 0}, &pa) || !InsideImage(a, pa) ||
          !ProjectWorldPoint(b, {x, y, 0}, &pb) || !InsideImage(b, pb))
        continue;
      pairs.push_back({{"pixel_a", {pa.x(), pa.y()}}, {"pixel_b", {pb.x(), pb.y()}}});
    }
  }
  ASSERT_GE(pairs.size(), 8u);
  const auto fitted = client_->Post(match, nlohmann::json{{"pairs", pairs}}.dump(), "application/json");
  ASSERT_EQ(fitted->status, 200) << fitted->body;
  EXPECT_LT(Json(fitted)["rms_px"].get<double>(), 0.1) << fitted->body;
  EXPECT_EQ(Json(fitted)["error_px"].size(), pairs.size());
  EXPECT_EQ(Json(fitted)["matrix_row_major"].size(), 9u);
  // Points off one plane: a fundamental matrix (a homography would not fit them).
  nlohmann::json general = nlohmann::json::array();
  int k = 0;
  for (double x = -3; x <= 3; x += 1.0) {
    for (double y = 5; y <= 12; y += 1.5) {
      const Eigen::Vector3d point(x, y, 0.4 * (k++ % 5));
      Eigen::Vector2d pa, pb;
      if (!ProjectWorldPoint(a, point, &pa) || !InsideImage(a, pa) || !ProjectWorldPoint(b, point, &pb) ||
          !InsideImage(b, pb))
        continue;
      general.push_back({{"pixel_a", {pa.x(), pa.y()}}, {"pixel_b", {pb.x(), pb.y()}}});
    }
  }
  ASSERT_GE(general.size(), 15u);
  const auto fundamental = client_->Post(
      match, nlohmann::json{{"pairs", general}, {"model", "fundamental"}}.dump(), "application/json");
  ASSERT_EQ(fundamental->status, 200) << fundamental->body;
  EXPECT_LT(Json(fundamental)["rms_px"].get<double>(), 0.1) << fundamental->body;
  EXPECT_EQ(
      client_->Post(match, nlohmann::json{{"pairs", pairs}, {"model", "affine"}}.dump(), "application/json")
          ->status,
      400);
  const nlohmann::json three = nlohmann::json::array({pairs[0], pairs[1], pairs[2]});
  EXPECT_EQ(client_->Post(match, nlohmann::json{{"pairs", three}}.dump(), "application/json")->status, 400);
  const auto outside =
      client_->Post(match, R"({"pairs": [{"pixel_a": [1, 1], "pixel_b": [500, 1]}]})", "application/json");
  EXPECT_EQ(outside->status, 400);
  EXPECT_NE(Json(outside)["error"].get<std::string>().find("outside the 300 x 200 photo"), std::string::npos)
      << outside->body;
  // The kinds do not mix across routes: photo pairs are not resection pairs.
  EXPECT_EQ(client_
                ->Post(Api(fmt::format("/api/docs/{}/recolor", id)), nlohmann::json{{"pairs", pairs}}.dump(),
                       "application/json")
                ->status,
            400);
}

TEST_F(ServerTest, ConcurrentEditsAreNotLost) {
  const int id = OpenBox();
  const int64_t before = Json(client_->Get(Api(fmt::format("/api/docs/{}", id))))["version"];
  constexpr int kClients = 16, kEdits = 10;
  std::vector<std::thread> clients;
  std::atomic<int> failures{0};
  for (int k = 0; k < kClients; ++k) {
    clients.emplace_back([&, k] {
      httplib::Client client("127.0.0.1", server_->port());
      for (int e = 0; e < kEdits; ++e) {
        const std::string body = fmt::format(R"({{"object": [[{}, {}]], "radius": 0}})", k, e);
        const auto result =
            client.Post(Api(fmt::format("/api/docs/{}/strokes", id)), body, "application/json");
        if (!result || result->status != 200) {
          ++failures;
          ADD_FAILURE() << "edit " << k << "/" << e << ": "
                        << (result ? result->body : httplib::to_string(result.error()));
        }
      }
    });
  }
  for (std::thread& client : clients) client.join();
  EXPECT_EQ(failures, 0);
  EXPECT_EQ(Json(client_->Get(Api(fmt::format("/api/docs/{}", id))))["version"].get<int64_t>(),
            before + kClients * kEdits);
}

TEST_F(ServerTest, BuiltinScenes) {
  EXPECT_EQ(Json(client_->Get(Api("/api/scenes")))["scenes"][0], "tiny");
  EXPECT_EQ(client_->Get(Api("/api/open?scene=tiny"))->status, 200);
  EXPECT_EQ(client_->Get(Api("/api/open?scene=nope"))->status, 404);
}

}  // namespace
}  // namespace lidarshop::server
