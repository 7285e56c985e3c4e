// LAS reading: every point format read from files built here byte by byte from the specification's tables
// (independent of las_format.h and of the writer), and the header checks of hostile and LAZ files.
#include "lidarshop/io/las.h"

#include <cstring>
#include <filesystem>

#include <fmt/format.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "lidarshop/io/io_test_util.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/io/scan_write_plan.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

using testing::AllOf;
using testing::HasSubstr;
using testing_io::InputErrorOf;
using testing_io::TempFolder;

// ---- A LAS file built by hand (ASPRS LAS 1.4 R15, tables 3 and 7-16), independent of las_format.h ----

struct HandPoint {
  int32_t x = 0, y = 0, z = 0;  // in scale steps
  uint16_t intensity = 0;
  uint8_t classification = 0;
  bool synthetic = false;
  uint16_t rgb[3] = {0, 0, 0};
};

struct HandLas {
  int minor = 4;
  int format = 6;
  int extra_bytes = 0;  // after each record
  double scale = 0.001;
  double offset[3] = {100, 200, 0};
  std::vector<HandPoint> points;
  std::string vlr;  // one variable length record's payload, or none
  std::string vlr_user = "lidarshop_test";
  uint16_t vlr_id = 7;
};

template <typename T>
void Put(std::string* bytes, size_t at, T value) {
  if (bytes->size() < at + sizeof(T)) bytes->resize(at + sizeof(T), '\0');
  std::memcpy(bytes->data() + at, &value, sizeof(T));
}

std::string Build(const HandLas& las) {
  const int base[] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
  const int record = base[las.format] + las.extra_bytes;
  const int header = las.minor >= 4 ? 375 : las.minor == 3 ? 235 : 227;
  const int vlr_bytes = las.vlr.empty() ? 0 : 54 + static_cast<int>(las.vlr.size());
  std::string b(header, '\0');
  std::memcpy(b.data(), "LASF", 4);
  b[24] = 1;
  b[25] = static_cast<char>(las.minor);
  Put<uint16_t>(&b, 94, header);
  Put<uint32_t>(&b, 96, header + vlr_bytes);
  Put<uint32_t>(&b, 100, las.vlr.empty() ? 0 : 1);
  b[104] = static_cast<char>(las.format);
  Put<uint16_t>(&b, 105, record);
  if (las.format < 6) Put<uint32_t>(&b, 107, las.points.size());
  for (int axis = 0; axis < 3; ++axis) {
    Put<double>(&b, 131 + 8 * axis, las.scale);
    Put<double>(&b, 155 + 8 * axis, las.offset[axis]);
  }
  if (las.minor >= 4) Put<uint64_t>(&b, 247, las.points.size());
  if (!las.vlr.empty()) {
    std::string v(54, '\0');
    std::memcpy(v.data() + 2, las.vlr_user.data(), std::min<size_t>(16, las.vlr_user.size()));
    Put<uint16_t>(&v, 18, las.vlr_id);
    Put<uint16_t>(&v, 20, las.vlr.size());  // record length after header (table 15)
    b += v + las.vlr;
  }
  const bool legacy = las.format <= 5;
  const int rgb_at = las.format == 2 ? 20 : (las.format == 3 || las.format == 5) ? 28 : 30;
  const bool has_rgb = las.format == 2 || las.format == 3 || las.format == 5 || las.format == 7 ||
                       las.format == 8 || las.format == 10;
  for (const HandPoint& p : las.points) {
    const size_t at = b.size();
    b.resize(at + record, '\0');
    Put<int32_t>(&b, at, p.x);
    Put<int32_t>(&b, at + 4, p.y);
    Put<int32_t>(&b, at + 8, p.z);
    Put<uint16_t>(&b, at + 12, p.intensity);
    if (legacy) {
      b[at + 14] = 1 | (1 << 3);
      b[at + 15] = static_cast<char>((p.classification & 31) | (p.synthetic ? 32 : 0));
      if (las.format == 1 || las.format == 3) Put<double>(&b, at + 20, 12345.5);  // GPS time
    } else {
      b[at + 14] = 1 | (1 << 4);
      b[at + 15] = p.synthetic ? 1 : 0;
      b[at + 16] = static_cast<char>(p.classification);
      Put<double>(&b, at + 22, 12345.5);
    }
    if (has_rgb) {
      for (int c = 0; c < 3; ++c) Put<uint16_t>(&b, at + rgb_at + 2 * c, p.rgb[c]);
    }
    for (int i = 0; i < las.extra_bytes; ++i) b[at + base[las.format] + i] = '\x7f';
  }
  return b;
}

