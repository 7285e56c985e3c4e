// The scan routes (routes_scan.cc, docs/api.md): the token before any route, files only under the roots and
// listed in name order, pictures and points of an opened scan, the write formats and the plan of a save, an E57
// file's photo and guid through an edit and a save, the built-in scenes.
#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "lidarshop/io/e57.h"
#include "lidarshop/io/scan_io.h"
// After every Eigen include: httplib (in server_test_util.h) pulls in <resolv.h>, whose `_res` macro breaks
// Eigen's headers.
#include "server_routes_test_util.h"

namespace lidarshop::server {
namespace {

namespace fs = std::filesystem;

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

TEST_F(ServerTest, BuiltinScenes) {
  EXPECT_EQ(Json(client_->Get(Api("/api/scenes")))["scenes"][0], "tiny");
  EXPECT_EQ(client_->Get(Api("/api/open?scene=tiny"))->status, 200);
  EXPECT_EQ(client_->Get(Api("/api/open?scene=nope"))->status, 404);
}

}  // namespace
}  // namespace lidarshop::server
