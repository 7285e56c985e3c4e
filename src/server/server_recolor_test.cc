// The recolour routes (routes_recolor.cc, docs/api.md): a photo uploaded and a scan recoloured from picked
// pairs, one scan registered to another by landmarks (and undone), photo pairs fitted by a homography or a
// fundamental matrix.
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <Eigen/Core>
#include <Eigen/LU>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "lidarshop/geometry/camera.h"
#include "lidarshop/scanner/photo.h"
#include "lidarshop/testing/scenes.h"
// After every Eigen include: httplib (in server_test_util.h) pulls in <resolv.h>, whose `_res` macro breaks
// Eigen's headers.
#include "server_routes_test_util.h"

namespace lidarshop::server {
namespace {

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

}  // namespace
}  // namespace lidarshop::server
