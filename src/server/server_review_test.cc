// The patch review of inpainting (routes_review.cc, docs/api.md): strict acceptance makes every target a
// review point; a listed candidate accepted, one placed by hand, the review closed; a fill without acceptance
// is one undoable colour edit of the hole.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
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

}  // namespace
}  // namespace lidarshop::server
