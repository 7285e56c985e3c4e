// ReadScanHeader against the full readers: the same scans, grids, point counts, channels and poses for every
// format, from the headers alone; intensity only where the header declares it; E57 images and metadata;
// clear errors on truncated headers.
#include "lidarshop/io/scan_header.h"

#include <algorithm>
#include <filesystem>
#include <set>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "lidarshop/io/e57.h"
#include "lidarshop/io/io_test_util.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

using ::testing::HasSubstr;
using testing_io::InputErrorOf;
using testing_io::kE57Dir;
using testing_io::ReadText;
using testing_io::TempFolder;
using testing_io::WriteText;

// A 5 x 7 scan with a hole, colour, labels, normals and synthesized cells, in a tilted pose far from the
// origin (the LAS reader then picks an origin of its own).
Scan MakeTestScan() {
  Scan scan = MakeScan(5, 7, /*with_color=*/true);
  scan.grid = UniformGrid(5, 7, -0.5, 0.5, -0.3, 0.3);
  scan.direction = DirectionsFromGrid(scan.grid);
  scan.world_from_scanner.topLeftCorner<3, 3>() =
      Eigen::AngleAxisd(0.6, Eigen::Vector3d(0.2, -0.1, 1.0).normalized()).toRotationMatrix();
  scan.world_from_scanner.topRightCorner<3, 1>() = Eigen::Vector3d(12.5, -3.25, 1.5);
  scan.label = cv::Mat(scan.rows, scan.cols, CV_32S, cv::Scalar(kNoLabel));
  scan.normal = cv::Mat(scan.rows, scan.cols, CV_32FC3, cv::Scalar::all(0));
  scan.synthesized = cv::Mat(scan.rows, scan.cols, CV_8U, cv::Scalar(0));
  for (int r = 0; r < scan.rows; ++r) {
    for (int c = 0; c < scan.cols; ++c) {
      if (r == 2 && c == 3) continue;  // no return
      const float range = 4.0f + 0.1f * r + 0.05f * c;
      scan.valid.at<uint8_t>(r, c) = kValid;
      scan.range.at<float>(r, c) = range;
      scan.point.at<cv::Vec3f>(r, c) = scan.direction.at<cv::Vec3f>(r, c) * range;
      scan.intensity.at<float>(r, c) = 0.1f + 0.02f * (r * scan.cols + c);
      scan.color.at<cv::Vec3b>(r, c) = cv::Vec3b(10 * r, 20 * c, 100);
      scan.label.at<int32_t>(r, c) = 1 + (c > 3);
      scan.normal.at<cv::Vec3f>(r, c) = -scan.direction.at<cv::Vec3f>(r, c);
      if (c == 6) scan.synthesized.at<uint8_t>(r, c) = kValid;
    }
  }
  return scan;
}

std::set<std::string> Without(std::vector<std::string> names, const std::set<std::string>& drop) {
  std::set<std::string> out;
  for (const std::string& name : names)
    if (!drop.count(name)) out.insert(name);
  return out;
}

