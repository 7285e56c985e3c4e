#include <gtest/gtest.h>

#include "lidarshop/raycast/raycast.h"
#include "lidarshop/scan/scan_mesh.h"
#include "lidarshop/scanner/photo.h"
#include "lidarshop/scanner/primitives.h"
#include "lidarshop/scanner/scene.h"
#include "lidarshop/scanner/site_scan.h"
#include "lidarshop/scanner/texture.h"
#include "lidarshop/util/options_test_util.h"

namespace lidarshop {

TEST(ScannerOptionsInfo, ExactRoundTrips) {
  ExpectExactRoundTrip<ScannerOptions>();
  ExpectExactRoundTrip<PhotoOptions>();
  ExpectExactRoundTrip<ScanMeshOptions>();
  ExpectExactRoundTrip<CarMeshOptions>();
  ExpectExactRoundTrip<FacadeMeshOptions>();
  ExpectExactRoundTrip<RaycastSceneOptions>();
}

// What a scan run did not make (a site's stations, photos, labels, a mesh) is left out of its summary.
TEST(ScannerOptionsInfo, SceneScanSummaryLeavesOutWhatTheRunDidNotMake) {
  auto keys = [](const nlohmann::ordered_json& json) {
    std::vector<std::string> out;
    for (const auto& item : json.items()) out.push_back(item.key());
    return out;
  };
  SceneScanSummary summary;
  EXPECT_EQ(keys(ToJson(summary)),
            (std::vector<std::string>{"scene", "output", "objects", "triangles", "rows", "columns", "rays",
                                      "returns", "mesh_triangles", "threads", "seconds", "rays_per_second"}));
  summary.labels = "l.png";
  summary.labels_color = "l_color.png";
  summary.target_label = 3;
  StationScanSummary station;
  station.mesh = "m_0.ply";
  summary.stations.push_back(station);
  StationPhoto photo;
  photo.name = "panorama";
  summary.photos.push_back(SummarizeStationPhoto(photo, 0));
  summary.mesh_options = ScanMeshOptions{};
  const nlohmann::ordered_json json = ToJson(summary);
  EXPECT_EQ(keys(json), (std::vector<std::string>{"scene", "output", "labels", "labels_color", "target_label",
                                                  "objects", "triangles", "rows", "columns", "rays",
                                                  "returns", "mesh_triangles", "stations", "photos",
                                                  "threads", "seconds", "rays_per_second", "mesh_options"}));
  EXPECT_EQ(keys(json["stations"][0]),
            (std::vector<std::string>{"index", "name", "position", "objects", "rows", "columns", "rays",
                                      "returns", "mesh"}));
  EXPECT_EQ(json["photos"][0].dump(),
            R"({"name":"panorama","model":"pinhole","width_px":0,"height_px":0,"gain":1.0,"station":0})");
}

TEST(ScannerOptionsInfo, Errors) {
  ExpectRejected<ScannerOptions>({{"elevation_min_deg", -91}}, "elevation_min_deg", "out of range [-90, 90]");
  ExpectRejected<ScannerOptions>({{"azimuth_min_deg", 10}, {"azimuth_max_deg", 5}}, "azimuth_max_deg",
                                 "above azimuth_min_deg");
  ExpectRejected<ScannerOptions>({{"cast_method", "packet4"}}, "cast_method",
                                 "packet16|packet8|stream|single");
  ExpectRejected<CarMeshOptions>({{"style", "sedans"}}, "style", "did you mean 'sedan'");
  ExpectRejected<RaycastSceneOptions>({{"build_quality", "best"}}, "build_quality",
                                      "not low, medium or high");
}

TEST(ScannerOptionsInfo, SceneFileWordsStayInputErrors) {
  EXPECT_EQ(ParseCarStyle("suv", "scene.json"), CarStyle::kVan);
  EXPECT_EQ(ToString(TextureKind::kGravel), "gravel");
  try {
    ParseTextureKind("marble", "scene.json");
    ADD_FAILURE();
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("scene.json"), std::string::npos);
    EXPECT_NE(std::string(error.what()).find("texture"), std::string::npos);
  }
}

}  // namespace lidarshop
