// The edit routes (routes_edit.cc, docs/api.md): strokes and their counts, segment (the session prepared at
// the first stroke, live refinement), remove, fill and fill shadow, undo and redo, malformed requests, and
// concurrent edits that are not lost.
#include <atomic>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "lidarshop/io/scan_io.h"
// After every Eigen include: httplib (in server_test_util.h) pulls in <resolv.h>, whose `_res` macro breaks
// Eigen's headers.
#include "server_routes_test_util.h"

namespace lidarshop::server {
namespace {

namespace fs = std::filesystem;

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

}  // namespace
}  // namespace lidarshop::server
