// The ray image's tile pyramid (tiles.cc, docs/api.md "Tiles"): sizes and pixels of every level, coordinates
// that no picture has, the token, and that an edit re-renders exactly the tiles whose footprint meets the box of
// pixels it changed.
#include <unistd.h>

#include <chrono>
#include <thread>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "lidarshop/testing/scenes.h"
#include "server.h"
#include "server_test_util.h"

namespace lidarshop::server {
namespace {

// Not a multiple of 4: the coarser levels' last blocks are completed by repeating the picture's edge.
constexpr int kRows = 603, kCols = 901;  // levels 0 (12 tiles of 256 px), 1 (4 x 2), 2 (one 226 x 151 tile)

class TilesTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    test_scenes::GroundAndBoxOptions scene;
    scene.rows = kRows;
    scene.columns = kCols;
    scan_ = new Scan(test_scenes::ScanScene(test_scenes::MakeGroundAndBoxScene(scene)));
    ServerOptions options;
    options.port = 0;
    options.token = "tile-token";
    options.builtin_scenes = {"ground"};
    options.scan_builtin = [](const std::string&) { return *scan_; };
    running_ = new RunningServer(options, 120);
    server_ = &running_->server();
    client_ = &running_->client();
  }
  static void TearDownTestSuite() {
    delete running_;
    delete scan_;
  }
  static std::string Api(const std::string& path) {
    return path + (path.find('?') == std::string::npos ? "?" : "&") + "token=tile-token";
  }
  static int Open() {
    const auto result = client_->Get(Api("/api/open?scene=ground"));
    EXPECT_EQ(result->status, 200) << result->body;
    return nlohmann::json::parse(result->body)["id"].get<int>();
  }
  static cv::Mat Decode(const std::string& png) {
    return cv::imdecode(cv::Mat(1, static_cast<int>(png.size()), CV_8U, const_cast<char*>(png.data())),
                        cv::IMREAD_COLOR);
  }
  static cv::Mat Whole(int id, const std::string& channel) {
    const auto result = client_->Get(Api(fmt::format("/api/docs/{}/image.png?channel={}", id, channel)));
    EXPECT_EQ(result->status, 200);
    return Decode(result->body);
  }
  struct Tile {
    int status = 0;
    cv::Mat image;
    int64_t version = -1, tile_version = -1;
  };
  static Tile Get(int id, int level, int tx, int ty, const std::string& channel) {
    const auto result = client_->Get(
        Api(fmt::format("/api/docs/{}/tiles/{}/{}/{}.png?channel={}", id, level, tx, ty, channel)));
    Tile tile;
    tile.status = result->status;
    if (result->status != 200) return tile;
    tile.image = Decode(result->body);
    tile.version = std::stoll(result->get_header_value("X-Lidarshop-Version"));
    tile.tile_version = std::stoll(result->get_header_value("X-Lidarshop-Tile-Version"));
    return tile;
  }
  // Level `level` of `whole` as the pyramid defines it: means of 2^level blocks, the edge repeated.
  static cv::Mat Level(const cv::Mat& whole, int level) {
    const int f = 1 << level;
    const int width = (whole.cols + f - 1) / f, height = (whole.rows + f - 1) / f;
    cv::Mat padded, out;
    cv::copyMakeBorder(whole, padded, 0, height * f - whole.rows, 0, width * f - whole.cols,
                       cv::BORDER_REPLICATE);
    cv::resize(padded, out, cv::Size(width, height), 0, 0, cv::INTER_AREA);
    return out;
  }
  static int MaxDifference(const cv::Mat& a, const cv::Mat& b) {
    if (a.size() != b.size() || a.type() != b.type()) return 256;
    double most = 0;
    cv::Mat d;
    cv::absdiff(a, b, d);
    cv::minMaxLoc(d.reshape(1), nullptr, &most);
    return static_cast<int>(most);
  }

  static Scan* scan_;
  static EditorServer* server_;
  static RunningServer* running_;
  static httplib::Client* client_;
};
Scan* TilesTest::scan_ = nullptr;
EditorServer* TilesTest::server_ = nullptr;
RunningServer* TilesTest::running_ = nullptr;
httplib::Client* TilesTest::client_ = nullptr;