// Three points: (100.001, 200.002, 0.003), (101, 199, -1.5), (100, 200.5, 2) with scale 1 mm.
HandLas ThreePoints(int minor, int format) {
  HandLas las;
  las.minor = minor;
  las.format = format;
  HandPoint a{1, 2, 3, 65535, 2, false, {65535, 0, 32896}};
  HandPoint b{1000, -1000, -1500, 0, 6, true, {257, 514, 771}};
  HandPoint c{0, 500, 2000, 32768, 0, false, {0, 65535, 0}};
  las.points = {a, b, c};
  return las;
}

Scan ReadBytes(const TempFolder& folder, const std::string& bytes, const std::string& name = "hand.las") {
  const std::string path = folder.File(name);
  testing_io::WriteText(path, bytes);
  return ReadScanFile(path).scans.at(0);
}

TEST(LasTest, EveryPointFormatReads) {
  TempFolder folder;
  const std::pair<int, int> versions_formats[] = {{0, 0}, {1, 1}, {2, 2}, {2, 3}, {3, 4}, {3, 5}, {4, 0},
                                                  {4, 3}, {4, 6}, {4, 7}, {4, 8}, {4, 9}, {4, 10}};
  for (const auto& [minor, format] : versions_formats) {
    SCOPED_TRACE(fmt::format("LAS 1.{} format {}", minor, format));
    const Scan scan = ReadBytes(folder, Build(ThreePoints(minor, format)));
    ASSERT_EQ(scan.rows, 1);
    ASSERT_EQ(scan.cols, 3);
    EXPECT_EQ(scan.CountValid(), 3);
    EXPECT_TRUE(scan.world_from_scanner.isIdentity());  // within 1 km: no origin shift
    EXPECT_LT((WorldPointOfCell(scan, 0, 0) - Eigen::Vector3d(100.001, 200.002, 0.003)).norm(), 1e-5);
    EXPECT_LT((WorldPointOfCell(scan, 0, 1) - Eigen::Vector3d(101, 199, -1.5)).norm(), 1e-5);
    EXPECT_LT((WorldPointOfCell(scan, 0, 2) - Eigen::Vector3d(100, 200.5, 2)).norm(), 1e-5);
    EXPECT_FLOAT_EQ(scan.intensity.at<float>(0, 0), 1.0f);
    EXPECT_FLOAT_EQ(scan.intensity.at<float>(0, 1), 0.0f);
    EXPECT_NEAR(scan.intensity.at<float>(0, 2), 0.5f, 1e-4);
    ASSERT_FALSE(scan.label.empty());
    EXPECT_EQ(scan.label.at<int32_t>(0, 0), 2);
    EXPECT_EQ(scan.label.at<int32_t>(0, 1), 6);
    EXPECT_EQ(scan.label.at<int32_t>(0, 2), 0);
    ASSERT_FALSE(scan.synthesized.empty());
    EXPECT_EQ(scan.synthesized.at<uint8_t>(0, 0), 0);
    EXPECT_EQ(scan.synthesized.at<uint8_t>(0, 1), kValid);
    const bool rgb = format == 2 || format == 3 || format == 5 || format == 7 || format == 8 || format == 10;
    ASSERT_EQ(scan.has_color(), rgb);
    if (rgb) {
      EXPECT_EQ(scan.color.at<cv::Vec3b>(0, 0), cv::Vec3b(255, 0, 128));  // 16-bit / 257
      EXPECT_EQ(scan.color.at<cv::Vec3b>(0, 1), cv::Vec3b(1, 2, 3));
      EXPECT_EQ(scan.color.at<cv::Vec3b>(0, 2), cv::Vec3b(0, 255, 0));
    }
  }
}

