// Malformed input for every reader: each must throw InputError naming the file, the place (line, byte offset
// or header) and the field — never crash, never allocate what a header merely claims.
#include <random>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "lidarshop/io/image_io.h"
#include "lidarshop/io/io_test_util.h"
#include "lidarshop/io/mesh_io.h"
#include "lidarshop/io/pcd.h"
#include "lidarshop/io/ptx.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

using testing::AllOf;
using testing::HasSubstr;
using testing_io::ScanError;
using testing_io::TempFolder;
using testing_io::WriteText;

using testing_io::InputErrorOf;

std::string MeshError(const std::string& path) {
  return InputErrorOf([&] { ReadMesh(path); });
}

const char kPtxHeader[] = "2\n2\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n";
const char kPtxPoints[] = "0 1 0 0.5\n0 1 0.1 0.5\n0.1 1 0 0.5\n0.1 1 0.1 0.5\n";

std::string Garbage(size_t size, uint32_t seed) {
  std::mt19937 random(seed);
  std::string bytes(size, '\0');
  for (char& c : bytes) c = static_cast<char>(random() & 0xff);
  return bytes;
}

TEST(MalformedInputTest, Ptx) {
  TempFolder folder;
  const std::string path = folder.File("bad.ptx");
  auto error_for = [&](const std::string& text) {
    WriteText(path, text);
    return ScanError(path);
  };
  const std::string good = std::string(kPtxHeader) + kPtxPoints;
  WriteText(path, good);
  ASSERT_EQ(ReadScanFile(path).scans[0].CountValid(), 4);

  EXPECT_THAT(error_for(""), AllOf(HasSubstr(path), HasSubstr("line 1"), HasSubstr("empty")));
  EXPECT_THAT(error_for(good.substr(0, good.size() - std::string("0.1 1 0.1 0.5\n").size())),
              AllOf(HasSubstr(path), HasSubstr("line 14"), HasSubstr("truncated"), HasSubstr("found 3")));
  EXPECT_THAT(error_for(std::string(kPtxHeader).substr(0, 20)),
              AllOf(HasSubstr(path), HasSubstr("line 5"), HasSubstr("field 'scanner y axis (3rd value)'")));
  // One point line too many: the extra line is taken as the next scan's header.
  EXPECT_THAT(error_for(good + "0.2 1 0 0.5\n"),
              AllOf(HasSubstr(path), HasSubstr("line 15"), HasSubstr("field 'columns'"),
                    HasSubstr("more point lines")));
  EXPECT_THAT(error_for(std::string(kPtxHeader) + "0 1 0 0.5\n0 abc 0.1 0.5\n0.1 1 0 0.5\n0.1 1 0.1 0.5\n"),
              AllOf(HasSubstr(path), HasSubstr("line 12"), HasSubstr("field 'y'"), HasSubstr("'abc'")));
  EXPECT_THAT(
      error_for(std::string(kPtxHeader) + "0 1 0 0.5\n0 1 nan 0.5\n0.1 1 0 0.5\n0.1 1 0.1 0.5\n"),
      AllOf(HasSubstr(path), HasSubstr("line 12"), HasSubstr("field 'z'"), HasSubstr("not a finite")));
  EXPECT_THAT(error_for(std::string(kPtxHeader) + "0 1 0 0.5 1\n" + std::string(kPtxPoints).substr(10)),
              AllOf(HasSubstr(path), HasSubstr("line 11"), HasSubstr("field 'green'")));
  EXPECT_THAT(error_for(std::string(kPtxHeader) + "0 1 0 0.5 1 2 300\n" + std::string(kPtxPoints).substr(10)),
              AllOf(HasSubstr(path), HasSubstr("line 11"), HasSubstr("field 'colour'"), HasSubstr("0-255")));
  EXPECT_THAT(error_for(std::string(kPtxHeader) + "0 1 0 0.5\n"),
              AllOf(HasSubstr(path), HasSubstr("line 1"), HasSubstr("field 'size'"), HasSubstr("truncated")));
  EXPECT_THAT(error_for("2\n1.5\n"), AllOf(HasSubstr(path), HasSubstr("line 2"), HasSubstr("field 'rows'")));
  EXPECT_THAT(error_for("-2\n2\n"), AllOf(HasSubstr(path), HasSubstr("field 'size'")));
  // A header claiming 10^12 cells is refused before anything is allocated.
  EXPECT_THAT(error_for("1000000\n1000000\n0 0 0\n"),
              AllOf(HasSubstr(path), HasSubstr("line 1"), HasSubstr("field 'size'"), HasSubstr("more than")));
  EXPECT_THAT(error_for(Garbage(5000, 1)), HasSubstr(path));
  EXPECT_THAT(error_for(std::string(kPtxHeader, 30) + "x y z\n"),
              AllOf(HasSubstr(path), HasSubstr("line 7"), HasSubstr("field 'matrix row 1 (2nd value)'")));
}

