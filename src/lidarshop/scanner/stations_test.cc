// Scenes of several stations ("stations", "at_stations"; docs/stations.md): parsing, what each station sees,
// and a site written to one E57 and read back as a list of organized scans with their poses.
#include <filesystem>

#include <gtest/gtest.h>

#include "lidarshop/io/scan_io.h"
#include "lidarshop/scanner/scanner.h"
#include "lidarshop/scanner/scene.h"
#include "lidarshop/scanner/site_scan.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

// Two stations 6 m apart facing a wall; a box (label 2) in front of the wall only at station 0.
constexpr char kSite[] = R"({
  "stations": [
    {"position": [-3, 0, 1.5], "rotate_deg": [0, 0, -10], "azimuth_deg": [-30, 30], "elevation_deg": [-20, 20],
     "columns": 60, "rows": 40, "seed": 1},
    {"position": [3, 0, 1.5], "rotate_deg": [0, 0, 10], "azimuth_deg": [-30, 30], "elevation_deg": [-20, 20],
     "columns": 60, "rows": 40, "seed": 2}],
  "objects": [
    {"primitive": "plane", "size": [60, 60], "label": 0},
    {"primitive": "box", "size": [20, 0.5, 6], "translate": [0, 12, 3], "label": 1},
    {"primitive": "box", "size": [2, 2, 2], "translate": [0, 6, 1], "label": 2, "at_stations": [0]}]})";

int CountLabel(const Scan& scan, int32_t label) {
  int count = 0;
  for (int r = 0; r < scan.rows; ++r)
    for (int c = 0; c < scan.cols; ++c) count += scan.label.at<int32_t>(r, c) == label;
  return count;
}

TEST(Stations, ParsesStationsAndAtStations) {
  const SceneDescription scene = ParseScene(kSite, "site.json", "");
  ASSERT_EQ(scene.NumStations(), 2);
  EXPECT_EQ(scene.stations[1].position, Eigen::Vector3d(3, 0, 1.5));
  EXPECT_EQ(scene.scanner.position, scene.stations[0].position);  // the first station stands for the scene
  EXPECT_EQ(scene.objects[2].at_stations, std::vector<int>{0});
  EXPECT_TRUE(scene.objects[1].AtStation(1));
  EXPECT_FALSE(scene.objects[2].AtStation(1));
  const SceneDescription at1 = SceneAtStation(scene, 1);
  EXPECT_EQ(at1.objects.size(), 2u);
  EXPECT_EQ(at1.NumStations(), 1);
  EXPECT_EQ(at1.scanner.position, Eigen::Vector3d(3, 0, 1.5));
  EXPECT_EQ(SceneAtStation(scene, 0).objects.size(), 3u);
  EXPECT_THROW(SceneAtStation(scene, 2), std::out_of_range);
  // A one-station scene is its own station 0, as before.
  const SceneDescription one =
      ParseScene(R"({"scanner": {"position": [1, 2, 3]}, "objects": [{"primitive": "box"}]})", "one", "");
  EXPECT_EQ(one.NumStations(), 1);
  EXPECT_TRUE(one.stations.empty());
  EXPECT_EQ(SceneAtStation(one, 0).scanner.position, Eigen::Vector3d(1, 2, 3));
}

TEST(Stations, RefusesBadStationsNamingTheField) {
  auto message = [](const std::string& text) {
    try {
      ParseScene(text, "bad.json", "");
    } catch (const InputError& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(R"({"scanner": {}, "stations": [{}], "objects": []})").find("not both"),
            std::string::npos);
  EXPECT_NE(message(R"({"stations": [], "objects": []})").find("stations"), std::string::npos);
  EXPECT_NE(message(R"({"stations": [{"rows": 1}], "objects": []})").find("stations[0]"), std::string::npos);
  const std::string out_of_range =
      message(R"({"stations": [{}, {}], "objects": [{"primitive": "box", "at_stations": [2]}]})");
  EXPECT_NE(out_of_range.find("objects[0]"), std::string::npos) << out_of_range;
  EXPECT_NE(out_of_range.find("at_stations"), std::string::npos) << out_of_range;
  EXPECT_NE(message(R"({"objects": [{"primitive": "box", "at_stations": [0, 0]}]})").find("twice"),
            std::string::npos);
  EXPECT_NE(message(R"({"objects": [{"primitive": "box", "at_stations": [1]}]})").find("at_stations"),
            std::string::npos);
}

TEST(Stations, EachStationSeesItsObjectsAndTheSiteRoundTripsThroughE57) {
  const SceneDescription scene = ParseScene(kSite, "site.json", "");
  std::vector<Scan> scans;
  for (int i = 0; i < scene.NumStations(); ++i) {
    const SceneDescription station = SceneAtStation(scene, i);
    scans.push_back(SyntheticScanner(station).Acquire(station.scanner));
    scans.back().name = "station" + std::to_string(i);
  }
  EXPECT_GT(CountLabel(scans[0], 2), 20);                       // the box is there at station 0
  EXPECT_EQ(CountLabel(scans[1], 2), 0);                        // and gone at station 1
  EXPECT_GT(CountLabel(scans[1], 1), CountLabel(scans[0], 1));  // where the wall shows through
  const std::string path = (std::filesystem::temp_directory_path() / "stations_test_site.e57").string();
  WriteScanFile(path, scans);
  const ScanFile file = ReadScanFile(path);
  std::filesystem::remove(path);
  ASSERT_EQ(file.scans.size(), 2u);
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(file.scans[i].name, "station" + std::to_string(i));
    EXPECT_EQ(file.scans[i].rows, 40);
    EXPECT_EQ(file.scans[i].cols, 60);
    EXPECT_LT((file.scans[i].world_from_scanner - scene.stations[i].WorldFromScanner()).norm(), 1e-9);
    EXPECT_EQ(file.scans[i].CountValid(), scans[i].CountValid());
  }
}

TEST(Stations, ScanStationsScansEveryStationWithTheObjectsThere) {
  const SceneDescription scene = ParseScene(kSite, "site.json", "");
  const std::vector<Scan> scans = ScanStations(scene);
  ASSERT_EQ(scans.size(), 2u);
  EXPECT_EQ(scans[0].name, "station0");
  EXPECT_EQ(scans[1].name, "station1");
  // Each at its own pose, the box only where it stands (station 0).
  EXPECT_NEAR(scans[0].world_from_scanner(0, 3), -3.0, 1e-9);
  EXPECT_NEAR(scans[1].world_from_scanner(0, 3), 3.0, 1e-9);
  EXPECT_GT(CountLabel(scans[0], 2), 20);
  EXPECT_EQ(CountLabel(scans[1], 2), 0);
  EXPECT_GT(CountLabel(scans[1], 1), 100);
  // A scene with one scanner: the one scan SynthesizeScan gives.
  const SceneDescription one = SceneAtStation(scene, 1);
  const std::vector<Scan> single = ScanStations(one);
  ASSERT_EQ(single.size(), 1u);
  EXPECT_NE(single[0].name, "station0");
  EXPECT_EQ(single[0].CountValid(), scans[1].CountValid());
  EXPECT_EQ(cv::norm(single[0].range, scans[1].range, cv::NORM_INF), 0.0);
}

}  // namespace
}  // namespace lidarshop
