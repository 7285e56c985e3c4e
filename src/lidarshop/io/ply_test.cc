#include "lidarshop/io/ply.h"

#include <cmath>
#include <cstring>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "lidarshop/io/io_test_util.h"
#include "lidarshop/io/mesh_io.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/scan/ray_directions.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

using testing_io::TempFolder;

TriangleMesh TwoTriangles() {
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0.5f}};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  mesh.vertex_colors = {Rgb8(255, 0, 0), Rgb8(0, 255, 0), Rgb8(0, 0, 255), Rgb8(1, 2, 3)};
  mesh.vertex_normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0.6f, 0.8f}};
  mesh.triangle_colors = {Rgb8(10, 20, 30), Rgb8(40, 50, 60)};
  return mesh;
}

void ExpectSameMesh(const TriangleMesh& a, const TriangleMesh& b) {
  ASSERT_EQ(a.vertices.size(), b.vertices.size());
  ASSERT_EQ(a.triangles, b.triangles);
  for (size_t i = 0; i < a.vertices.size(); ++i) EXPECT_TRUE(a.vertices[i].isApprox(b.vertices[i]));
  EXPECT_EQ(a.vertex_colors, b.vertex_colors);
  EXPECT_EQ(a.triangle_colors, b.triangle_colors);
  ASSERT_EQ(a.vertex_normals.size(), b.vertex_normals.size());
  for (size_t i = 0; i < a.vertex_normals.size(); ++i)
    EXPECT_TRUE(a.vertex_normals[i].isApprox(b.vertex_normals[i]));
}

TEST(PlyTest, MeshRoundTripBinaryAndAscii) {
  TempFolder folder;
  const TriangleMesh mesh = TwoTriangles();
  WriteMesh(folder.File("binary.ply"), mesh);
  WriteMesh(folder.File("ascii.ply"), mesh, /*ascii=*/true);
  ExpectSameMesh(ReadMesh(folder.File("binary.ply")), mesh);
  ExpectSameMesh(ReadMesh(folder.File("ascii.ply")), mesh);
  EXPECT_THAT(testing_io::ReadText(folder.File("ascii.ply")), testing::HasSubstr("format ascii 1.0"));
}

TEST(PlyTest, TexturedMeshRoundTrip) {
  TempFolder folder;
  TriangleMesh mesh = TwoTriangles();
  mesh.texcoords = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  mesh.triangle_texcoords = {{0, 1, 2}, {0, 2, 3}};
  mesh.texture = cv::Mat(4, 8, CV_8UC3, cv::Scalar(200, 100, 50));
  WriteMesh(folder.File("textured.ply"), mesh);
  const TriangleMesh back = ReadMesh(folder.File("textured.ply"));
  ASSERT_EQ(back.triangle_texcoords.size(), 2u);
  EXPECT_TRUE(back.texcoords[back.triangle_texcoords[1][2]].isApprox(Eigen::Vector2f(0, 1)));
  ASSERT_FALSE(back.texture.empty());
  EXPECT_EQ(back.texture.at<cv::Vec3b>(0, 0), cv::Vec3b(200, 100, 50));  // RGB kept through the PNG
}

// A binary big-endian PLY with a quad, written by hand: the quad becomes two triangles.
TEST(PlyTest, ReadsBigEndianAndPolygons) {
  TempFolder folder;
  std::string bytes =
      "ply\nformat binary_big_endian 1.0\ncomment made by hand\nelement vertex 4\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\nproperty list uchar int "
      "vertex_indices\nend_header\n";
  auto put_float = [&](float value) {
    uint32_t bits;
    std::memcpy(&bits, &value, 4);
    for (int shift = 24; shift >= 0; shift -= 8) bytes += static_cast<char>((bits >> shift) & 0xff);
  };
  auto put_int = [&](int32_t value) {
    for (int shift = 24; shift >= 0; shift -= 8) bytes += static_cast<char>((value >> shift) & 0xff);
  };
  const float coords[4][3] = {{0, 0, 0}, {2, 0, 0}, {2, 3, 0}, {0, 3, 0}};
  for (const auto& v : coords) {
    for (float c : v) put_float(c);
  }
  bytes += static_cast<char>(4);
  for (int i = 0; i < 4; ++i) put_int(i);
  testing_io::WriteText(folder.File("big.ply"), bytes);
  const TriangleMesh mesh = ReadMesh(folder.File("big.ply"));
  ASSERT_EQ(mesh.num_triangles(), 2u);
  EXPECT_TRUE(mesh.vertices[2].isApprox(Eigen::Vector3f(2, 3, 0)));
  EXPECT_NEAR(SurfaceArea(mesh), 6.0, 1e-9);
}