TEST(MalformedInputTest, Ply) {
  TempFolder folder;
  const std::string path = folder.File("bad.ply");
  auto error_for = [&](const std::string& text) {
    WriteText(path, text);
    return MeshError(path);
  };
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  WriteText(path, header + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  ASSERT_EQ(ReadMesh(path).num_triangles(), 1u);

  EXPECT_THAT(error_for(""), AllOf(HasSubstr(path), HasSubstr("byte 0"), HasSubstr("empty")));
  EXPECT_THAT(
      error_for(header + "0 0 0\n1 0 0\n"),
      AllOf(HasSubstr(path), HasSubstr("header"), HasSubstr("field 'element face'"), HasSubstr("claims 1")));
  EXPECT_THAT(
      error_for(header + "0 0 0\n1 0 0\n0 1 0\n" + std::string(20, ' ')),
      AllOf(HasSubstr(path), HasSubstr("line 13"), HasSubstr("field 'face'"), HasSubstr("truncated")));
  EXPECT_THAT(error_for(header + "0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n"),
              AllOf(HasSubstr(path), HasSubstr("line 11"), HasSubstr("field 'y'"), HasSubstr("'zero'")));
  EXPECT_THAT(error_for(header + "0 0 0\n1 0 nan\n0 1 0\n3 0 1 2\n"),
              AllOf(HasSubstr(path), HasSubstr("line 11"), HasSubstr("field 'z'")));
  EXPECT_THAT(error_for(header + "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n"),
              AllOf(HasSubstr(path), HasSubstr("triangle 0"), HasSubstr("field 'vertex index'")));
  EXPECT_THAT(
      error_for("ply\nformat binary_little_endian 1.0\nelement vertex 4000000000000\nproperty float x\n"
                "property float y\nproperty float z\nend_header\n"),
      AllOf(HasSubstr(path), HasSubstr("header"), HasSubstr("element vertex"), HasSubstr("claims")));
  // Binary, truncated inside the face list.
  std::string binary =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const size_t data_start = binary.size();
  binary += std::string(36, '\0') + '\x03' + std::string(4, '\0');
  EXPECT_THAT(error_for(binary),
              AllOf(HasSubstr(path), HasSubstr(fmt::format("byte {}", data_start + 37)),
                    HasSubstr("field 'vertex_indices'"), HasSubstr("truncated in face 0")));
  EXPECT_THAT(error_for(Garbage(3000, 2)), AllOf(HasSubstr(path), HasSubstr("magic")));
  EXPECT_THAT(error_for("ply\nformat ascii 1.0\nelement vertex 1\n"),
              AllOf(HasSubstr(path), HasSubstr("end_header")));
}

TEST(MalformedInputTest, Obj) {
  TempFolder folder;
  const std::string path = folder.File("bad.obj");
  auto error_for = [&](const std::string& text) {
    WriteText(path, text);
    return MeshError(path);
  };
  EXPECT_THAT(error_for(""), AllOf(HasSubstr(path), HasSubstr("empty")));
  EXPECT_THAT(error_for("v 0 0 0\nv 1 x 0\n"),
              AllOf(HasSubstr(path), HasSubstr("line 2"), HasSubstr("field 'v y'")));
  EXPECT_THAT(error_for("v 0 0 0\nv 1 0 inf\n"),
              AllOf(HasSubstr(path), HasSubstr("line 2"), HasSubstr("field 'v z'")));
  EXPECT_THAT(error_for("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n"),
              AllOf(HasSubstr(path), HasSubstr("line 4"), HasSubstr("field 'f'"), HasSubstr("3 corners")));
  EXPECT_THAT(error_for("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n"),
              AllOf(HasSubstr(path), HasSubstr("line 4"), HasSubstr("field 'f vertex index'")));
  EXPECT_THAT(error_for("v 0 0 0\nv 1 0 0\nv 0 1 0\n"), AllOf(HasSubstr(path), HasSubstr("no triangles")));
  EXPECT_THAT(error_for(Garbage(3000, 3)), HasSubstr(path));
}

TEST(MalformedInputTest, Pcd) {
  TempFolder folder;
  const std::string path = folder.File("bad.pcd");
  auto error_for = [&](const std::string& text) {
    WriteText(path, text);
    return ScanError(path);
  };
  auto header = [](const std::string& size, const std::string& data) {
    return "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n" + size +
           "VIEWPOINT 0 0 0 1 0 0 0\n" + "DATA " + data + "\n";
  };
  EXPECT_THAT(error_for(""), AllOf(HasSubstr(path), HasSubstr("empty")));
  EXPECT_THAT(error_for(header("WIDTH 2\nHEIGHT 2\nPOINTS 4\n", "binary") + std::string(40, '\0')),
              AllOf(HasSubstr(path), HasSubstr("byte"), HasSubstr("field 'DATA'"), HasSubstr("truncated")));
  EXPECT_THAT(error_for(header("WIDTH 2\nHEIGHT 2\nPOINTS 5\n", "binary")),
              AllOf(HasSubstr(path), HasSubstr("header"), HasSubstr("field 'POINTS'")));
  EXPECT_THAT(error_for(header("WIDTH 100000\nHEIGHT 100000\nPOINTS 10000000000\n", "binary")),
              AllOf(HasSubstr(path), HasSubstr("header"), HasSubstr("more than")));
  EXPECT_THAT(error_for(header("WIDTH 2\nHEIGHT 1\nPOINTS 2\n", "ascii") + "1 2 3\n4 five 6\n"),
              AllOf(HasSubstr(path), HasSubstr("line 12"), HasSubstr("field 'y'"), HasSubstr("'five'")));
  EXPECT_THAT(error_for(header("WIDTH 2\nHEIGHT 1\nPOINTS 2\n", "ascii") + "1 2 3\n"),
              AllOf(HasSubstr(path), HasSubstr("truncated")));
  // binary_compressed with a corrupt LZF stream.
  std::string compressed = header("WIDTH 2\nHEIGHT 2\nPOINTS 4\n", "binary_compressed");
  const uint32_t sizes[2] = {20, 48};
  compressed.append(reinterpret_cast<const char*>(sizes), 8);
  compressed += Garbage(20, 4);
  EXPECT_THAT(error_for(compressed),
              AllOf(HasSubstr(path), HasSubstr("byte"), HasSubstr("field 'compressed")));
  EXPECT_THAT(error_for(Garbage(3000, 5)), HasSubstr(path));
}

TEST(MalformedInputTest, ImagesAndUnknownFormats) {
  TempFolder folder;
  WriteText(folder.File("bad.png"), Garbage(500, 6));
  EXPECT_THAT(InputErrorOf([&] { ReadImage(folder.File("bad.png")); }), HasSubstr(folder.File("bad.png")));
  EXPECT_THAT(InputErrorOf([&] { ReadImage(folder.File("missing.png")); }), HasSubstr("missing"));
  WriteText(folder.File("scan.asc"), "1 2 3\n");
  EXPECT_THAT(ScanError(folder.File("scan.asc")),
              AllOf(HasSubstr("scan.asc"), HasSubstr("unknown scan format"), HasSubstr(".las")));
  EXPECT_THAT(ScanError(folder.File("missing.ptx")),
              AllOf(HasSubstr("missing.ptx"), HasSubstr("cannot open")));
}

// Truncations and byte flips of valid files: every reader either succeeds or throws
// InputError, never anything else.
TEST(MalformedInputTest, TruncationsAndByteFlipsNeverCrash) {
  TempFolder folder;
  Scan scan = MakeScan(6, 5, /*with_color=*/true);
  scan.direction = DirectionsFromGrid(UniformGrid(6, 5, -0.2, 0.2, -0.1, 0.1));
  for (int row = 0; row < 6; ++row) {
    for (int col = 0; col < 5; ++col) {
      if ((row * 5 + col) % 7 == 3) continue;
      scan.valid.at<uint8_t>(row, col) = kValid;
      scan.point.at<cv::Vec3f>(row, col) = scan.direction.at<cv::Vec3f>(row, col) * (3.0f + row);
      scan.color.at<cv::Vec3b>(row, col) = cv::Vec3b(row, col, 7);
    }
  }
  std::vector<std::string> paths;
  for (const char* name : {"good.ptx", "good.ply", "good.pcd", "good.las", "good.xyz", "good.pts"}) {
    paths.push_back(folder.File(name));
    WriteScanFile(paths.back(), {scan});
  }
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  mesh.triangles = {{0, 1, 2}};
  paths.push_back(folder.File("mesh.ply"));
  WriteMesh(paths.back(), mesh, /*ascii=*/true);
  std::mt19937 random(11);
  int errors = 0, successes = 0;
  for (const std::string& path : paths) {
    const std::string bytes = testing_io::ReadText(path);
    const std::string extension = FileExtension(path);
    // In memory when the system has /dev/shm: writing 1200 files to a disk is slow.
    const std::string target = std::filesystem::is_directory("/dev/shm")
                                   ? fmt::format("/dev/shm/lidarshop_mutant_{}.{}", getpid(), extension)
                                   : folder.File("mutant." + extension);
    for (int trial = 0; trial < 300; ++trial) {
      std::string mutant = bytes;
      if (trial % 2 == 0) {
        mutant.resize(random() % bytes.size());
      } else {
        for (int flips = 0; flips < 3; ++flips)
          mutant[random() % mutant.size()] = static_cast<char>(random() & 0xff);
      }
      WriteText(target, mutant);
      try {
        if (path.find("mesh") != std::string::npos) {
          ReadMesh(target);
        } else {
          ReadScanFile(target);
        }
        ++successes;
      } catch (const InputError& error) {
        EXPECT_THAT(error.what(), HasSubstr(target));
        ++errors;
      }
    }
    std::filesystem::remove(target);
  }
  EXPECT_GT(errors, 100);
  EXPECT_GT(successes, 10);
}

}  // namespace
}  // namespace lidarshop
