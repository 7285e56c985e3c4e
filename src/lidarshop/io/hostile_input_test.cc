// Hostile input at the reader level: sizes come from the bytes, numbers and poses are checked,
// counts must agree with the data, and only regular files are read.
#include <sys/stat.h>

#include <chrono>
#include <cstring>
#include <future>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "lidarshop/io/io_test_util.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

using testing::AllOf;
using testing::HasSubstr;
using testing_io::TempFolder;
using testing_io::WriteText;

std::string ScanError(const std::string& path) {
  return testing_io::InputErrorOf([&] { ReadScanFile(path); });
}

// A 2 x 2 PTX with the given printed matrix and first point.
std::string Ptx(const std::string& matrix, const std::string& first_point = "0 1 0") {
  return "2\n2\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n" + matrix + first_point +
         " 0.5\n0 1 0.1 0.5\n0.1 1 0 0.5\n0.1 1 0.1 0.5\n";
}
const char kIdentity[] = "1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n";

TEST(HostileInputTest, PtxPosesMustBeRotations) {
  TempFolder folder;
  const std::string path = folder.File("pose.ptx");
  WriteText(path, Ptx(kIdentity));
  ASSERT_EQ(ReadScanFile(path).scans[0].CountValid(), 4);
  const std::pair<const char*, const char*> cases[] = {
      {"0 0 0 0\n0 0 0 0\n0 0 0 0\n0 0 0 1\n", "singular"},
      {"1 0 0 0\n0.5 1 0 0\n0 0 1 0\n0 0 0 1\n", "sheared"},
      {"-1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n", "mirrored"},
      {"1e6 0 0 0\n0 1e6 0 0\n0 0 1e6 0\n0 0 0 1\n", "scaled by"},
      {"1 0 0 0\n0 1 0 0\n0 0 1 0\n1e308 0 0 1\n", "translation"},
  };
  for (const auto& [matrix, problem] : cases) {
    WriteText(path, Ptx(matrix));
    EXPECT_THAT(ScanError(path), AllOf(HasSubstr(path), HasSubstr("field 'pose'"), HasSubstr(problem)))
        << matrix;
  }
}

TEST(HostileInputTest, AbsurdCoordinatesAreNotData) {
  TempFolder folder;
  const std::string path = folder.File("far.ptx");
  for (const char* point : {"1e38 1 0", "0 -1e38 0", "0 1 3e7"}) {
    WriteText(path, Ptx(kIdentity, point));
    EXPECT_THAT(ScanError(path), AllOf(HasSubstr(path), HasSubstr("row 1 column 0"), HasSubstr("within")))
        << point;
  }
}

std::string PlyScan(int64_t rows, int64_t cols, int count, const std::string& body) {
  return "ply\nformat ascii 1.0\ncomment lidarshop_scan 0 " + std::to_string(rows) + " " +
         std::to_string(cols) + " 1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1\nelement vertex " + std::to_string(count) +
         "\nproperty float x\nproperty float y\nproperty float z\nproperty int row\nproperty int "
         "col\nend_header\n" +
         body;
}

TEST(HostileInputTest, PlyCountsAndCellsMustAgreeWithTheData) {
  TempFolder folder;
  const std::string path = folder.File("scan.ply");
  const std::string body = "0 5 0 0 0\n0.1 5 0 0 1\n0 5 0.1 1 0\n";
  WriteText(path, PlyScan(2, 2, 3, body));
  ASSERT_EQ(ReadScanFile(path).scans[0].CountValid(), 3);
  WriteText(path, PlyScan(2, 2, 3, "0 5 0 0 0\n0.1 5 0 0 1\n0 5 0.1 0 1\n"));
  EXPECT_THAT(ScanError(path), AllOf(HasSubstr("vertex 2"), HasSubstr("two points in one cell")));
  WriteText(path, PlyScan(2, 2, 2, body));
  EXPECT_THAT(ScanError(path), HasSubstr("more data follows"));
  WriteText(path, PlyScan(2, 2, 0, body));
  EXPECT_THAT(ScanError(path), HasSubstr(path));
  // A 300-byte file cannot make the reader allocate a 2^24-cell grid (1 GB of channels).
  WriteText(path, PlyScan(int64_t{1} << 12, int64_t{1} << 12, 3, body));
  EXPECT_THAT(ScanError(path), AllOf(HasSubstr("header: scan 0"), HasSubstr("cells per byte")));
}

