// The summaries `lidarshop info` writes: the rounding policy, the keys in reading order (the header's, then
// what the points add), stations of a file of several scans, and the one-line report.
#include "lidarshop/io/scan_summary.h"

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "lidarshop/util/options.h"

namespace lidarshop {
namespace {

std::vector<std::string> Keys(const nlohmann::ordered_json& json) {
  std::vector<std::string> keys;
  for (const auto& item : json.items()) keys.push_back(item.key());
  return keys;
}

// Two scans of a site as a header describes them: the second turned 30 degrees to the left, 10 m away; its
// grid unknown (an E57 scan without indexBounds).
ScanFileHeader TwoStationHeader() {
  ScanFileHeader header;
  header.path = "site.ptx";
  header.format = "ptx";
  header.format_version = "PTX";
  header.file_size_bytes = 1234;
  for (int i = 0; i < 2; ++i) {
    ScanHeader scan;
    scan.organized = true;
    scan.rows = i == 0 ? 3 : -1;
    scan.cols = i == 0 ? 4 : -1;
    scan.points = i == 0 ? 12 : -1;
    scan.channels = {"xyz", "range", "intensity"};
    header.scans.push_back(scan);
  }
  header.scans[1].world_from_scanner.topLeftCorner<3, 3>() =
      Eigen::AngleAxisd(30 * M_PI / 180, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  header.scans[1].world_from_scanner.topRightCorner<3, 1>() = Eigen::Vector3d(10, 0.1 + 0.2, 0);
  return header;
}

TEST(ScanSummary, RoundsAsPeopleReadNumbers) {
  EXPECT_EQ(RoundStatistic(1.23456789), 1.234568);
  EXPECT_EQ(RoundStatistic(-1e-9), 0.0);
  EXPECT_FALSE(std::signbit(RoundStatistic(-1e-9)));  // no -0
  EXPECT_EQ(RoundRadians(1.234567891e-4), 1.23457e-4);
  EXPECT_EQ(RoundValue(0.1 + 0.2), 0.3);
  EXPECT_EQ(RoundValue(1e-13), 0.0);
  EXPECT_TRUE(std::isnan(RoundValue(std::nan(""))));

  nlohmann::ordered_json json = {{"range_m", {{"min", 1.23456789}}},
                                 {"pixel_width_rad", 1.234567891e-4},
                                 {"scale", {0.1 + 0.2, 2}},
                                 {"heading_deg", 30.0000000004}};
  RoundForReading(&json);
  EXPECT_EQ(json["range_m"]["min"].get<double>(), 1.234568);
  EXPECT_EQ(json["pixel_width_rad"].get<double>(), 1.23457e-4);
  EXPECT_EQ(json["scale"][0].get<double>(), 0.3);
  EXPECT_TRUE(json["scale"][1].is_number_integer());  // integers stay as they are
  EXPECT_EQ(json["heading_deg"].get<double>(), 30.0);
}

TEST(ScanSummary, HeaderKeysStationsAndBriefReport) {
  const ScanFileSummary summary = SummarizeScanFile(TwoStationHeader());
  ASSERT_EQ(summary.stations.size(), 2u);
  EXPECT_EQ(summary.stations[1].heading_deg, 30.0);
  EXPECT_EQ(summary.stations[1].position, (std::vector<double>{10, 0.3, 0}));
  EXPECT_EQ(summary.scans[1].world_from_scanner(1, 3), 0.3);  // not 0.30000000000000004

  const nlohmann::ordered_json json = ToJson(summary);
  EXPECT_EQ(Keys(json), (std::vector<std::string>{"file", "format", "format_version", "size_bytes", "scans",
                                                  "stations"}));
  EXPECT_EQ(Keys(json["scans"][0]), (std::vector<std::string>{"index", "organized", "rows", "cols", "cells",
                                                              "points", "channels", "world_from_scanner"}));
  EXPECT_EQ(json["scans"][0]["cells"], 12);
  EXPECT_TRUE(json["scans"][1]["rows"].is_null());
  EXPECT_TRUE(json["scans"][1]["cells"].is_null());
  EXPECT_EQ(json["stations"][1]["position"][1].get<double>(), 0.3);
  EXPECT_EQ(BriefReport(summary), "site.ptx: PTX file, 2 scan(s) at 2 stations, 12 points, 0 image(s)");

  ScanFileHeader one = TwoStationHeader();
  one.scans.resize(1);
  one.format = "e57";
  one.format_version.clear();
  const ScanFileSummary single = SummarizeScanFile(one);
  EXPECT_TRUE(single.stations.empty());
  EXPECT_EQ(Keys(ToJson(single)),
            (std::vector<std::string>{"file", "format", "size_bytes", "scans", "images"}));
  EXPECT_EQ(BriefReport(single), "site.ptx: e57 file, 1 scan(s), 12 points, 0 image(s)");
}

TEST(ScanSummary, StatisticsFollowTheHeaderKeys) {
  ScanFileHeader header = TwoStationHeader();
  std::vector<Scan> scans = {MakeScan(3, 4), MakeScan(2, 2, false, false)};
  // Two returns in the first scan, 2 m and 4 m ahead; none in the second.
  for (int col = 0; col < 2; ++col) {
    const float range = 2.0f + 2 * col;
    scans[0].valid.at<uint8_t>(1, col) = 1;
    scans[0].range.at<float>(1, col) = range;
    scans[0].point.at<cv::Vec3f>(1, col) = cv::Vec3f(0, range, 0.5f);
  }
  const ScanFileStatistics summary = SummarizeScanFileStatistics(header, scans, {});
  const ScanStatisticsSummary& first = summary.scans[0];
  EXPECT_EQ(first.valid, 2);
  ASSERT_TRUE(first.range_m.has_value());
  EXPECT_EQ(first.range_m->mean, 3.0);
  ASSERT_TRUE(first.bounds.has_value());
  EXPECT_EQ(first.bounds->max, (std::vector<double>{0, 4, 0.5}));
  ASSERT_TRUE(first.intensity.has_value());
  EXPECT_EQ(first.intensity->max, 0.5);
  // The second scan's grid is known once its points are read; it has no return.
  EXPECT_EQ(summary.scans[1].header.rows, 2);
  EXPECT_FALSE(summary.scans[1].bounds.has_value());

  const nlohmann::ordered_json json = ToJson(summary);
  EXPECT_EQ(Keys(json["scans"][0]),
            (std::vector<std::string>{"index", "organized", "rows", "cols", "cells", "points", "channels",
                                      "world_from_scanner", "valid", "bounds", "range_m", "intensity", "grid",
                                      "grid_fit_rms_residual_rad"}));
  EXPECT_TRUE(json["scans"][1]["bounds"].is_null());  // read, without returns
  EXPECT_FALSE(json["scans"][1].contains("range_m"));
  EXPECT_EQ(json["scans"][1]["cells"], 4);
  EXPECT_FALSE(json.contains("images"));
  EXPECT_EQ(BriefReport(summary), "site.ptx: PTX file, 2 scan(s) at 2 stations, 2 points, 0 image(s)");
}

}  // namespace
}  // namespace lidarshop