TEST(PlyTest, PointCloudRoundTrip) {
  TempFolder folder;
  PointCloud cloud;
  cloud.points = {{1, 2, 3}, {-4, 5.5f, 6}};
  cloud.normals = {{0, 0, 1}, {1, 0, 0}};
  cloud.colors = {Rgb8(1, 2, 3), Rgb8(250, 251, 252)};
  cloud.intensities = {0.25f, 0.75f};
  cloud.labels = {7, -1};
  cloud.synthesized = {0, 1};
  for (bool ascii : {false, true}) {
    const std::string path = folder.File(ascii ? "a.ply" : "b.ply");
    WritePointCloud(path, cloud, ascii);
    const PointCloud back = ReadPointCloud(path);
    EXPECT_THAT(ReadPly(path).comments, ::testing::Contains("frame world"));
    EXPECT_EQ(back.points, cloud.points);
    EXPECT_EQ(back.normals, cloud.normals);
    EXPECT_EQ(back.colors, cloud.colors);
    EXPECT_EQ(back.intensities, cloud.intensities);
    EXPECT_EQ(back.labels, cloud.labels);
    EXPECT_EQ(back.synthesized, cloud.synthesized);
  }
}

Scan SmallScan(double azimuth_offset) {
  Scan scan = MakeScan(4, 5, /*with_color=*/true);
  scan.direction =
      DirectionsFromGrid(UniformGrid(4, 5, -0.2 + azimuth_offset, 0.2 + azimuth_offset, -0.1, 0.2));
  scan.label = cv::Mat(4, 5, CV_32S, cv::Scalar(kNoLabel));
  scan.synthesized = cv::Mat(4, 5, CV_8U, cv::Scalar(0));
  scan.curvature = cv::Mat(4, 5, CV_32F, cv::Scalar(NAN));
  for (int row = 0; row < 4; ++row) {
    for (int col = 0; col < 5; ++col) {
      if ((row + col) % 3 == 0) continue;  // no return
      const cv::Vec3f d = DirectionImage(scan).at<cv::Vec3f>(row, col);
      const float range = 2.0f + row + 0.5f * col;
      scan.valid.at<uint8_t>(row, col) = kValid;
      scan.point.at<cv::Vec3f>(row, col) = d * range;
      scan.range.at<float>(row, col) = range;
      scan.intensity.at<float>(row, col) = 0.1f * col;
      scan.color.at<cv::Vec3b>(row, col) = cv::Vec3b(row * 10, col * 10, 99);
      scan.label.at<int32_t>(row, col) = row;
      scan.synthesized.at<uint8_t>(row, col) = col == 2 ? 255 : 0;
      if (col != 4) scan.curvature.at<float>(row, col) = 0.01f * (row + col);  // NaN = unknown in column 4
    }
  }
  return scan;
}

