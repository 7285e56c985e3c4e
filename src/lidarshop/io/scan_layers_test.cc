// The synthesized flag in E57 (lidarshop's extension field) and scans written with a second layer behind them
// (WriteScanWithLayer: E57 second returns, PLY two scans, PCD one cloud, PTX refused); the lists of formats.
#include <algorithm>
#include <filesystem>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "lidarshop/io/e57.h"
#include "lidarshop/io/e57_format.h"
#include "lidarshop/io/io_test_util.h"
#include "lidarshop/io/mesh_io.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using testing_io::TempFolder;

// A 6 x 8 scan before a wall at 5 m with an object at 2 m in the middle 2 x 4 cells, one hole (no return) at
// (0, 0), colour and a tilted pose. `behind` is the wall filled in behind the object and in the hole
// (9 cells), marked synthesized, intensity 0.25.
struct Layers {
  Scan front;
  Scan behind;
};

Layers MakeLayers() {
  Layers layers;
  Scan& front = layers.front;
  front = MakeScan(6, 8, /*with_color=*/true);
  front.name = "wall";
  front.grid = UniformGrid(6, 8, -0.4, 0.4, -0.3, 0.3);
  front.direction = DirectionsFromGrid(front.grid);
  front.world_from_scanner.topLeftCorner<3, 3>() =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.1, 0.2, 1.0).normalized()).toRotationMatrix();
  front.world_from_scanner.topRightCorner<3, 1>() = Eigen::Vector3d(3.5, -2.0, 1.25);
  Scan behind = Clone(front);
  behind.valid.setTo(0);
  behind.range.setTo(0);
  behind.point.setTo(cv::Scalar::all(0));
  behind.intensity.setTo(0.5);
  behind.color.setTo(cv::Scalar::all(0));
  for (int r = 0; r < front.rows; ++r) {
    for (int c = 0; c < front.cols; ++c) {
      const bool hole = r == 0 && c == 0;
      const bool object = r >= 2 && r < 4 && c >= 2 && c < 6;
      const cv::Vec3f d = front.direction.at<cv::Vec3f>(r, c);
      if (!hole) {
        const float range = object ? 2.0f + 0.01f * c : 5.0f + 0.02f * r;
        front.valid.at<uint8_t>(r, c) = kValid;
        front.range.at<float>(r, c) = range;
        front.point.at<cv::Vec3f>(r, c) = d * range;
        front.intensity.at<float>(r, c) = object ? 0.9f : 0.1f * (r + 1);
        front.color.at<cv::Vec3b>(r, c) = object ? cv::Vec3b(200, 10, 10) : cv::Vec3b(20, 30 + r, 40 + c);
      }
      if (!object && !hole) continue;
      behind.valid.at<uint8_t>(r, c) = kValid;
      behind.range.at<float>(r, c) = 5.0f;
      behind.point.at<cv::Vec3f>(r, c) = d * 5.0f;
      behind.intensity.at<float>(r, c) = 0.25f;
      behind.color.at<cv::Vec3b>(r, c) = cv::Vec3b(20, 31, 42);
    }
  }
  behind.synthesized = cv::Mat(front.rows, front.cols, CV_8U, cv::Scalar(0));
  behind.synthesized.setTo(kValid, behind.valid);
  layers.behind = behind;
  return layers;
}

std::string XmlTextOf(const std::vector<uint8_t>& file_bytes) {
  const std::vector<uint8_t> logical = e57::LogicalFromPages("test.e57", file_bytes);
  const e57::Header header = e57::ParseHeader("test.e57", logical);
  const uint64_t start = e57::LogicalFromPhysical(header.xml_physical_offset);
  return std::string(logical.begin() + start, logical.begin() + start + header.xml_logical_length);
}

