#include "lidarshop/site/site_stations.h"

#include <gtest/gtest.h>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/scanner/scene.h"
#include "lidarshop/scanner/site_scan.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

TEST(SiteStations, HeadingIsTheYawOfRotateDeg) {
  for (const double yaw : {0.0, 30.0, -30.0, 90.0, 135.0, -170.0}) {
    Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();
    pose.topLeftCorner<3, 3>() = RotationFromEulerDegrees(Eigen::Vector3d(0, 0, yaw));
    EXPECT_NEAR(HeadingDeg(pose), yaw, 1e-9) << yaw;
  }
  // A tilted scanner keeps the heading of its yaw.
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();
  pose.topLeftCorner<3, 3>() = RotationFromEulerDegrees(Eigen::Vector3d(2, -3, 40));
  EXPECT_NEAR(HeadingDeg(pose), 40.0, 0.2);
}

TEST(SiteStations, SummariesOfAScannedSite) {
  const SceneDescription scene = ParseScene(R"({
    "stations": [
      {"position": [0, 0, 1.6], "azimuth_deg": [-40, 40], "elevation_deg": [-20, 20], "columns": 40, "rows": 20},
      {"position": [-8, 2, 1.5], "rotate_deg": [0, 0, -30], "azimuth_deg": [-40, 40], "elevation_deg": [-20, 20],
       "columns": 30, "rows": 16}],
    "objects": [{"primitive": "plane", "size": [80, 80]},
                {"primitive": "box", "size": [30, 0.5, 8], "translate": [0, 15, 4]}]})",
                                            "site", "");
  const std::vector<StationSummary> stations = SummarizeStations(ScanStations(scene));
  ASSERT_EQ(stations.size(), 2u);
  EXPECT_EQ(stations[1].index, 1);
  EXPECT_EQ(stations[1].name, "station1");
  EXPECT_NEAR(stations[1].position_m.x(), -8.0, 1e-9);
  EXPECT_NEAR(stations[1].position_m.z(), 1.5, 1e-9);
  EXPECT_NEAR(stations[1].heading_deg, -30.0, 1e-9);
  EXPECT_EQ(stations[1].rows, 16);
  EXPECT_EQ(stations[1].cols, 30);
  EXPECT_GT(stations[0].returns, 400);
  EXPECT_LE(stations[0].returns, 800);
  EXPECT_TRUE(stations[0].organized);
  const nlohmann::ordered_json json = StationSummaryJson(stations[1]);
  EXPECT_EQ(json["name"], "station1");
  EXPECT_NEAR(json["heading_deg"].get<double>(), -30.0, 1e-9);
  EXPECT_NEAR(json["world_from_scanner_column_major"][12].get<double>(), -8.0, 1e-9);  // translation x
  EXPECT_NEAR(json["position_m"][1].get<double>(), 2.0, 1e-9);
}

TEST(SiteStations, StationIndicesAreCheckedNamingTheField) {
  EXPECT_NO_THROW(CheckStationIndices({0, 2, 1}, 3, "stations"));
  EXPECT_NO_THROW(CheckStationIndices({}, 3, "stations"));
  try {
    CheckStationIndices({0, 3}, 3, "stations");
    FAIL() << "no error";
  } catch (const OptionsError& error) {
    EXPECT_NE(std::string(error.what()).find("stations"), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("station 3 is out of range"), std::string::npos) << error.what();
  }
  EXPECT_THROW(CheckStationIndices({-1}, 3, "stations"), OptionsError);
  EXPECT_THROW(CheckStationIndices({1, 1}, 3, "stations"), OptionsError);
}

}  // namespace
}  // namespace lidarshop
