#include "lidarshop/io/obj.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "lidarshop/io/image_io.h"
#include "lidarshop/io/io_test_util.h"
#include "lidarshop/io/mesh_io.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;
using testing_io::TempFolder;
using testing_io::WriteText;

TEST(ObjTest, MaterialsColoursAndTexture) {
  TempFolder folder;
  cv::Mat texture(2, 2, CV_8UC3);
  texture.at<cv::Vec3b>(0, 0) = cv::Vec3b(255, 0, 0);
  texture.at<cv::Vec3b>(0, 1) = cv::Vec3b(0, 255, 0);
  texture.at<cv::Vec3b>(1, 0) = cv::Vec3b(0, 0, 255);
  texture.at<cv::Vec3b>(1, 1) = cv::Vec3b(9, 9, 9);
  WriteImage(folder.File("wood.png"), texture);
  WriteText(folder.File("box.mtl"),
            "# materials\nnewmtl red\nKd 1 0 0\nnewmtl textured\nKd 0.5 0.5 0.5\nmap_Kd -s 1 1 1 wood.png\n");
  WriteText(folder.File("box.obj"),
            "mtllib box.mtl\n"
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\n"
            "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
            "vn 0 0 1\n"
            "usemtl red\nf 1 2 3\n"
            "usemtl textured\nf 1/1/1 3/3/1 4/4/1\n"
            "f -5/1 -4/2 -1/4\n");  // negative indices: vertices 1, 2, 5
  const TriangleMesh mesh = ReadMesh(folder.File("box.obj"));
  ASSERT_EQ(mesh.num_triangles(), 3u);
  EXPECT_EQ(mesh.triangles[2], Eigen::Vector3i(0, 1, 4));
  ASSERT_EQ(mesh.triangle_colors.size(), 3u);
  EXPECT_EQ(mesh.triangle_colors[0], Rgb8(255, 0, 0));
  EXPECT_EQ(mesh.triangle_colors[1], Rgb8(128, 128, 128));
  ASSERT_FALSE(mesh.texture.empty());
  EXPECT_EQ(mesh.texture.at<cv::Vec3b>(0, 0), cv::Vec3b(255, 0, 0));  // RGB, as written
  ASSERT_EQ(mesh.triangle_texcoords.size(), 3u);
  EXPECT_TRUE(mesh.texcoords[mesh.triangle_texcoords[1][1]].isApprox(Eigen::Vector2f(1, 1)));
  EXPECT_TRUE(mesh.texcoords[mesh.triangle_texcoords[2][2]].isApprox(Eigen::Vector2f(0, 1)));
  ASSERT_EQ(mesh.vertex_normals.size(), 5u);
  EXPECT_TRUE(mesh.vertex_normals[2].isApprox(Eigen::Vector3f(0, 0, 1)));
}

TEST(ObjTest, QuadsVertexColoursAndMissingMaterialFile) {
  TempFolder folder;
  WriteText(folder.File("quad.obj"),
            "mtllib missing.mtl\nv 0 0 0 1 0 0\nv 2 0 0 0 1 0\nv 2 2 0 0 0 1\nv 0 2 0 1 1 1\nusemtl nothing\n"
            "f 1 2 3 4\n");
  const TriangleMesh mesh = ReadMesh(folder.File("quad.obj"));
  ASSERT_EQ(mesh.num_triangles(), 2u);
  EXPECT_NEAR(SurfaceArea(mesh), 4.0, 1e-9);
  ASSERT_EQ(mesh.vertex_colors.size(), 4u);
  EXPECT_EQ(mesh.vertex_colors[1], Rgb8(0, 255, 0));
  EXPECT_TRUE(mesh.triangle_colors.empty());
}

TEST(ObjTest, MissingMaterialAndTextureFilesAreWarningsInTheResult) {
  // A missing MTL file, and an MTL whose texture is missing: the geometry is read, each left-out file is one
  // warning starting with the OBJ's path, and nothing is printed.
  TempFolder folder;
  WriteText(folder.File("quad.obj"), "mtllib missing.mtl\nv 0 0 0\nv 2 0 0\nv 2 2 0\nv 0 2 0\nf 1 2 3 4\n");
  WriteText(folder.File("textured.mtl"), "newmtl wood\nKd 0.5 0.5 0.5\nmap_Kd wood.png\n");
  WriteText(folder.File("textured.obj"),
            "mtllib textured.mtl\nv 0 0 0\nv 2 0 0\nv 2 2 0\nvt 0 0\nvt 1 0\nvt 1 1\n"
            "usemtl wood\nf 1/1 2/2 3/3\n");
  ::testing::internal::CaptureStdout();
  ::testing::internal::CaptureStderr();
  const MeshFile quad = ReadMeshFile(folder.File("quad.obj"));
  const MeshFile textured = ReadMeshFile(folder.File("textured.obj"));
  const std::string printed =
      ::testing::internal::GetCapturedStdout() + ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(printed, "");
  EXPECT_EQ(quad.mesh.num_triangles(), 2u);
  ASSERT_EQ(quad.warnings.size(), 1u);
  EXPECT_THAT(quad.warnings[0], StartsWith(folder.File("quad.obj") + ": "));
  EXPECT_THAT(quad.warnings[0], HasSubstr("missing.mtl"));
  EXPECT_THAT(quad.warnings[0], HasSubstr("the mesh is read without its materials"));
  EXPECT_EQ(textured.mesh.num_triangles(), 1u);
  EXPECT_TRUE(textured.mesh.texture.empty());
  ASSERT_EQ(textured.warnings.size(), 1u);
  EXPECT_THAT(textured.warnings[0], StartsWith(folder.File("textured.obj") + ": "));
  EXPECT_THAT(textured.warnings[0], HasSubstr("wood.png"));
  EXPECT_THAT(textured.warnings[0], HasSubstr("the mesh is read without this texture"));
  // ReadMesh gives the same mesh.
  EXPECT_EQ(ReadMesh(folder.File("quad.obj")).num_triangles(), 2u);
}

TEST(ObjTest, SharedMeshesHaveTheirTriangleCounts) {
  const std::string folder = LIDARSHOP_SHARED_DATA_DIR "/meshes/";
  const std::pair<const char*, size_t> expected[] = {{"beetle.obj", 2053},
                                                     {"stanford-bunny.obj", 69451},
                                                     {"spot.obj", 5856},
                                                     {"cow.obj", 5804},
                                                     {"teapot.obj", 6320}};
  for (const auto& [name, triangles] : expected) {
    const TriangleMesh mesh = ReadMesh(folder + name);
    EXPECT_EQ(mesh.num_triangles(), triangles) << name;
    EXPECT_GT(SurfaceArea(mesh), 0.0) << name;
  }
}

TEST(ObjTest, BadIndexNamesLineAndField) {
  EXPECT_THAT([] { ParseObj("v 0 0 0\nv 1 0 0\nf 1 2 3\n", "bad.obj", "."); },
              testing::ThrowsMessage<InputError>(testing::HasSubstr(
                  "bad.obj: line 3: field 'f vertex index': index 3 is outside the 2 defined")));
}

}  // namespace
}  // namespace lidarshop
