// Hostile input at the reader level: sizes come from the bytes, numbers and poses are checked,
// counts must agree with the data, and only regular files are read.
#include <sys/stat.h>

#include <chrono>
#include <cstring>
#include <future>

#include <opencv2/imgcodecs.hpp>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "lidarshop/io/e57.h"
#include "lidarshop/io/e57_format.h"
#include "lidarshop/io/io_test_util.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/memory_budget.h"

namespace lidarshop {
namespace {

using testing::AllOf;
using testing::HasSubstr;
using testing_io::ScanError;
using testing_io::TempFolder;
using testing_io::WriteText;

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

// 20 lidarshop_scan comments of 2048 x 2048 cells are each within the limit of one grid, and 2.4 GB together.
TEST(HostileInputTest, PlyScanCommentsAreBoundedTogether) {
  TempFolder folder;
  const std::string path = folder.File("scans.ply");
  std::string text = PlyScan(2048, 2048, 1, "0 5 0 3 5\n");
  std::string comments;
  for (int i = 1; i < 20; ++i)
    comments += fmt::format("comment lidarshop_scan {} 2048 2048 1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1\n", i);
  text.insert(text.find("element vertex"), comments);
  WriteText(path, text);
  EXPECT_THAT(ScanError(path), AllOf(HasSubstr("header: scans 0 to 1"), HasSubstr("lidarshop_scan grids")));
}

// Many one-point PTX scans: each costs far more than its 60 bytes (its channels, its grid).
TEST(HostileInputTest, PtxScansAreBoundedByTheBytes) {
  TempFolder folder;
  const std::string path = folder.File("scans.ptx");
  std::string text;
  for (int i = 0; i < 100; ++i)
    text += "1\n1\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n" + std::string(kIdentity) + "0 1 0 0.5\n";
  WriteText(path, text);
  EXPECT_THAT(ScanError(path), AllOf(HasSubstr(path), HasSubstr("more than 64 scans")));
  text.resize(text.size() / 2);
  WriteText(path, text);
  EXPECT_EQ(ReadScanFile(path).scans.size(), 50u);
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

// 172 bytes claiming 1.2 GB of LZF-compressed points: LZF expands a byte into at most 88.
TEST(HostileInputTest, PcdCompressedSizeMustFitTheCompressedBytes) {
  TempFolder folder;
  const std::string path = folder.File("cloud.pcd");
  const int64_t budget = MemoryBudgetBytes();
  SetMemoryBudgetBytes(int64_t{64} << 30);  // the budget would allow the scan: the bytes must not
  std::string text =
      "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 100000000\nHEIGHT 1\n"
      "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 100000000\nDATA binary_compressed\n";
  const uint32_t sizes[2] = {20, 1200000000};
  text.append(reinterpret_cast<const char*>(sizes), 8);
  text.append(20, '\0');
  WriteText(path, text);
  EXPECT_THAT(ScanError(path), HasSubstr("cannot come from 20 bytes of LZF data"));
  SetMemoryBudgetBytes(budget);
}

// An E57 file (pages and CRCs) of scans whose fields all take no bits (Integer minimum == maximum: a point
// at (1, 5, 0)), so that any recordCount fits in no bytes, and `photos` images2D entries all listing `png`.
std::vector<uint8_t> ZeroBitE57(const std::vector<std::pair<std::string, int64_t>>& scans,
                                const std::vector<uchar>& png = {}, int photos = 0) {
  using namespace e57;  // NOLINT: the format's helpers
  std::vector<uint8_t> logical(kHeaderSize);
  const auto align = [&] { logical.resize((logical.size() + 7) / 8 * 8); };
  const uint64_t blob_at = PhysicalFromLogical(logical.size());
  logical.resize(logical.size() + 8);  // sectionId 0 (blob), reserved
  AppendLe<uint64_t>(&logical, 16 + png.size());
  logical.insert(logical.end(), png.begin(), png.end());
  align();
  const uint64_t cv_at = logical.size();
  logical.push_back(1);  // sectionId 1 (compressed vector), reserved, length, data offset, index offset
  logical.resize(logical.size() + 7);
  AppendLe<uint64_t>(&logical, 32);
  AppendLe<uint64_t>(&logical, PhysicalFromLogical(cv_at + 32));
  AppendLe<uint64_t>(&logical, 0);
  std::string xml =
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<e57Root type=\"Structure\" "
      "xmlns=\"http://www.astm.org/COMMIT/E57/2010-e57-v1.0\"><guid type=\"String\">g</guid>"
      "<data3D type=\"Vector\">";
  for (const auto& [name, count] : scans) {
    xml += fmt::format(
        "<vectorChild type=\"Structure\"><name type=\"String\">{}</name><points type=\"CompressedVector\" "
        "fileOffset=\"{}\" recordCount=\"{}\"><prototype type=\"Structure\">"
        "<cartesianX type=\"Integer\" minimum=\"1\" maximum=\"1\"/><cartesianY type=\"Integer\" "
        "minimum=\"5\" "
        "maximum=\"5\"/><cartesianZ type=\"Integer\" minimum=\"0\" maximum=\"0\"/></prototype>"
        "<codecs type=\"Vector\"/></points></vectorChild>",
        name, PhysicalFromLogical(cv_at), count);
  }
  xml += "</data3D><images2D type=\"Vector\">";
  for (int i = 0; i < photos; ++i) {
    xml += fmt::format(
        "<vectorChild type=\"Structure\"><name type=\"String\">p{}</name><visualReferenceRepresentation "
        "type=\"Structure\"><pngImage type=\"Blob\" fileOffset=\"{}\" length=\"{}\"/>"
        "</visualReferenceRepresentation></vectorChild>",
        i, blob_at, png.size());
  }
  xml += "</images2D></e57Root>\n";
  const uint64_t xml_at = logical.size();
  logical.insert(logical.end(), xml.begin(), xml.end());
  Header header;
  header.file_physical_length = (logical.size() + kPagePayload - 1) / kPagePayload * kPageSize;
  header.xml_physical_offset = PhysicalFromLogical(xml_at);
  header.xml_logical_length = xml.size();
  StoreHeader(header, logical.data());
  return PagesFromLogical(logical);
}

std::string E57Error(const std::vector<uint8_t>& bytes) {
  return testing_io::InputErrorOf([&] { ReadE57Bytes(bytes, "zero_bits.e57"); });
}

// Fields that take no bits do not bound recordCount by the bytestreams: the records of all scans are bounded
// by the file's bytes (as grids are) and the budget.
TEST(HostileInputTest, E57RecordsOfNoBitsAreBoundedByTheBytes) {
  const E57File small = ReadE57Bytes(ZeroBitE57({{"a", 24}}), "small.e57");
  ASSERT_EQ(small.scans.size(), 1u);
  EXPECT_EQ(small.scans[0].CountValid(), 24);
  EXPECT_THAT(E57Error(ZeroBitE57({{"a", int64_t{1} << 24}})),
              AllOf(HasSubstr("zero_bits.e57"), HasSubstr("16777216 cells from")));
  // Eight scans, each within the limit: refused together, before any is read.
  EXPECT_THAT(E57Error(ZeroBitE57(std::vector<std::pair<std::string, int64_t>>(8, {"a", int64_t{1} << 22}))),
              AllOf(HasSubstr("33554432 cells from"), HasSubstr("records of all scans")));
}

// E57's XML is UTF-8: a Latin-1 scan name is refused naming the file and the byte.
TEST(HostileInputTest, E57NamesMustBeUtf8) {
  EXPECT_EQ(ReadE57Bytes(ZeroBitE57({{"caf\xc3\xa9", 24}}), "utf8.e57").scans[0].name, "caf\xc3\xa9");
  EXPECT_THAT(E57Error(ZeroBitE57({{"caf\xe9", 24}})),
              AllOf(HasSubstr("zero_bits.e57: XML section, byte"), HasSubstr("not UTF-8")));
}

// A photo blob listed many times is decoded once; one whose header claims more pixels than lidarshop decodes
// is kept undecoded with the reason, and the scans still read.
TEST(HostileInputTest, E57PhotosAreCheckedFromTheHeaderAndDecodedOnce) {
  std::vector<uchar> png;
  cv::imencode(".png", cv::Mat(200, 300, CV_8UC3, cv::Scalar(1, 2, 3)), png);
  const E57File file = ReadE57Bytes(ZeroBitE57({{"a", 24}}, png, 50), "photos.e57");
  ASSERT_EQ(file.images.size(), 50u);
  EXPECT_EQ(file.images[0].image.size(), cv::Size(300, 200));
  EXPECT_EQ(file.images[49].image.data, file.images[0].image.data);  // the same pixels, decoded once
  EXPECT_EQ(file.images[49].encoded, png);
  for (int i : {16, 20}) png[i] = 0, png[i + 1] = 0, png[i + 2] = 0x4e, png[i + 3] = 0x20;  // 20000 x 20000
  const E57File huge = ReadE57Bytes(ZeroBitE57({{"a", 24}}, png, 3), "huge.e57");
  ASSERT_EQ(huge.images.size(), 3u);
  EXPECT_TRUE(huge.images[2].image.empty());
  EXPECT_THAT(huge.images[2].decode_error, AllOf(HasSubstr("huge.e57"), HasSubstr("20000 x 20000 pixels")));
  EXPECT_EQ(huge.scans[0].CountValid(), 24);
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
