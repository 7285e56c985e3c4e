#include "lidarshop/io/ply.h"

#include <cmath>
#include <cstring>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "lidarshop/io/io_test_util.h"
#include "lidarshop/io/mesh_io.h"
#include "lidarshop/io/scan_io.h"
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
      const cv::Vec3f d = scan.direction.at<cv::Vec3f>(row, col);
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
    EXPECT_LT(cv::norm(back.direction, scans[k].direction, cv::NORM_INF), 1e-5);
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

}  // namespace
}  // namespace lidarshop