TEST(LasTest, ExtraBytesAreKeptAndForeignRecordsLeftOutWithAWarning) {
  TempFolder folder;
  HandLas las = ThreePoints(4, 7);
  las.extra_bytes = 5;
  las.vlr = std::string(40, 'v');
  const std::string path = folder.File("extra.las");
  testing_io::WriteText(path, Build(las));
  const ScanFile file = ReadScanFile(path);
  const Scan& scan = file.scans.at(0);
  ASSERT_EQ(scan.CountValid(), 3);
  EXPECT_LT((WorldPointOfCell(scan, 0, 2) - Eigen::Vector3d(100, 200.5, 2)).norm(), 1e-5);
  EXPECT_EQ(scan.color.at<cv::Vec3b>(0, 1), cv::Vec3b(1, 2, 3));
  ASSERT_EQ(scan.attributes.count(kLasExtraBytes), 1u);
  EXPECT_EQ(scan.attributes.at(kLasExtraBytes).channels(), 5);
  EXPECT_EQ(scan.attributes.at(kLasExtraBytes).at<uint8_t>(0, 7), 0x7f);
  EXPECT_TRUE(scan.source_records.empty());  // a vendor's record describes the file it came with
  ASSERT_EQ(file.warnings.size(), 1u);
  EXPECT_THAT(file.warnings[0], AllOf(HasSubstr(path), HasSubstr("lidarshop_test 7"), HasSubstr("not kept")));
}

// The coordinate system's records, every attribute and the 16-bit colour come back from LAS -> LAS; with the
// source's scale, offset and format, every point record is the same bytes.
TEST(LasTest, LasToLasKeepsEveryPointRecordAndTheCoordinateSystem) {
  TempFolder folder;
  for (const auto& [minor, format] : {std::pair{2, 3}, std::pair{2, 1}, std::pair{4, 8}, std::pair{4, 6}}) {
    SCOPED_TRACE(fmt::format("LAS 1.{} format {}", minor, format));
    HandLas las = ThreePoints(minor, format);
    las.vlr_user = "LASF_Projection";
    las.vlr_id = 34735;
    las.vlr =
        std::string("\x01\x00\x01\x00\x00\x00\x01\x00\x00\x0c\x00\x00\x01\x00\x6b\x68", 16);  // EPSG:26731
    std::string bytes = Build(las);
    // Attributes the hand builder leaves at their defaults: scan angle, user data, point source ID, NIR.
    const size_t header = minor >= 4 ? 375 : 227;
    const size_t first = header + 54 + las.vlr.size();
    const size_t length = (bytes.size() - first) / las.points.size();
    for (size_t i = 0; i < las.points.size(); ++i) {
      char* p = bytes.data() + first + i * length;
      if (format <= 5) {
        p[16] = static_cast<char>(-12 + static_cast<int>(i));  // scan angle rank
        p[17] = 42;                                            // user data
        Put<uint16_t>(&bytes, first + i * length + 18, static_cast<uint16_t>(7 + i));
      } else {
        p[15] = static_cast<char>(p[15] | (1 << 3) | (2 << 4));  // overlap, scanner channel 2
        Put<int16_t>(&bytes, first + i * length + 18, static_cast<int16_t>(-2000 + 7 * i));
        Put<uint16_t>(&bytes, first + i * length + 20, static_cast<uint16_t>(7 + i));
        if (format == 8) Put<uint16_t>(&bytes, first + i * length + 36, static_cast<uint16_t>(1000 * i));
      }
    }
    const Scan scan = ReadBytes(folder, bytes);
    ASSERT_EQ(scan.source_records.size(), 1u);
    EXPECT_EQ(scan.source_records[0].payload, las.vlr);
    EXPECT_EQ(LasCrsJson(scan.source_records)["geotiff"]["projected_epsg"], 26731);
    const std::string written = EncodeLas({scan}, {.minor_version = minor}, "out.las");
    ASSERT_EQ(written[104], static_cast<char>(format));
    ASSERT_EQ(written.size(), bytes.size());
    EXPECT_EQ(written.substr(first), bytes.substr(first));  // every point record, byte for byte
    EXPECT_EQ(written.substr(header, 54 + las.vlr.size()).substr(54), las.vlr);
    EXPECT_EQ(written.substr(header + 2, 15), "LASF_Projection");
  }
}