bool Has(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

// The header and the full read agree on what both can know.
void ExpectHeaderMatchesFile(const std::string& path) {
  SCOPED_TRACE(path);
  const ScanFileHeader header = ReadScanHeader(path);
  const ScanFile file = ReadScanFile(path);
  EXPECT_EQ(header.format, file.format);
  EXPECT_EQ(header.file_size_bytes, static_cast<int64_t>(std::filesystem::file_size(path)));
  ASSERT_EQ(header.scans.size(), file.scans.size());
  for (size_t i = 0; i < file.scans.size(); ++i) {
    const ScanHeader& h = header.scans[i];
    const Scan& scan = file.scans[i];
    EXPECT_EQ(h.rows, scan.rows);
    EXPECT_EQ(h.cols, scan.cols);
    EXPECT_EQ(h.organized, scan.rows > 1);
    if (h.points >= 0) {  // unknown for each of several scans in one PLY (only the total is in the header)
      EXPECT_GE(h.points, scan.CountValid());
      EXPECT_LE(h.points, scan.num_cells());
    }
    EXPECT_TRUE(h.world_from_scanner.isApprox(scan.world_from_scanner, 1e-9))
        << h.world_from_scanner << "\nvs\n"
        << scan.world_from_scanner;
    // Intensity is left out of the comparison: the full reader lists it for every scan, the header only
    // when the file declares one. LAS labels and synthetic flags exist when some point's value is non-zero.
    const std::set<std::string> value_dependent =
        file.format == "las" ? std::set<std::string>{"intensity", "label", "synthesized"}
                             : std::set<std::string>{"intensity"};
    EXPECT_EQ(Without(h.channels, value_dependent), Without(ChannelNames(scan), value_dependent));
  }
}

TEST(ScanHeader, EveryFormatAgreesWithTheFullRead) {
  TempFolder folder;
  for (const std::string& extension : SupportedScanWriteExtensions()) {
    Scan scan = MakeTestScan();
    if (extension == "xyz" || extension == "pts") scan.synthesized.release();  // they cannot mark them
    const std::string path = folder.File("scan." + extension);
    WriteScanFile(path, {scan});
    ExpectHeaderMatchesFile(path);
    const ScanFileHeader header = ReadScanHeader(path);
    ASSERT_EQ(header.scans.size(), 1u);
    EXPECT_TRUE(Has(header.scans[0].channels, "intensity")) << extension;
    EXPECT_TRUE(Has(header.scans[0].channels, "rgb")) << extension;
  }
}

TEST(ScanHeader, CountsOfTheFormatsWithAGrid) {
  TempFolder folder;
  const Scan scan = MakeTestScan();
  const int64_t valid = scan.CountValid();
  for (const std::string& extension : {"ptx", "pcd", "e57", "ply", "las"}) {
    WriteScanFile(folder.File(std::string("scan.") + extension), {scan});
  }
  const ScanHeader ptx = ReadScanHeader(folder.File("scan.ptx")).scans.at(0);
  EXPECT_TRUE(ptx.organized);
  EXPECT_EQ(ptx.points, 35);  // every cell is a point line
  const ScanHeader pcd = ReadScanHeader(folder.File("scan.pcd")).scans.at(0);
  EXPECT_TRUE(pcd.organized);
  EXPECT_EQ(pcd.rows, 5);
  EXPECT_EQ(pcd.points, 35);
  EXPECT_TRUE(Has(pcd.channels, "label") && Has(pcd.channels, "normal") && Has(pcd.channels, "synthesized"));
  const ScanHeader e57 = ReadScanHeader(folder.File("scan.e57")).scans.at(0);
  EXPECT_TRUE(e57.organized);
  EXPECT_EQ(e57.rows, 5);
  EXPECT_EQ(e57.cols, 7);
  EXPECT_EQ(e57.coordinates, "cartesian");
  EXPECT_TRUE(Has(e57.channels, "synthesized"));
  const ScanHeader ply = ReadScanHeader(folder.File("scan.ply")).scans.at(0);
  EXPECT_TRUE(ply.organized);
  EXPECT_EQ(ply.points, valid);  // the valid points only
  const ScanHeader las = ReadScanHeader(folder.File("scan.las")).scans.at(0);
  EXPECT_FALSE(las.organized);
  EXPECT_EQ(las.rows, 1);
  EXPECT_EQ(las.cols, valid);
  EXPECT_EQ(las.points, valid);
}

TEST(ScanHeader, SeveralScansInPtxAndPly) {
  TempFolder folder;
  Scan second = MakeTestScan();
  second.world_from_scanner(0, 3) = -7.0;
  for (const std::string& extension : {"ptx", "ply", "e57"}) {
    const std::string path = folder.File(std::string("two.") + extension);
    WriteScanFile(path, {MakeTestScan(), second});
    ExpectHeaderMatchesFile(path);
    EXPECT_EQ(ReadScanHeader(path).scans.at(1).world_from_scanner(0, 3), -7.0);
    EXPECT_EQ(ReadScanHeader(path).scans.at(1).rows, 5);
  }
}

TEST(ScanHeader, IntensityOnlyWhenTheHeaderDeclaresIt) {
  TempFolder folder;
  const std::string pcd = folder.File("no_intensity.pcd");
  WriteText(pcd,
            "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 1\n"
            "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA ascii\n1 2 3\n4 5 6\n");
  const ScanHeader pcd_header = ReadScanHeader(pcd).scans.at(0);
  EXPECT_FALSE(Has(pcd_header.channels, "intensity"));
  EXPECT_EQ(pcd_header.points, 2);
  const std::string ply = folder.File("no_intensity.ply");
  WriteText(ply,
            "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
            "end_header\n1 2 3\n4 5 6\n");
  EXPECT_FALSE(Has(ReadScanHeader(ply).scans.at(0).channels, "intensity"));
  ExpectHeaderMatchesFile(pcd);
  ExpectHeaderMatchesFile(ply);
  // bunnyFloat.e57's prototype has coordinates only.
  EXPECT_FALSE(Has(ReadScanHeader(kE57Dir + "bunnyFloat.e57").scans.at(0).channels, "intensity"));
}

TEST(ScanHeader, RealE57FilesAgreeWithTheFullRead) {
  for (const char* name : {"pumpA.e57", "bunnyFloat.e57", "tiny_spherical.e57", "tinyCartesianFloatRgb.e57",
                           "tiny_pc_and_images.e57", "integer_intensity.e57", "scaled_integer_intensity.e57",
                           "float_intensity_without_min_max.e57", "cartesian_invalid_state_single.e57",
                           "no_ext_namespace.e57", "empty_pc.e57"}) {
    ExpectHeaderMatchesFile(kE57Dir + name);
  }
}

TEST(ScanHeader, PumpAMetadataAndPhoto) {
  const ScanFileHeader header = ReadScanHeader(kE57Dir + "pumpA.e57");
  EXPECT_EQ(header.guid, "{4F947749-517F-49D1-9AD9-A899110EFFDD}");
  EXPECT_EQ(header.format_version, "E57 1.0");
  // creationDateTime 996438465.78 GPS seconds, 15 leap seconds behind in 2011.
  EXPECT_EQ(header.creation_utc, "2011-08-03T20:27:30Z");
  ASSERT_EQ(header.scans.size(), 1u);
  const ScanHeader& scan = header.scans[0];
  EXPECT_EQ(scan.name, "pumpA");
  EXPECT_EQ(scan.e57.guid, "{116B6772-AC46-41B3-B70C-0C63CC671447}");
  EXPECT_EQ(scan.rows * scan.cols, 1074 * 345);
  EXPECT_EQ(scan.points, 155201);
  ASSERT_EQ(header.images.size(), 1u);
  EXPECT_EQ(header.images[0].name, "pumpVisual");
  EXPECT_EQ(header.images[0].projection, "visual");
  EXPECT_EQ(header.images[0].width_px, 3072);
  EXPECT_EQ(header.images[0].height_px, 2304);
  EXPECT_EQ(header.images[0].encoding, "jpeg");
  EXPECT_EQ(header.images[0].encoded_bytes, 1504576);
}

TEST(ScanHeader, ImagesNameTheirScanAndSensor) {
  const ScanFileHeader header = ReadScanHeader(kE57Dir + "tiny_pc_and_images.e57");
  ASSERT_EQ(header.images.size(), 4u);
  const ScanImageHeader& spherical = header.images[1];
  EXPECT_EQ(spherical.projection, "spherical");
  EXPECT_EQ(spherical.encoding, "png");
  EXPECT_EQ(spherical.scan_index, 0);  // associatedData3DGuid
  EXPECT_EQ(spherical.e57.sensor_vendor, "vendor");
  EXPECT_EQ(spherical.e57.sensor_model, "sensor");
  EXPECT_EQ(spherical.e57.sensor_serial_number, "serial");
  EXPECT_EQ(spherical.world_from_camera(0, 3), 1.0);
  EXPECT_EQ(header.images[0].scan_index, -1);
  EXPECT_EQ(header.images[2].projection, "pinhole");
}

TEST(ScanHeader, GpsTimeToUtc) {
  EXPECT_EQ(UtcFromGpsSeconds(0), "1980-01-06T00:00:00Z");
  // 2017-01-01T00:00:00Z is GPS second 1167264018 (18 leap seconds since 1980).
  EXPECT_EQ(UtcFromGpsSeconds(1167264018), "2017-01-01T00:00:00Z");
  EXPECT_EQ(UtcFromGpsSeconds(1167264016.5), "2016-12-31T23:59:59Z");
  EXPECT_EQ(UtcFromGpsSeconds(std::numeric_limits<double>::quiet_NaN()), "");
}

TEST(ScanHeader, JsonKeysInReadingOrder) {
  TempFolder folder;
  const std::string path = folder.File("scan.ptx");
  WriteScanFile(path, {MakeTestScan()});
  const nlohmann::ordered_json json = ToJson(ReadScanHeader(path));
  std::vector<std::string> keys;
  for (const auto& item : json.items()) keys.push_back(item.key());
  EXPECT_EQ(keys, (std::vector<std::string>{"file", "format", "format_version", "size_bytes", "scans"}));
  const auto& scan = json["scans"][0];
  EXPECT_EQ(scan["rows"], 5);
  EXPECT_EQ(scan["cells"], 35);
  EXPECT_EQ(scan["points"], 35);
  EXPECT_EQ(scan["organized"], true);
  EXPECT_NEAR(scan["world_from_scanner"][0][3].get<double>(), 12.5, 1e-12);
}

TEST(ScanHeader, TruncatedHeadersGiveClearErrors) {
  TempFolder folder;
  const Scan scan = MakeTestScan();
  for (const std::string& extension : {"ptx", "ply", "pcd", "las", "e57"}) {
    WriteScanFile(folder.File("full." + extension), {scan});
  }
  auto cut = [&](const std::string& extension, size_t bytes) {
    const std::string path = folder.File("cut_" + std::to_string(bytes) + "." + extension);
    WriteText(path, ReadText(folder.File("full." + extension)).substr(0, bytes));
    return InputErrorOf([&] { ReadScanHeader(path); });
  };
  EXPECT_THAT(cut("ptx", 10), HasSubstr("line"));
  EXPECT_THAT(cut("ptx", 10), HasSubstr("cut_10.ptx"));
  // The header whole, the point lines not.
  const std::string ptx = ReadText(folder.File("full.ptx"));
  size_t header_end = 0;
  for (int line = 0; line < 10; ++line) header_end = ptx.find('\n', header_end) + 1;
  EXPECT_THAT(cut("ptx", header_end + 30), HasSubstr("truncated"));
  EXPECT_THAT(cut("ply", 40), HasSubstr("end_header"));
  EXPECT_THAT(cut("pcd", 40), HasSubstr("DATA"));
  EXPECT_THAT(cut("las", 100), HasSubstr("truncated"));
  EXPECT_THAT(cut("las", 0), HasSubstr("empty"));
  EXPECT_THAT(cut("e57", 1000), HasSubstr("whole number of 1024-byte E57 pages"));
  EXPECT_THAT(cut("e57", 1024), HasSubstr("filePhysicalLength"));
  EXPECT_THAT(InputErrorOf([&] { ReadScanHeader(folder.File("missing.ptx")); }), HasSubstr("missing.ptx"));
  EXPECT_THAT(InputErrorOf([&] { ReadScanHeader(folder.File("scan.laz")); }), HasSubstr("scan.laz"));
  // A LAZ header is a LAS header; the points are compressed.
  const ScanFileHeader laz = ReadScanHeader(LIDARSHOP_SHARED_DATA_DIR "/interop/laz/autzen_trim.laz");
  EXPECT_EQ(laz.format_version, "LAZ (LAS 1.2 point format 3)");
  ASSERT_EQ(laz.scans.size(), 1u);
  EXPECT_EQ(laz.scans[0].points, 110000);
}

TEST(ScanHeader, CorruptE57PagesAreNamed) {
  EXPECT_THAT(InputErrorOf([] { ReadScanHeader(kE57Dir + "corrupt_crc.e57"); }), HasSubstr("page"));
  // empty.e57 has no data3D at all: no scan, as the full reader says.
  EXPECT_TRUE(ReadScanHeader(kE57Dir + "empty.e57").scans.empty());
  ExpectHeaderMatchesFile(kE57Dir + "empty.e57");
}

}  // namespace
}  // namespace lidarshop