// Points, ranges, intensities, colours and flags of the valid cells are the same; the validity masks too.
void ExpectSameReturns(const Scan& expected, const Scan& actual) {
  ASSERT_EQ(expected.rows, actual.rows);
  ASSERT_EQ(expected.cols, actual.cols);
  EXPECT_LT((expected.world_from_scanner - actual.world_from_scanner).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_EQ(cv::countNonZero(expected.valid != actual.valid), 0);
  for (int64_t c = 0; c < expected.num_cells(); ++c) {
    if (!expected.valid.ptr<uint8_t>()[c]) continue;
    ASSERT_EQ(expected.point.ptr<cv::Vec3f>()[c], actual.point.ptr<cv::Vec3f>()[c]) << "cell " << c;
    ASSERT_EQ(expected.intensity.ptr<float>()[c], actual.intensity.ptr<float>()[c]) << "cell " << c;
    ASSERT_EQ(expected.color.ptr<cv::Vec3b>()[c], actual.color.ptr<cv::Vec3b>()[c]) << "cell " << c;
    const uint8_t flag = expected.synthesized.empty() ? 0 : expected.synthesized.ptr<uint8_t>()[c];
    ASSERT_EQ(flag, actual.synthesized.ptr<uint8_t>()[c]) << "cell " << c;
  }
}

TEST(E57Synthesized, FlagSurvivesARoundTripAsAnExtensionField) {
  Scan scan = MakeLayers().front;
  scan.synthesized = cv::Mat(scan.rows, scan.cols, CV_8U, cv::Scalar(0));
  scan.synthesized.at<uint8_t>(1, 3) = kValid;
  scan.synthesized.at<uint8_t>(5, 7) = kValid;
  const std::vector<uint8_t> bytes = EncodeE57({scan});
  const std::string xml = XmlTextOf(bytes);
  EXPECT_THAT(xml, HasSubstr("xmlns:lidarshop=\"http://lidarshop.dev/e57/1.0\""));
  EXPECT_THAT(xml, HasSubstr("<lidarshop:synthesized type=\"Integer\" minimum=\"0\" maximum=\"1\""));
  EXPECT_THAT(xml, Not(HasSubstr("returnIndex")));  // one layer: no return fields

  const E57File file = ReadE57Bytes(bytes, "synthesized.e57");
  ASSERT_EQ(file.scans.size(), 1u);
  const Scan& back = file.scans[0];
  ASSERT_FALSE(back.synthesized.empty());
  EXPECT_EQ(cv::countNonZero(back.synthesized), 2);
  EXPECT_EQ(back.synthesized.at<uint8_t>(1, 3), kValid);
  EXPECT_EQ(back.synthesized.at<uint8_t>(5, 7), kValid);
  ExpectSameReturns(scan, back);
  EXPECT_EQ(file.second_returns.size(), 1u);
  EXPECT_EQ(file.second_returns[0].num_cells(), 0);
  EXPECT_TRUE(file.warnings.empty());
}

TEST(E57Synthesized, FilesWithoutTheFlagReadAsBefore) {
  const Scan scan = MakeLayers().front;  // no synthesized channel
  const std::vector<uint8_t> bytes = EncodeE57({scan});
  // No flag field (the namespace may still be declared for the no-return cells' rays).
  EXPECT_THAT(XmlTextOf(bytes), Not(HasSubstr("lidarshop:synthesized")));
  const E57File file = ReadE57Bytes(bytes, "plain.e57");
  EXPECT_TRUE(file.scans[0].synthesized.empty());
  EXPECT_EQ(file.scans[0].CountValid(), scan.CountValid());
}

TEST(E57Synthesized, AFieldUnderAnUndeclaredPrefixIsIgnored) {
  // The same field name bound to another namespace is someone else's field: it must not set the flag.
  Scan scan = MakeLayers().front;
  scan.synthesized = cv::Mat(scan.rows, scan.cols, CV_8U, cv::Scalar(kValid));
  std::vector<uint8_t> bytes = EncodeE57({scan});
  std::vector<uint8_t> logical = e57::LogicalFromPages("x.e57", bytes);
  const std::string from = kLidarshopE57Namespace, to = "http://example.com/e57/19.90";
  ASSERT_EQ(from.size(), to.size());  // same length: offsets stay valid
  const auto at = std::search(logical.begin(), logical.end(), from.begin(), from.end());
  ASSERT_NE(at, logical.end());
  std::copy(to.begin(), to.end(), at);
  const E57File file = ReadE57Bytes(e57::PagesFromLogical(logical), "other_namespace.e57");
  EXPECT_TRUE(file.scans[0].synthesized.empty());
  EXPECT_EQ(file.scans[0].CountValid(), scan.CountValid());
}

TEST(ScanLayers, E57KeepsBothLayersAsFirstAndSecondReturns) {
  const Layers layers = MakeLayers();
  TempFolder folder;
  const std::string path = folder.File("kept.e57");
  WriteScanWithLayer(path, layers.front, layers.behind);
  const std::vector<uint8_t> bytes = EncodeE57WithLayer(layers.front, layers.behind);
  EXPECT_EQ(bytes.size(), std::filesystem::file_size(path));  // the same bytes
  const std::string xml = XmlTextOf(bytes);
  EXPECT_THAT(xml, HasSubstr("<returnIndex type=\"Integer\" minimum=\"0\" maximum=\"1\""));
  EXPECT_THAT(xml, HasSubstr("<returnCount type=\"Integer\" minimum=\"1\" maximum=\"2\""));
  EXPECT_THAT(xml, HasSubstr("<returnMaximum type=\"Integer\">1</returnMaximum>"));
  // 47 front returns + 1 direction-only hole + 9 second returns.
  EXPECT_THAT(xml, HasSubstr("recordCount=\"57\""));

  const E57File file = ReadE57(path);
  ASSERT_EQ(file.scans.size(), 1u);
  ASSERT_EQ(file.second_returns.size(), 1u);
  EXPECT_TRUE(file.warnings.empty());
  const Scan& front = file.scans[0];
  const Scan& behind = file.second_returns[0];
  EXPECT_EQ(front.CountValid(), 47);
  EXPECT_EQ(behind.CountValid(), 9);
  EXPECT_EQ(behind.valid.at<uint8_t>(0, 0), kValid);  // behind a front record without a return
  EXPECT_EQ(front.valid.at<uint8_t>(0, 0), 0);
  ExpectSameReturns(layers.front, front);  // front: no synthesized channel given, read back as all 0
  ExpectSameReturns(layers.behind, behind);
  EXPECT_EQ(behind.name, "wall");
  EXPECT_EQ(cv::norm(front.direction, behind.direction, cv::NORM_INF), 0.0);  // the same rays
  EXPECT_EQ(behind.synthesized.at<uint8_t>(2, 2), kValid);
  EXPECT_EQ(front.synthesized.at<uint8_t>(2, 2), 0);
  // ReadScanFile gives the front layer, the scan other tools see.
  EXPECT_EQ(ReadScanFile(path).scans[0].CountValid(), 47);
}

TEST(ScanLayers, ThirdAndLaterReturnsAreLeftOutAndReported) {
  // Shift every returnIndex up by one (same bit width, same XML length): the front records become second
  // returns and the second returns become third returns, which the reader leaves out and reports.
  const Layers layers = MakeLayers();
  std::vector<uint8_t> logical =
      e57::LogicalFromPages("x.e57", EncodeE57WithLayer(layers.front, layers.behind));
  const std::string from = "<returnIndex type=\"Integer\" minimum=\"0\" maximum=\"1\"";
  const std::string to = "<returnIndex type=\"Integer\" minimum=\"1\" maximum=\"2\"";
  const auto at = std::search(logical.begin(), logical.end(), from.begin(), from.end());
  ASSERT_NE(at, logical.end());
  std::copy(to.begin(), to.end(), at);
  const E57File file = ReadE57Bytes(e57::PagesFromLogical(logical), "shifted.e57");
  ASSERT_EQ(file.scans.size(), 1u);
  EXPECT_EQ(file.scans[0].CountValid(), 0);
  EXPECT_EQ(file.second_returns[0].CountValid(), 47);
  ASSERT_EQ(file.warnings.size(), 1u);
  EXPECT_THAT(file.warnings[0], HasSubstr("shifted.e57: scan 0 ('wall'): 9 records with returnIndex >= 2"));
}

TEST(ScanLayers, ReadScanFileReturnsTheReaderWarningsAndPrintsNothing) {
  // The same file as above through ReadScanFile: the E57 reader's warning reaches ScanFile::warnings, naming
  // the file, and the library writes nothing to stdout or stderr.
  const Layers layers = MakeLayers();
  std::vector<uint8_t> logical =
      e57::LogicalFromPages("x.e57", EncodeE57WithLayer(layers.front, layers.behind));
  const std::string from = "<returnIndex type=\"Integer\" minimum=\"0\" maximum=\"1\"";
  const std::string to = "<returnIndex type=\"Integer\" minimum=\"1\" maximum=\"2\"";
  const auto at = std::search(logical.begin(), logical.end(), from.begin(), from.end());
  ASSERT_NE(at, logical.end());
  std::copy(to.begin(), to.end(), at);
  TempFolder folder;
  const std::string path = folder.File("shifted.e57");
  const std::vector<uint8_t> bytes = e57::PagesFromLogical(logical);
  testing_io::WriteText(path, std::string(bytes.begin(), bytes.end()));
  ::testing::internal::CaptureStdout();
  ::testing::internal::CaptureStderr();
  const ScanFile file = ReadScanFile(path);
  const std::string printed =
      ::testing::internal::GetCapturedStdout() + ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(printed, "");
  ASSERT_EQ(file.scans.size(), 1u);
  ASSERT_EQ(file.warnings.size(), 1u);
  EXPECT_THAT(file.warnings[0], HasSubstr(path + ": scan 0 ('wall'): 9 records with returnIndex >= 2"));
  // A file the reader keeps whole has none.
  const std::string clean = folder.File("clean.e57");
  WriteScanFile(clean, {layers.front});
  EXPECT_TRUE(ReadScanFile(clean).warnings.empty());
}

TEST(ScanLayers, PlyAndPcdHoldTheUnionOfThePointsFlagged) {
  const Layers layers = MakeLayers();
  TempFolder folder;
  const Eigen::Matrix4d& pose = layers.front.world_from_scanner;
  const cv::Vec3f p = layers.behind.point.at<cv::Vec3f>(2, 3);
  const Eigen::Vector3d behind_in_world =
      pose.topLeftCorner<3, 3>() * Eigen::Vector3d(p[0], p[1], p[2]) + pose.topRightCorner<3, 1>();

  WriteScanWithLayer(folder.File("kept.ply"), layers.front, layers.behind);
  const ScanFile ply = ReadScanFile(folder.File("kept.ply"));
  ASSERT_EQ(ply.scans.size(), 2u);  // front, then the layer behind, on one grid
  EXPECT_EQ(ply.scans[0].CountValid(), 47);
  EXPECT_EQ(ply.scans[1].CountValid(), 9);
  EXPECT_EQ(cv::countNonZero(ply.scans[0].synthesized), 0);
  EXPECT_EQ(cv::countNonZero(ply.scans[1].synthesized), 9);
  EXPECT_LT(cv::norm(ply.scans[1].point.at<cv::Vec3f>(2, 3) - p), 1e-5);
  const PointCloud ply_points = ReadPointCloud(folder.File("kept.ply"));  // what a plain reader sees
  ASSERT_EQ(ply_points.size(), 56u);
  ASSERT_EQ(ply_points.synthesized.size(), 56u);
  EXPECT_EQ(std::count(ply_points.synthesized.begin(), ply_points.synthesized.end(), 1), 9);

  WriteScanWithLayer(folder.File("kept.pcd"), layers.front, layers.behind);
  const ScanFile pcd = ReadScanFile(folder.File("kept.pcd"));
  ASSERT_EQ(pcd.scans.size(), 1u);
  const Scan& cloud = pcd.scans[0];
  EXPECT_EQ(cloud.rows, 1);
  EXPECT_EQ(cloud.CountValid(), 56);
  ASSERT_FALSE(cloud.synthesized.empty());
  EXPECT_EQ(cv::countNonZero(cloud.synthesized), 9);
  // The points are in the world frame: the pose is the identity and the behind point is where the pose says.
  EXPECT_TRUE(cloud.world_from_scanner.isIdentity(1e-12));
  bool found = false;
  for (int c = 0; c < cloud.cols; ++c) {
    const cv::Vec3f q = cloud.point.at<cv::Vec3f>(0, c);
    if ((Eigen::Vector3d(q[0], q[1], q[2]) - behind_in_world).norm() < 1e-4) {
      found = true;
      EXPECT_EQ(cloud.synthesized.at<uint8_t>(0, c), kValid);
      EXPECT_EQ(cloud.intensity.at<float>(0, c), 0.25f);
    }
  }
  EXPECT_TRUE(found);
}

TEST(ScanLayers, PtxAndMismatchedLayersAreRefused) {
  const Layers layers = MakeLayers();
  TempFolder folder;
  try {
    WriteScanWithLayer(folder.File("kept.ptx"), layers.front, layers.behind);
    FAIL() << "PTX accepted two layers";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("PTX cannot hold two returns per cell; write E57, PLY, PCD or LAS"));
  }
  EXPECT_FALSE(std::filesystem::exists(folder.File("kept.ptx")));
  try {
    WriteScanWithLayer(folder.File("kept.e57"), layers.front, MakeScan(3, 8));
    FAIL() << "layers of different sizes accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("kept.e57"));
    EXPECT_THAT(e.what(), HasSubstr("3 x 8"));
  }
  Scan moved = Clone(layers.behind);
  moved.world_from_scanner(0, 3) += 1.0;
  EXPECT_THROW(WriteScanWithLayer(folder.File("kept.pcd"), layers.front, moved), InputError);
  EXPECT_FALSE(std::filesystem::exists(folder.File("kept.pcd")));
}

