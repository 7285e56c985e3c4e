// The format registry against the readers and writers it describes: what it says a format holds is what a
// write and a read of that format keep.
#include "lidarshop/io/formats.h"

#include <fstream>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "lidarshop/io/io_test_util.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"

namespace lidarshop {
namespace {

using testing::HasSubstr;
using testing_io::TempFolder;

// A 3 x 4 organized scan with every channel the registry describes.
Scan EveryChannelScan() {
  Scan scan = MakeScan(3, 4, /*color=*/true, /*intensity=*/true);
  scan.grid = UniformGrid(3, 4, -0.2, 0.2, -0.1, 0.1);
  scan.direction = DirectionsFromGrid(scan.grid);
  scan.label = cv::Mat(3, 4, CV_32S, cv::Scalar(7));
  scan.normal = cv::Mat(3, 4, CV_32FC3, cv::Scalar(0, 0, 1));
  scan.true_range = cv::Mat(3, 4, CV_32F, cv::Scalar(2.5));
  scan.synthesized = cv::Mat(3, 4, CV_8U, cv::Scalar(0));
  scan.synthesized.at<uint8_t>(1, 2) = 1;
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 4; ++col) {
      const float range = 2.0f + 0.1f * (row * 4 + col);
      scan.valid.at<uint8_t>(row, col) = kValid;
      scan.point.at<cv::Vec3f>(row, col) = scan.direction.at<cv::Vec3f>(row, col) * range;
      scan.range.at<float>(row, col) = range;
      scan.intensity.at<float>(row, col) = 0.25f;
      scan.color.at<cv::Vec3b>(row, col) = cv::Vec3b(10, 20, 30);
    }
  }
  return scan;
}

TEST(Formats, EveryFormatHasAReaderAndAWriterAsTheTableSays) {
  for (const ScanFormatInfo& format : ScanFormats()) {
    const std::string path = "x." + std::string(format.extension);
    SCOPED_TRACE(path);
    ASSERT_TRUE(format.read) << "a format in the table that nothing reads";
    EXPECT_NO_THROW(CheckScanFileReadable(path));
    if (format.write) {
      EXPECT_NO_THROW(CheckScanFileFormat(path));
    } else {
      EXPECT_FALSE(format.write_refusal.empty());
      try {
        CheckScanFileFormat(path);
        ADD_FAILURE() << "a format the table does not write was accepted for writing";
      } catch (const InputError& error) {
        EXPECT_THAT(error.what(), HasSubstr(std::string(format.write_refusal)));
      }
    }
  }
  EXPECT_THROW(CheckScanFileReadable("x.abc"), InputError);
  EXPECT_EQ(FindScanFormat("abc"), nullptr);
}

TEST(Formats, WhatTheTableSaysIsHeldSurvivesAWriteAndARead) {
  TempFolder folder;
  const Scan scan = EveryChannelScan();
  for (const ScanFormatInfo& format : ScanFormats()) {
    if (!format.write) continue;
    const std::string path = folder.File("every." + std::string(format.extension));
    SCOPED_TRACE(path);
    WriteScanFile(path, {scan});
    const ScanFile file = ReadScanFile(path);
    ASSERT_EQ(file.scans.size(), 1u);
    const Scan& back = file.scans[0];
    EXPECT_EQ(back.rows == 3 && back.cols == 4, format.grid) << back.rows << " x " << back.cols;
    EXPECT_EQ(back.has_intensity(), format.intensity.held);
    EXPECT_EQ(back.has_color(), format.color.held);
    EXPECT_EQ(!back.label.empty(), format.label.held);
    EXPECT_EQ(!back.normal.empty(), format.normal.held);
    EXPECT_EQ(!back.true_range.empty(), format.true_range.held);
    // A format that cannot mark synthesized points writes them like measured ones (the plan says so).
    EXPECT_EQ(!back.synthesized.empty() && cv::countNonZero(back.synthesized) == 1, format.synthesized.held);
  }
}

TEST(Formats, LayerBehindRefusalNamesTheFormatsThatHoldIt) {
  EXPECT_EQ(LayerBehindRefusal(*FindScanFormat("ptx")),
            "PTX cannot hold two returns per cell; write E57, PLY, PCD or LAS");
  EXPECT_EQ(FormatNamesWhere([](const ScanFormatInfo& f) { return f.images; }), "E57");
  EXPECT_EQ(FormatNamesWhere([](const ScanFormatInfo& f) { return f.write && !f.grid; }), "LAS, XYZ or PTS");
  TempFolder folder;
  const Scan scan = EveryChannelScan();
  for (const ScanFormatInfo& format : ScanFormats()) {
    if (!format.write) continue;
    const std::string path = folder.File("layers." + std::string(format.extension));
    SCOPED_TRACE(path);
    if (format.layer_behind) {
      EXPECT_NO_THROW(WriteScanWithLayer(path, scan, scan));
    } else {
      EXPECT_THROW(WriteScanWithLayer(path, scan, scan), InputError);
    }
  }
}

TEST(Formats, TheDocsHoldTheCurrentTable) {
  std::ifstream docs(LIDARSHOP_SOURCE_DIR "/docs/file-formats.md");
  std::stringstream text;
  text << docs.rdbuf();
  EXPECT_THAT(text.str(), HasSubstr(ScanFormatsMarkdown()))
      << "docs/file-formats.md: paste the output of `lidarshop formats --markdown`";
}

TEST(Formats, JsonHasOneObjectPerFormatWithItsChannels) {
  const nlohmann::ordered_json json = ToJson(ScanFormatsSummary{SummarizeScanFormats()})["formats"];
  ASSERT_EQ(json.size(), ScanFormats().size());
  EXPECT_EQ(json[0]["extension"], "ptx");
  EXPECT_EQ(json[0]["label"], false);
  const auto las =
      std::find_if(json.begin(), json.end(), [](const auto& f) { return f["extension"] == "las"; });
  ASSERT_NE(las, json.end());
  EXPECT_EQ((*las)["label"], "classification");
  EXPECT_EQ((*las)["scans"], "merged");
  // A refusal only where the format is not written: LAZ is read, not written.
  EXPECT_FALSE(json[0].contains("write_refusal"));
  const auto laz =
      std::find_if(json.begin(), json.end(), [](const auto& f) { return f["extension"] == "laz"; });
  ASSERT_NE(laz, json.end());
  EXPECT_EQ((*laz)["write"], false);
  EXPECT_THAT((*laz)["write_refusal"].get<std::string>(), HasSubstr("LAZ"));
}

}  // namespace
}  // namespace lidarshop