// A point format that cannot hold an attribute: the write plan (what `convert` warns) names it.
TEST(LasTest, AFormatThatCannotHoldAnAttributeSaysSo) {
  TempFolder folder;
  HandLas las = ThreePoints(4, 8);
  std::string bytes = Build(las);
  for (size_t i = 0; i < las.points.size(); ++i)
    Put<uint16_t>(&bytes, 375 + i * 38 + 36, uint16_t{500});  // NIR
  const Scan scan = ReadBytes(folder, bytes);
  ASSERT_EQ(scan.attributes.count(kLasNir), 1u);
  const std::string out = folder.File("out.las");
  EXPECT_THAT(PlanScanWrite(out, {scan}, 0, 0).dropped, testing::Not(testing::Contains(HasSubstr("nir"))));
  const LasWriteOptions format1{.minor_version = 2, .point_format = 1};
  EXPECT_THAT(PlanScanWrite(out, {scan}, 0, 0, &format1).dropped,
              testing::Contains(AllOf(HasSubstr(out), HasSubstr("point format 1 does not hold nir"),
                                      testing::Not(HasSubstr("4's formats")))));
  const LasWriteOptions format3{.minor_version = 2, .point_format = 3};
  EXPECT_THAT(PlanScanWrite(out, {scan}, 0, 0, &format3).dropped,
              testing::Contains(AllOf(HasSubstr("nir"), testing::Not(HasSubstr("gps_time")))));
}

// LAS 1.4 keeps its coordinate system in extended records after the points: read; one that runs past the
// file's end is left out with a warning naming the file.
TEST(LasTest, ExtendedRecordsAfterThePointsAreRead) {
  TempFolder folder;
  std::string bytes = Build(ThreePoints(4, 6));
  const std::string wkt = "PROJCS[\"test\"]";
  std::string evlr(60, '\0');
  std::memcpy(evlr.data() + 2, "LASF_Projection", 15);
  Put<uint16_t>(&evlr, 18, 2112);
  Put<uint64_t>(&evlr, 20, wkt.size());
  Put<uint64_t>(&bytes, 235, bytes.size());  // start of the first extended record
  Put<uint32_t>(&bytes, 243, 1);
  const std::string path = folder.File("evlr.las");
  testing_io::WriteText(path, bytes + evlr + wkt);
  const ScanFile file = ReadScanFile(path);
  ASSERT_EQ(file.scans.at(0).source_records.size(), 1u);
  EXPECT_EQ(file.scans[0].source_records[0].payload, wkt);
  EXPECT_EQ(LasCrsJson(file.scans[0].source_records)["wkt"], wkt);
  EXPECT_TRUE(file.warnings.empty());
  testing_io::WriteText(path, bytes + evlr + wkt.substr(0, 5));
  const ScanFile cut = ReadScanFile(path);
  EXPECT_TRUE(cut.scans.at(0).source_records.empty());
  EXPECT_THAT(cut.warnings,
              testing::Contains(AllOf(HasSubstr(path), HasSubstr("extended variable length record 0"),
                                      HasSubstr("does not fit"))));
  // The first extended record said to start past the file's end: left out with a warning, nothing read.
  std::string past_end = bytes + evlr + wkt;
  Put<uint64_t>(&past_end, 235, past_end.size() + 100);
  testing_io::WriteText(path, past_end);
  const ScanFile beyond = ReadScanFile(path);
  EXPECT_TRUE(beyond.scans.at(0).source_records.empty());
  EXPECT_THAT(beyond.warnings, testing::Contains(AllOf(HasSubstr("extended variable length record 0"),
                                                       HasSubstr("does not fit"))));
  // A record header that would start 1 to 59 bytes before the end (the las fuzzer's find: an unsigned
  // size - position - 60 wrapped around and let a length of 2^64 - 1 through) is left out too.
  for (const int short_by : {1, 30, 59}) {
    std::string tail = bytes + std::string(60 - short_by, 'x');
    Put<uint64_t>(&tail, 235, bytes.size());
    testing_io::WriteText(path, tail);
    const ScanFile past = ReadScanFile(path);
    EXPECT_TRUE(past.scans.at(0).source_records.empty()) << short_by;
    EXPECT_THAT(past.warnings, testing::Contains(HasSubstr("does not fit"))) << short_by;
  }
}