// The lists a file dialog offers are the table's: every listed write format writes a scan that reads back,
// and an extension not listed is refused.
TEST(ScanFormats, EveryListedWriteFormatWritesAndReadsBack) {
  const std::vector<std::string> write = SupportedScanWriteExtensions();
  const std::vector<std::string> read = SupportedScanReadExtensions();
  for (const char* expected : {"ptx", "e57", "ply", "pcd"}) {
    EXPECT_THAT(write, ::testing::Contains(expected));
    EXPECT_THAT(read, ::testing::Contains(expected));
  }
  const Layers layers = MakeLayers();
  TempFolder folder;
  for (const std::string& extension : write) {
    const std::string path = folder.File("scan." + extension);
    WriteScanFile(path, {layers.front});
    EXPECT_EQ(ReadScanFile(path).scans.at(0).CountValid(), layers.front.CountValid()) << extension;
  }
  EXPECT_THAT(write, Not(::testing::Contains("laz")));  // read, not written
  EXPECT_THAT(read, ::testing::Contains("laz"));
  EXPECT_THAT(write, Not(::testing::Contains("asc")));
  EXPECT_THROW(WriteScanFile(folder.File("scan.asc"), {layers.front}), InputError);
  EXPECT_THROW(WriteScanFile(folder.File("scan.laz"), {layers.front}), InputError);
}

}  // namespace
}  // namespace lidarshop