TEST_F(TilesTest, LevelsHalveAndTilesHoldTheirFootprint) {
  const int id = Open();
  const auto info =
      nlohmann::json::parse(client_->Get(Api(fmt::format("/api/docs/{}/tiles.json", id)))->body);
  EXPECT_EQ(info["rows"], kRows);
  EXPECT_EQ(info["cols"], kCols);
  EXPECT_EQ(info["tile_px"], 256);
  ASSERT_EQ(info["levels"].size(), 3u);
  EXPECT_EQ(info["levels"][1]["cols"], 451);
  EXPECT_EQ(info["levels"][1]["rows"], 302);
  EXPECT_EQ(info["levels"][0]["tiles_x"], 4);
  EXPECT_EQ(info["levels"][0]["tiles_y"], 3);
  EXPECT_EQ(info["levels"][2]["tiles_x"], 1);
  for (const std::string channel : {"range", "rgb"}) {
    const cv::Mat whole = Whole(id, channel);
    ASSERT_EQ(whole.size(), cv::Size(kCols, kRows));
    for (int level = 0; level < 3; ++level) {
      const cv::Mat expected = Level(whole, level);
      const auto& sizes = info["levels"][level];
      for (int ty = 0; ty < sizes["tiles_y"].get<int>(); ++ty) {
        for (int tx = 0; tx < sizes["tiles_x"].get<int>(); ++tx) {
          const Tile tile = Get(id, level, tx, ty, channel);
          ASSERT_EQ(tile.status, 200);
          const cv::Rect box =
              cv::Rect(tx * 256, ty * 256, 256, 256) & cv::Rect(0, 0, expected.cols, expected.rows);
          EXPECT_EQ(tile.image.size(), box.size())
              << channel << " level " << level << " tile " << tx << "," << ty;
          // Level 0 is the picture's pixels; coarser ones its block means (rounding may differ by one).
          EXPECT_LE(MaxDifference(tile.image, expected(box)), level == 0 ? 0 : 1)
              << channel << " level " << level << " tile " << tx << "," << ty;
        }
      }
    }
  }
  // The last tile of level 0 is what is left of the picture: 901 - 768 by 603 - 512.
  EXPECT_EQ(Get(id, 0, 3, 2, "range").image.size(), cv::Size(133, 91));
  EXPECT_EQ(Get(id, 2, 0, 0, "range").image.size(), cv::Size(226, 151));
}

TEST_F(TilesTest, CoordinatesNoPictureHasAreRefused) {
  const int id = Open();
  EXPECT_EQ(Get(id, 3, 0, 0, "range").status, 404);  // past the coarsest level
  EXPECT_EQ(Get(id, 0, 4, 0, "range").status, 404);  // right of the picture
  EXPECT_EQ(Get(id, 0, 0, 3, "range").status, 404);  // below it
  EXPECT_EQ(Get(id, 1, 2, 0, "range").status, 404);  // level 1 has 2 tiles across
  EXPECT_EQ(Get(id, 99999999, 0, 0, "range").status, 404);
  EXPECT_EQ(Get(id, 0, 0, 0, "bogus").status, 400);
  EXPECT_EQ(Get(9999, 0, 0, 0, "range").status, 404);
  const auto huge = client_->Get(Api(fmt::format("/api/docs/{}/tiles/0/99999999999999999999/0.png", id)));
  EXPECT_EQ(huge->status, 404);
  EXPECT_EQ(client_->Get(Api(fmt::format("/api/docs/{}/tiles/0/-1/0.png", id)))->status, 404);
  EXPECT_EQ(client_->Get(Api(fmt::format("/api/docs/{}/tiles/0/a/0.png", id)))->status, 404);
  EXPECT_EQ(client_->Get(Api(fmt::format("/api/docs/{}/tiles.json?since=x", id)))->status, 400);
  EXPECT_EQ(client_->Get(Api(fmt::format("/api/docs/{}/tiles.json?channel=x", id)))->status, 400);
}

TEST_F(TilesTest, TokenIsRequired) {
  const int id = Open();
  EXPECT_EQ(client_->Get(fmt::format("/api/docs/{}/tiles/0/0/0.png", id))->status, 401);
  EXPECT_EQ(client_->Get(fmt::format("/api/docs/{}/tiles/0/0/0.png?token=wrong", id))->status, 401);
  EXPECT_EQ(client_->Get(fmt::format("/api/docs/{}/tiles.json", id))->status, 401);
  EXPECT_EQ(client_->Get(Api(fmt::format("/api/docs/{}/tiles/0/0/0.png", id)))->status, 200);
}