// A file read from disk is parsed a chunk of 65,536 records at a time (ReadLas), not held whole: the same scan
// as parsing the whole file's bytes, over three chunks, with every attribute.
TEST(LasTest, ReadingAChunkAtATimeEqualsParsingTheWholeFile) {
  TempFolder folder;
  const int n = 150'001;
  Scan scan = MakeScan(1, n, /*with_color=*/true);
  for (int i = 0; i < n; ++i) {
    const cv::Vec3f p(0.001f * static_cast<float>(i % 1000), 0.01f * static_cast<float>(i / 1000),
                      1.0f + 0.5f * static_cast<float>(i % 7));
    scan.valid.at<uint8_t>(0, i) = kValid;
    scan.point.at<cv::Vec3f>(0, i) = p;
    scan.range.at<float>(0, i) = static_cast<float>(cv::norm(p));
    scan.intensity.at<float>(0, i) = static_cast<float>(i % 251) / 250.0f;
    scan.color.at<cv::Vec3b>(0, i) = cv::Vec3b(i % 256, (i / 256) % 256, 7);
  }
  const std::string path = folder.File("chunks.las");
  WriteScanFile(path, {scan});
  std::vector<std::string> streamed_warnings, whole_warnings;
  const Scan streamed = ReadLas(path, &streamed_warnings);
  const Scan whole = ParseLas(testing_io::ReadText(path), path, &whole_warnings);
  EXPECT_EQ(streamed_warnings, whole_warnings);
  ASSERT_EQ(streamed.cols, n);
  EXPECT_EQ(cv::norm(streamed.point, whole.point, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(streamed.intensity, whole.intensity, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(streamed.color, whole.color, cv::NORM_INF), 0.0);
  EXPECT_EQ(streamed.world_from_scanner, whole.world_from_scanner);
  EXPECT_EQ(streamed.source_metadata, whole.source_metadata);
  ASSERT_EQ(streamed.attributes.size(), whole.attributes.size());
  for (const auto& [name, values] : whole.attributes)
    EXPECT_EQ(cv::norm(streamed.attributes.at(name), values, cv::NORM_INF), 0.0) << name;
  // The last chunk's last point, spelled out: the points are where they were written (to the file's step).
  EXPECT_LT(cv::norm(streamed.point.at<cv::Vec3f>(0, n - 1) +
                     cv::Vec3f(streamed.world_from_scanner(0, 3), streamed.world_from_scanner(1, 3),
                               streamed.world_from_scanner(2, 3)) -
                     scan.point.at<cv::Vec3f>(0, n - 1)),
            1e-3);
}

TEST(LasTest, APointAtTheOriginIsAPoint) {
  TempFolder folder;
  HandLas las = ThreePoints(2, 0);
  las.offset[0] = las.offset[1] = las.offset[2] = 0;
  las.points[1].x = las.points[1].y = las.points[1].z = 0;
  const Scan scan = ReadBytes(folder, Build(las));
  EXPECT_EQ(scan.CountValid(), 3);
  EXPECT_EQ(scan.point.at<cv::Vec3f>(0, 1), cv::Vec3f(0, 0, 0));
  EXPECT_EQ(scan.range.at<float>(0, 1), 0.0f);
  EXPECT_EQ(EncodeLas({scan}, {.minor_version = 2}, "o.las").size(), Build(las).size());
}

TEST(LasTest, DegreesKeepTheirStep) {
  // A geographic cloud: 1e-7 degree steps near (-90.5, 30.25); a float at 90 keeps only 8e-6.
  TempFolder folder;
  HandLas las = ThreePoints(2, 0);
  las.scale = 1e-7;
  las.offset[0] = -90.5;
  las.offset[1] = 30.25;
  las.offset[2] = 0;
  for (HandPoint& p : las.points) p.x += 123457, p.y -= 98761;
  const std::string bytes = Build(las);
  const Scan scan = ReadBytes(folder, bytes);
  const std::string written = EncodeLas({scan}, {.minor_version = 2}, "o.las");
  EXPECT_EQ(written.substr(227), bytes.substr(227));
}

TEST(LasTest, ChannelsTheFileDoesNotHoldAreAbsent) {
  TempFolder folder;
  HandLas las = ThreePoints(4, 7);
  for (HandPoint& p : las.points) p = HandPoint{p.x, p.y, p.z, 0, 0, false, {p.rgb[0], 0, 0}};
  // Colour written as 8-bit values in the 16-bit fields: taken as they are.
  las.points[0].rgb[0] = 200;
  las.points[1].rgb[0] = 7;
  const Scan scan = ReadBytes(folder, Build(las));
  EXPECT_TRUE(scan.label.empty());
  EXPECT_TRUE(scan.synthesized.empty());
  EXPECT_FALSE(scan.has_intensity());  // all intensities 0 = not recorded: no channel
  EXPECT_EQ(scan.color.at<cv::Vec3b>(0, 0), cv::Vec3b(200, 0, 0));
  EXPECT_EQ(scan.color.at<cv::Vec3b>(0, 1), cv::Vec3b(7, 0, 0));
}

TEST(LasTest, FarCoordinatesKeepTenthsOfMillimetres) {
  TempFolder folder;
  HandLas las = ThreePoints(4, 6);
  las.scale = 0.0001;
  las.offset[0] = 512345;
  las.offset[1] = 5412345;
  las.offset[2] = 310;
  const Scan scan = ReadBytes(folder, Build(las));
  EXPECT_FALSE((scan.world_from_scanner.topRightCorner<3, 1>().isZero()));
  EXPECT_LT((WorldPointOfCell(scan, 0, 0) - Eigen::Vector3d(512345.0001, 5412345.0002, 310.0003)).norm(),
            2e-5);
  EXPECT_LT((WorldPointOfCell(scan, 0, 1) - Eigen::Vector3d(512345.1, 5412344.9, 309.85)).norm(), 2e-5);
}

// ---- Hostile and unsupported files ----

TEST(LasTest, HostileHeadersAreRefusedBeforeAllocating) {
  TempFolder folder;
  const std::string path = folder.File("bad.las");
  auto error_for = [&](const std::string& bytes) {
    testing_io::WriteText(path, bytes);
    return testing_io::ScanError(path);
  };
  const std::string good = Build(ThreePoints(4, 6));
  ASSERT_EQ(error_for(good), "");
  auto with = [&](size_t at, auto value) {
    std::string bytes = good;
    Put(&bytes, at, value);
    return bytes;
  };
  // More points than the file holds (the 64-bit count of LAS 1.4): refused, nothing allocated.
  EXPECT_THAT(error_for(with(247, uint64_t{1} << 40)),
              AllOf(HasSubstr(path), HasSubstr("header byte 247"), HasSubstr("Number of Point Records"),
                    HasSubstr("truncated")));
  EXPECT_THAT(error_for(with(247, uint64_t{4})), HasSubstr("truncated"));
  EXPECT_THAT(error_for(good.substr(0, good.size() - 1)), HasSubstr("truncated"));
  HandLas legacy = ThreePoints(2, 1);
  std::string legacy_bytes = Build(legacy);
  Put<uint32_t>(&legacy_bytes, 107, 0xFFFFFFFFu);
  EXPECT_THAT(error_for(legacy_bytes), AllOf(HasSubstr("header byte 107"), HasSubstr("4294967295 points")));
  EXPECT_EQ(error_for(with(247, uint64_t{0})), "");  // a header that promises no point: 0 points
  // A scale that cannot reach the header's bounds with 32-bit integers (5e-324 put every point on the offset).
  EXPECT_THAT(error_for(with(131, 5e-324)),
              AllOf(HasSubstr("X Scale Factor"), HasSubstr("not a coordinate step")));
  EXPECT_THAT(error_for(with(179, 1e9)),
              AllOf(HasSubstr("X Scale Factor"), HasSubstr("cannot represent the header's bound")));
  // Offset to the point data past the end, or inside the header.
  EXPECT_THAT(error_for(with(96, uint32_t{100000})),
              AllOf(HasSubstr("header byte 96"), HasSubstr("Offset to Point Data"), HasSubstr("100000")));
  EXPECT_THAT(error_for(with(96, uint32_t{300})), HasSubstr("Offset to Point Data"));
  // Record length too short for the format.
  EXPECT_THAT(error_for(with(105, uint16_t{20})),
              AllOf(HasSubstr("header byte 105"), HasSubstr("Point Data Record Length"),
                    HasSubstr("too short for point format 6 (30 bytes)")));
  EXPECT_THAT(error_for(with(104, uint8_t{11})), HasSubstr("11 does not exist"));
  EXPECT_THAT(error_for(with(94, uint16_t{200})), HasSubstr("Header Size"));
  EXPECT_THAT(error_for(with(25, uint8_t{5})), HasSubstr("LAS 1.5 is not read"));
  EXPECT_THAT(error_for(with(131, 0.0)),
              AllOf(HasSubstr("X Scale Factor"), HasSubstr("not a coordinate step")));
  EXPECT_THAT(error_for(with(163, std::nan(""))), HasSubstr("Y Offset"));
  EXPECT_THAT(error_for(with(171, 1e300)), HasSubstr("Z Offset"));
  EXPECT_THAT(error_for(with(107, uint32_t{2})), HasSubstr("the legacy count says 2"));
  // More records announced than fit before the points: read as far as they fit, with a warning (PDAL too).
  testing_io::WriteText(path, with(100, uint32_t{1}));
  const ScanFile miscounted = ReadScanFile(path);
  EXPECT_EQ(miscounted.scans.at(0).CountValid(), 3);
  ASSERT_EQ(miscounted.warnings.size(), 1u);
  EXPECT_THAT(miscounted.warnings[0], AllOf(HasSubstr(path), HasSubstr("does not fit")));
  EXPECT_THAT(error_for(good.substr(0, 200)), AllOf(HasSubstr(path), HasSubstr("truncated")));
  EXPECT_THAT(error_for("PK\x03\x04 not a las file at all"), HasSubstr("not a LAS file"));
  EXPECT_THAT(error_for(""), HasSubstr("empty"));
  // A coordinate beyond 10^7 m.
  HandLas far = ThreePoints(4, 6);
  far.scale = 1e6;
  EXPECT_THAT(error_for(Build(far)),
              AllOf(HasSubstr("point 1 (byte 405)"), HasSubstr("field 'X'"), HasSubstr("within")));
  HandLas with_vlr = ThreePoints(4, 6);
  with_vlr.vlr = "abc";
  std::string vlr_bytes = Build(with_vlr);
  Put<uint16_t>(&vlr_bytes, 375 + 20, 5000);
  testing_io::WriteText(path, vlr_bytes);
  EXPECT_THAT(ReadScanFile(path).warnings, testing::Contains(HasSubstr("does not fit")));
}

TEST(LasTest, LazIsReadButNotWritten) {
  TempFolder folder;
  const std::string laz = folder.File("x.laz");
  // .laz is read as LAS: an uncompressed file of that name too.
  testing_io::WriteText(laz, Build(ThreePoints(4, 6)));
  EXPECT_EQ(ReadScanFile(laz).scans.at(0).CountValid(),
            ReadBytes(folder, Build(ThreePoints(4, 6))).CountValid());
  EXPECT_THAT(InputErrorOf([&] { WriteScanFile(laz, {ReadBytes(folder, Build(ThreePoints(4, 6)))}); }),
              AllOf(HasSubstr("LAZ is not written"), HasSubstr("write .las instead")));
  // An output path is checked before any work: a .laz output is refused up front, and not offered.
  EXPECT_THAT(InputErrorOf([&] { CheckScanFileFormat(folder.File("out.laz")); }),
              HasSubstr("LAZ is not written"));
  EXPECT_THAT(SupportedScanWriteExtensions(), testing::Not(testing::Contains("laz")));
  EXPECT_THAT(SupportedScanReadExtensions(), testing::Contains("laz"));
  // LASzip marks compressed point formats with bits 7 and 6, and adds its VLR: bits without the VLR...
  std::string bytes = Build(ThreePoints(4, 6));
  bytes[104] = static_cast<char>(6 | 0x80);
  EXPECT_THAT(InputErrorOf([&] { ReadBytes(folder, bytes); }), HasSubstr("no laszip encoded VLR"));
  // ... and a VLR that is not LASzip's (all zero: compressor 0) are refused.
  HandLas with_vlr = ThreePoints(4, 6);
  with_vlr.vlr = std::string(34, '\0');
  bytes = Build(with_vlr);
  bytes[104] = static_cast<char>(6 | 0x80);
  std::memcpy(bytes.data() + 375 + 2, "laszip encoded\0\0", 16);
  Put<uint16_t>(&bytes, 375 + 18, 22204);
  EXPECT_THAT(InputErrorOf([&] { ReadBytes(folder, bytes); }),
              AllOf(HasSubstr("laszip VLR byte 0"), HasSubstr("compressor")));
}

}  // namespace
}  // namespace lidarshop