TEST(HostileInputTest, PcdCountsMustAgreeWithTheData) {
  TempFolder folder;
  const std::string path = folder.File("cloud.pcd");
  auto pcd = [](int64_t width, int64_t height, const std::string& body) {
    return "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH " + std::to_string(width) +
           "\nHEIGHT " + std::to_string(height) + "\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " +
           std::to_string(width * height) + "\nDATA ascii\n" + body;
  };
  WriteText(path, pcd(2, 1, "0 0 5\n1 0 5\n"));
  ASSERT_EQ(ReadScanFile(path).scans[0].CountValid(), 2);
  WriteText(path, pcd(2, 1, "0 0 5\n1 0 5\n2 0 5\n"));
  EXPECT_THAT(ScanError(path), HasSubstr("more point lines"));
  // 16 GB of claimed ASCII points in a few bytes: refused before allocating.
  WriteText(path, pcd(65536, 16384, "0 0 5\n"));
  EXPECT_THAT(ScanError(path), HasSubstr(path));
  WriteText(path, pcd(1 << 20, 1, "0 0 5\n"));
  EXPECT_THAT(ScanError(path), HasSubstr("truncated"));
}

TEST(HostileInputTest, LasCountsMustAgreeWithTheData) {
  TempFolder folder;
  const std::string path = folder.File("cloud.las");
  // A LAS 1.4 header (375 bytes), point format 6 (30-byte records), two points, scale 1 mm.
  auto las = [](uint64_t claimed, uint32_t offset_to_points, uint16_t record_length) {
    std::string bytes(375, '\0');
    auto put = [&bytes](size_t at, auto value) { std::memcpy(bytes.data() + at, &value, sizeof(value)); };
    std::memcpy(bytes.data(), "LASF", 4);
    bytes[24] = 1;
    bytes[25] = 4;
    put(94, uint16_t{375});
    put(96, offset_to_points);
    bytes[104] = 6;
    put(105, record_length);
    for (int axis = 0; axis < 3; ++axis) put(131 + 8 * axis, 0.001);
    put(247, claimed);
    for (int i = 0; i < 2; ++i) {
      std::string record(record_length, '\0');
      const int32_t xyz[3] = {100 * i, 5000, 0};
      std::memcpy(record.data(), xyz, sizeof(xyz));
      bytes += record;
    }
    return bytes;
  };
  WriteText(path, las(2, 375, 30));
  ASSERT_EQ(ReadScanFile(path).scans[0].CountValid(), 2);
  // 2^40 points of 30 bytes claimed by a 435-byte file: refused before anything is allocated.
  WriteText(path, las(uint64_t{1} << 40, 375, 30));
  EXPECT_THAT(ScanError(path),
              AllOf(HasSubstr(path), HasSubstr("Number of Point Records"), HasSubstr("truncated")));
  WriteText(path, las(2, 1u << 30, 30));
  EXPECT_THAT(ScanError(path), AllOf(HasSubstr("Offset to Point Data"), HasSubstr("1073741824")));
  WriteText(path, las(2, 375, 12));
  EXPECT_THAT(ScanError(path), AllOf(HasSubstr("Point Data Record Length"), HasSubstr("too short")));
}

TEST(HostileInputTest, OnlyRegularFilesAreRead) {
  TempFolder folder;
  const std::string fifo = folder.File("x.ptx");
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  auto message = std::async(std::launch::async, [&] { return ScanError(fifo); });
  ASSERT_EQ(message.wait_for(std::chrono::seconds(10)), std::future_status::ready)
      << "a FIFO blocked the reader";
  EXPECT_THAT(message.get(), HasSubstr("named pipe"));
  const std::string e57 = folder.File("y.e57");
  ASSERT_EQ(mkfifo(e57.c_str(), 0600), 0);
  auto e57_message = std::async(std::launch::async, [&] { return ScanError(e57); });
  ASSERT_EQ(e57_message.wait_for(std::chrono::seconds(10)), std::future_status::ready);
  EXPECT_THAT(e57_message.get(), HasSubstr("named pipe"));
  const std::string folder_ptx = folder.File("scan.ptx");
  std::filesystem::create_directories(folder_ptx);
  EXPECT_THAT(ScanError(folder_ptx), HasSubstr("is a folder"));  // was std::bad_alloc
}

}  // namespace
}  // namespace lidarshop