// A painted hole filled: the colour changes inside a small box; exactly the tiles whose footprint meets it are
// rendered again (their tile version is the new one), the others keep the version of their first render, and
// every tile shows the new picture. tiles.json?since names that box.
TEST_F(TilesTest, AnEditReRendersOnlyTheTilesItsBoxMeets) {
  const int id = Open();
  const std::string channel = "rgb";
  const cv::Mat before = Whole(id, channel);
  std::map<std::tuple<int, int, int>, Tile> first;
  const int tiles_x[] = {4, 2, 1}, tiles_y[] = {3, 2, 1};
  for (int level = 0; level < 3; ++level) {
    for (int ty = 0; ty < tiles_y[level]; ++ty) {
      for (int tx = 0; tx < tiles_x[level]; ++tx) first[{level, tx, ty}] = Get(id, level, tx, ty, channel);
    }
  }
  const int64_t version_before = first[{0, 0, 0}].version;
  // A hole on the ground below the box, inside level-0 tile (1, 2) and (2, 2)'s neighbourhood.
  const std::string strokes = Api(fmt::format("/api/docs/{}/strokes", id));
  ASSERT_EQ(client_
                ->Post(strokes, R"({"hole_polygon": [[540, 300], [540, 330], [570, 330], [570, 300]]})",
                       "application/json")
                ->status,
            200);
  const auto job =
      client_->Post(Api(fmt::format("/api/docs/{}/fill", id)),
                    R"({"hole": "painted", "options": {"method": "laplace"}})", "application/json");
  ASSERT_EQ(job->status, 202) << job->body;
  const int job_id = nlohmann::json::parse(job->body)["id"].get<int>();
  for (int i = 0; i < 1200; ++i) {
    const auto state = nlohmann::json::parse(client_->Get(Api(fmt::format("/api/jobs/{}", job_id)))->body);
    if (state["state"] == "done") break;
    ASSERT_TRUE(state["state"] == "queued" || state["state"] == "running") << state.dump();
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  const cv::Mat after = Whole(id, channel);
  cv::Mat difference;
  cv::absdiff(before, after, difference);
  cv::Mat any;
  cv::cvtColor(difference, any, cv::COLOR_BGR2GRAY);
  const cv::Rect changed = cv::boundingRect(any > 0);
  ASSERT_FALSE(changed.empty()) << "the fill changed no pixel";
  ASSERT_LT(changed.area(), kRows * kCols / 8) << "the fill changed most of the picture";

  const auto info = nlohmann::json::parse(
      client_
          ->Get(Api(fmt::format("/api/docs/{}/tiles.json?channel={}&since={}", id, channel, version_before)))
          ->body);
  EXPECT_EQ(info["changed"], nlohmann::json({changed.x, changed.y, changed.width, changed.height}));
  const int64_t version_after = info["version"].get<int64_t>();
  ASSERT_GT(version_after, version_before);

  int rendered = 0, kept = 0;
  for (const auto& [key, old] : first) {
    const auto [level, tx, ty] = key;
    const Tile now = Get(id, level, tx, ty, channel);
    ASSERT_EQ(now.status, 200);
    const int span = 256 << level;
    const bool meets = !(cv::Rect(tx * span, ty * span, span, span) & changed).empty();
    EXPECT_EQ(now.tile_version, meets ? version_after : old.tile_version)
        << "level " << level << " tile " << tx << "," << ty;
    const cv::Mat expected = Level(after, level);
    const cv::Rect box =
        cv::Rect(tx * 256, ty * 256, 256, 256) & cv::Rect(0, 0, expected.cols, expected.rows);
    EXPECT_LE(MaxDifference(now.image, expected(box)), level == 0 ? 0 : 1)
        << "level " << level << " tile " << tx << "," << ty;
    (meets ? rendered : kept) += 1;
  }
  EXPECT_GT(rendered, 0);
  EXPECT_GT(kept, 0);
  // A stroke moves no pixel: nothing changed, no tile rendered again.
  ASSERT_EQ(client_->Post(strokes, R"({"object": [[100, 100]]})", "application/json")->status, 200);
  const auto stroke = nlohmann::json::parse(
      client_
          ->Get(Api(fmt::format("/api/docs/{}/tiles.json?channel={}&since={}", id, channel, version_after)))
          ->body);
  EXPECT_EQ(stroke["changed"], nlohmann::json({0, 0, 0, 0}));
  for (int level = 0; level < 3; ++level) {
    const Tile again = Get(id, level, 0, 0, channel);
    EXPECT_LE(again.tile_version, version_after) << "level " << level;
    EXPECT_GT(again.version, version_after);
  }
}

}  // namespace
}  // namespace lidarshop::server