TEST(PlyTest, ScansKeepTheirGridPoseAndChannels) {
  TempFolder folder;
  std::vector<Scan> scans = {SmallScan(0.0), SmallScan(0.5)};
  scans[1].world_from_scanner(0, 3) = 10.0;
  scans[1].world_from_scanner(2, 3) = -1.0;
  WriteScanFile(folder.File("scans.ply"), scans);
  EXPECT_THAT(ReadPly(folder.File("scans.ply")).comments, ::testing::Contains("frame world"));
  const ScanFile file = ReadScanFile(folder.File("scans.ply"));
  ASSERT_EQ(file.scans.size(), 2u);
  for (int k = 0; k < 2; ++k) {
    const Scan& back = file.scans[k];
    ASSERT_EQ(back.rows, 4);
    ASSERT_EQ(back.cols, 5);
    EXPECT_TRUE(back.world_from_scanner.isApprox(scans[k].world_from_scanner));
    EXPECT_EQ(cv::norm(back.valid, scans[k].valid, cv::NORM_INF), 0.0);
    EXPECT_LT(cv::norm(back.point, scans[k].point, cv::NORM_INF), 1e-5);
    EXPECT_EQ(cv::norm(back.color, scans[k].color, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(back.label, scans[k].label, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(back.synthesized, scans[k].synthesized, cv::NORM_INF), 0.0);
    EXPECT_LT(cv::norm(back.intensity, scans[k].intensity, cv::NORM_INF), 1e-7);
    // The curvature field: the values where known, NaN where unknown or without a return.
    ASSERT_EQ(back.curvature.type(), CV_32F);
    for (int row = 0; row < 4; ++row) {
      for (int col = 0; col < 5; ++col) {
        const float want =
            scans[k].valid.at<uint8_t>(row, col) ? scans[k].curvature.at<float>(row, col) : NAN;
        const float got = back.curvature.at<float>(row, col);
        if (std::isnan(want)) {
          EXPECT_TRUE(std::isnan(got)) << row << " " << col;
        } else {
          EXPECT_FLOAT_EQ(got, want);
        }
      }
    }
    // The fitted grid gives every cell, also the empty ones, its direction back.
    EXPECT_LT(cv::norm(DirectionImage(back), scans[k].direction, cv::NORM_INF), 1e-5);
  }
}

TEST(PlyTest, PlainCloudBecomesOneRowScan) {
  TempFolder folder;
  PointCloud cloud;
  cloud.points = {{1, 2, 3}, {4, 5, 6}, {7, 8, 9}};
  WritePointCloud(folder.File("plain.ply"), cloud);
  const ScanFile file = ReadScanFile(folder.File("plain.ply"));
  ASSERT_EQ(file.scans.size(), 1u);
  EXPECT_EQ(file.scans[0].rows, 1);
  EXPECT_EQ(file.scans[0].cols, 3);
  EXPECT_EQ(file.scans[0].CountValid(), 3);
}

// PDAL's and others' PLY test files: sized type names (int8, uint16, float64), unsized ones, extra
// properties, meshes, and a file without vertices. Expected values read from the text files.
TEST(PlyTest, ReadsTheInteropFiles) {
  const std::string dir = LIDARSHOP_SHARED_DATA_DIR "/interop/ply/";
  struct Case {
    const char* file;
    int points;
    Eigen::Vector3d first, last;
    bool z_missing;
  };
  const Case cases[] = {
      {"sized_dims.ply", 1, {1, 12346, 0}, {1, 12346, 0}, true},    // int8 x, uint16 y, no z
      {"unsized_dims.ply", 1, {1, 12346, 0}, {1, 12346, 0}, true},  // char x, ushort y, no z
      {"simple_text.ply", 3, {-1, 0, 0}, {1, 0, 0}, false},
      {"simple_binary.ply", 3, {-1, 0, 0}, {1, 0, 0}, false},
      {"text_extradim.ply", 1, {-2.64944, -13.0955, 0.00640115}, {-2.64944, -13.0955, 0.00640115}, false},
      {"mesh.ply", 4, {1, 1, 0}, {2, 2, 2}, false},
      {"mesh_fixed.ply", 4, {1, 1, 0}, {2, 2, 2}, false},
  };
  for (const Case& c : cases) {
    const ScanFile file = ReadScanFile(dir + c.file);
    ASSERT_EQ(file.scans.size(), 1u) << c.file;
    const Scan& scan = file.scans[0];
    EXPECT_EQ(scan.cols, c.points) << c.file;
    EXPECT_EQ(scan.CountValid(), c.points) << c.file;
    EXPECT_LT((WorldPointOfCell(scan, 0, 0) - c.first).cwiseAbs().maxCoeff(), 1e-6) << c.file;
    EXPECT_LT((WorldPointOfCell(scan, 0, c.points - 1) - c.last).cwiseAbs().maxCoeff(), 1e-6) << c.file;
    if (c.z_missing) {
      ASSERT_EQ(file.warnings.size(), 1u) << c.file;
      EXPECT_THAT(file.warnings[0], ::testing::AllOf(::testing::StartsWith(dir + c.file),
                                                     ::testing::HasSubstr("no z property")));
    } else {
      EXPECT_TRUE(file.warnings.empty()) << c.file;
    }
  }
  // text_extradim: char blue and the extra properties alpha and omg.
  const Scan extra = ReadScanFile(dir + "text_extradim.ply").scans[0];
  ASSERT_TRUE(extra.has_color());
  EXPECT_EQ(extra.color.at<cv::Vec3b>(0, 0), cv::Vec3b(63, 200, 64));
  ASSERT_FALSE(extra.normal.empty());
  EXPECT_NEAR(extra.normal.at<cv::Vec3f>(0, 0)[2], 0.999665f, 1e-6f);

  EXPECT_THAT(testing_io::ScanError(dir + "no_vertex.ply"),
              ::testing::AllOf(::testing::HasSubstr(dir + "no_vertex.ply"),
                               ::testing::HasSubstr("element vertex"), ::testing::HasSubstr("missing")));
  // issue_2421.ply holds z = 1234567890.12345 (1.2 million km): past kMaxCoordinateM, refused by name.
  EXPECT_THAT(testing_io::ScanError(dir + "issue_2421.ply"),
              ::testing::AllOf(::testing::HasSubstr("vertex 0"), ::testing::HasSubstr("field 'z'"),
                               ::testing::HasSubstr("1234567890.12345")));
}

// In a plain cloud the origin is a point; coordinates 5,000 km out keep 0.1 mm (doubles in the file, a local
// origin in the scan), also through a write of the scan.
TEST(PlyTest, PlainCloudsKeepTheOriginAndFarCoordinates) {
  const std::string head =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float64 x\nproperty float64 y\nproperty float64 z\n"
      "end_header\n";
  TempFolder folder;
  testing_io::WriteText(folder.File("near.ply"), head + "0 0 0\n1 2 3\n-1 0 0\n");
  const Scan near = ReadScanFile(folder.File("near.ply")).scans[0];
  EXPECT_EQ(near.CountValid(), 3);
  EXPECT_EQ(WorldPointOfCell(near, 0, 0), Eigen::Vector3d(0, 0, 0));
  EXPECT_GT(near.range.at<float>(0, 0), 0.0f);

  const Eigen::Vector3d far[] = {{5000000.1234, -5000000.5678, 1234.0001},
                                 {5000100.0001, -4999900.4321, 1299.9999},
                                 {5000050.5, -4999950.5, 1250}};
  std::string text = head;
  for (const Eigen::Vector3d& p : far) text += fmt::format("{:.4f} {:.4f} {:.4f}\n", p.x(), p.y(), p.z());
  testing_io::WriteText(folder.File("far.ply"), text);
  const Scan scan = ReadScanFile(folder.File("far.ply")).scans[0];
  WriteScanFile(folder.File("copy.ply"), {scan});
  const Scan back = ReadScanFile(folder.File("copy.ply")).scans[0];
  for (int i = 0; i < 3; ++i) {
    EXPECT_LT((WorldPointOfCell(scan, 0, i) - far[i]).cwiseAbs().maxCoeff(), 1e-5) << i;
    EXPECT_LT((WorldPointOfCell(back, 0, i) - far[i]).cwiseAbs().maxCoeff(), 1e-5) << i;
  }
}

}  // namespace
}  // namespace lidarshop
