// The points of a scan (points.cc, the route in routes_scan.cc, docs/api.md "Points"): the deltas an edit
// sends, applied in order, give the whole points of each version; a level of detail and a box of cells.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

// After every Eigen include: httplib (in server_test_util.h) pulls in <resolv.h>, whose `_res` macro breaks
// Eigen's headers.
#include "server_routes_test_util.h"

namespace lidarshop::server {
namespace {

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

}  // namespace
}  // namespace lidarshop::server
