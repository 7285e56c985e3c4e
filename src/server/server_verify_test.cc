// The model routes (routes_verify.cc, docs/api.md): a model placed (built-in or a file, in other units),
// its mesh, the consistency of its pose with the scan, and the readers' warnings in the replies.
#include <cstdint>
#include <cstring>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

// After every Eigen include: httplib (in server_test_util.h) pulls in <resolv.h>, whose `_res` macro breaks
// Eigen's headers.
#include "server_routes_test_util.h"

namespace lidarshop::server {
namespace {

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

}  // namespace
}  // namespace lidarshop::server
