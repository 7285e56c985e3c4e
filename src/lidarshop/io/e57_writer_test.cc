// E57 writer round trips, the bit-pack codec, CRC-32C pages and hostile inputs.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "lidarshop/io/e57.h"
#include "lidarshop/io/e57_format.h"
#include "lidarshop/scan/ray_directions.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

std::string TempPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("lidarshop_e57_" + name)).string();
}

// A synthetic organized scan (marked by its name): uniform grid, ranges 1..20 m with noise off the ray,
// holes, intensity and colour; every channel is known exactly.
Scan SyntheticScan(int rows, int cols, uint32_t seed, bool with_color) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  Scan s = MakeScan(rows, cols, with_color);
  s.name = fmt::format("synthetic_{}", seed);
  s.grid = UniformGrid(rows, cols, -1.2, 1.4, -0.6, 0.9);
  s.direction = DirectionsFromGrid(s.grid);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      if (u(rng) < 0.2f) continue;  // no return: keeps its direction, intensity 0.5
      const cv::Vec3f d = DirectionImage(s).at<cv::Vec3f>(r, c);
      const cv::Vec3f p = d * (1.0f + 19.0f * u(rng)) + cv::Vec3f(u(rng), u(rng), u(rng)) * 0.002f;
      s.valid.at<uint8_t>(r, c) = kValid;
      s.point.at<cv::Vec3f>(r, c) = p;
      s.range.at<float>(r, c) = static_cast<float>(cv::norm(p));
      s.intensity.at<float>(r, c) = u(rng);
      if (with_color) s.color.at<cv::Vec3b>(r, c) = cv::Vec3b(rng() & 255, rng() & 255, rng() & 255);
    }
  }
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();
  pose.topLeftCorner<3, 3>() =
      Eigen::AngleAxisd(0.3 + seed % 7, Eigen::Vector3d(0.2, -0.5, 1.0).normalized()).toRotationMatrix();
  pose.topRightCorner<3, 1>() = Eigen::Vector3d(10.5, -3.25, 1.125 * seed);
  s.world_from_scanner = pose;
  return s;
}

void ExpectSameScan(const Scan& a, const Scan& b, double point_tolerance_m) {
  ASSERT_EQ(a.rows, b.rows);
  ASSERT_EQ(a.cols, b.cols);
  EXPECT_EQ(a.name, b.name);
  EXPECT_LT((a.world_from_scanner - b.world_from_scanner).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_EQ(cv::countNonZero(a.valid != b.valid), 0);
  ASSERT_EQ(a.has_color(), b.has_color());
  const cv::Mat rays_a = DirectionImage(a), rays_b = DirectionImage(b);
  for (int64_t c = 0; c < a.num_cells(); ++c) {
    const cv::Vec3f da = rays_a.ptr<cv::Vec3f>()[c], db = rays_b.ptr<cv::Vec3f>()[c];
    if (!a.valid.ptr<uint8_t>()[c]) {
      // Stored as cartesianInvalidState 1 at the coordinates' precision (renormalized when quantized).
      ASSERT_LE(cv::norm(da - db, cv::NORM_INF), 2 * point_tolerance_m) << "no-return direction, cell " << c;
      ASSERT_EQ(b.intensity.ptr<float>()[c], 0.5f);
      continue;
    }
    const cv::Vec3f pa = a.point.ptr<cv::Vec3f>()[c], pb = b.point.ptr<cv::Vec3f>()[c];
    if (point_tolerance_m == 0) {
      ASSERT_EQ(pa, pb) << "cell " << c;
      ASSERT_EQ(a.range.ptr<float>()[c], b.range.ptr<float>()[c]) << "cell " << c;
    } else {
      ASSERT_LE(cv::norm(pa - pb, cv::NORM_INF), point_tolerance_m) << "cell " << c;
    }
    ASSERT_EQ(a.intensity.ptr<float>()[c], b.intensity.ptr<float>()[c]) << "cell " << c;
    if (a.has_color()) ASSERT_EQ(a.color.ptr<cv::Vec3b>()[c], b.color.ptr<cv::Vec3b>()[c]) << "cell " << c;
    // Valid cells get their direction from the fitted grid: close to the nominal one.
    ASSERT_LT(cv::norm(da - db), 0.02) << "cell " << c;
  }
}

TEST(E57Codec, Crc32cKnownValue) {
  const std::string s = "123456789";
  EXPECT_EQ(e57::Crc32c(reinterpret_cast<const uint8_t*>(s.data()), s.size()), 0xE3069283u);
  // Slicing-by-8 and the byte loop agree at every length and alignment.
  std::vector<uint8_t> bytes(100);
  for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<uint8_t>(i * 37 + 11);
  for (size_t n = 0; n < 40; ++n) {
    uint32_t crc = 0xFFFFFFFFu;
    for (size_t i = 3; i < 3 + n; ++i) {
      crc ^= bytes[i];
      for (int k = 0; k < 8; ++k) crc = (crc & 1) ? (crc >> 1) ^ 0x82F63B78u : crc >> 1;
    }
    EXPECT_EQ(e57::Crc32c(bytes.data() + 3, n), crc ^ 0xFFFFFFFFu) << n;
    EXPECT_EQ(e57::Crc32cPortable(bytes.data() + 3, n), crc ^ 0xFFFFFFFFu) << n;
  }
}

// The hardware instruction (where the CPU has it) and the tables agree on pages and odd lengths.
TEST(E57Codec, Crc32cHardwareEqualsPortable) {
  std::mt19937 rng(3);
  std::vector<uint8_t> bytes(5000);
  for (uint8_t& b : bytes) b = static_cast<uint8_t>(rng());
  for (const size_t offset : {0, 1, 5, 7}) {
    for (const size_t n : {0, 1, 7, 8, 9, 63, 1020, 1021, 4093}) {
      EXPECT_EQ(e57::Crc32c(bytes.data() + offset, n), e57::Crc32cPortable(bytes.data() + offset, n))
          << offset << " " << n;
    }
  }
}

TEST(E57Codec, BitPackRoundTripEveryWidth) {
  std::mt19937_64 rng(7);
  for (int bits = 0; bits <= 64; ++bits) {
    e57::Field f;
    f.name = "v";
    f.type = e57::Field::Type::kInteger;
    f.minimum = bits == 64 ? std::numeric_limits<int64_t>::min() : -1000;
    f.maximum = bits == 64  ? std::numeric_limits<int64_t>::max()
                : bits == 0 ? f.minimum
                            : f.minimum + static_cast<int64_t>((uint64_t{1} << bits) - 1);
    ASSERT_EQ(e57::BitsForRange(f.minimum, f.maximum), bits);
    f.bits = bits;
    const int n = 1000 + bits;
    std::vector<int64_t> values(n);
    e57::BitWriter w(bits);
    for (int i = 0; i < n; ++i) {
      const uint64_t span = bits == 0 ? 0 : bits == 64 ? ~uint64_t{0} : (uint64_t{1} << bits) - 1;
      const uint64_t raw = span == ~uint64_t{0} ? rng() : rng() % (span + 1);
      values[i] = static_cast<int64_t>(static_cast<uint64_t>(f.minimum) + raw);
      w.PutInteger(values[i], f.minimum);
    }
    const std::vector<uint8_t> stream = w.Finish();
    EXPECT_EQ(stream.size(), (static_cast<size_t>(n) * bits + 7) / 8);
    std::vector<double> out(n);
    e57::DecodeField(f, stream.data(), stream.size(), n, out.data(), "test");
    for (int i = 0; i < n; ++i) {
      // Doubles hold integers exactly up to 2^53; wider fields are compared after the same rounding.
      ASSERT_EQ(out[i], static_cast<double>(values[i])) << "bits " << bits << " value " << i;
    }
    if (bits > 0) {  // one value too many is refused, naming the field
      EXPECT_THROW(e57::DecodeField(f, stream.data(), stream.size() - 1 - (bits > 8), n, out.data(), "test"),
                   InputError);
    }
  }
}

TEST(E57Codec, ScaledIntegerAndFloats) {
  e57::Field f;
  f.name = "x";
  f.type = e57::Field::Type::kScaledInteger;
  f.minimum = -8388608;
  f.maximum = 8388607;
  f.scale = 1e-6;
  f.offset = 2.5;
  f.bits = e57::BitsForRange(f.minimum, f.maximum);
  EXPECT_EQ(f.bits, 24);
  e57::BitWriter w(f.bits);
  w.PutInteger(-8388608, f.minimum);
  w.PutInteger(0, f.minimum);
  w.PutInteger(8388607, f.minimum);
  const auto s = w.Finish();
  double out[3];
  e57::DecodeField(f, s.data(), s.size(), 3, out, "test");
  EXPECT_DOUBLE_EQ(out[0], -8.388608 + 2.5);
  EXPECT_DOUBLE_EQ(out[1], 2.5);
  EXPECT_DOUBLE_EQ(out[2], 8.388607 + 2.5);

  e57::Field g;
  g.type = e57::Field::Type::kDouble;
  g.bits = 64;
  e57::BitWriter wd(64);
  wd.PutDouble(-1.0 / 3.0);
  wd.PutDouble(1e300);
  const auto sd = wd.Finish();
  e57::DecodeField(g, sd.data(), sd.size(), 2, out, "test");
  EXPECT_EQ(out[0], -1.0 / 3.0);
  EXPECT_EQ(out[1], 1e300);
}

TEST(E57Pages, CorruptByteNamesPageAndOffset) {
  std::vector<uint8_t> logical(3000);
  for (size_t i = 0; i < logical.size(); ++i) logical[i] = static_cast<uint8_t>(i);
  std::vector<uint8_t> pages = e57::PagesFromLogical(logical);
  ASSERT_EQ(pages.size(), 3 * 1024u);
  const std::vector<uint8_t> back = e57::LogicalFromPages("x.e57", pages);
  EXPECT_TRUE(std::equal(logical.begin(), logical.end(), back.begin()));
  pages[2 * 1024 + 5] ^= 1;
  try {
    e57::LogicalFromPages("x.e57", pages);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("x.e57: page 2 (byte offset 2048)"));
  }
  pages.resize(2500);
  EXPECT_THROW(e57::LogicalFromPages("x.e57", pages), InputError);
}

TEST(E57Writer, OrganizedRoundTripIsExact) {
  const Scan scan = SyntheticScan(41, 67, 1, true);
  const std::string path = TempPath("organized.e57");
  WriteE57(path, {scan});
  const E57File f = ReadE57(path);
  ASSERT_EQ(f.scans.size(), 1u);
  ExpectSameScan(scan, f.scans[0], 0.0);
  // The grid is the scan's (lidarshop:angularGrid), not fitted again.
  EXPECT_EQ(f.scans[0].grid.fitted, scan.grid.fitted);
  EXPECT_EQ(f.scans[0].grid.azimuth_rad, scan.grid.azimuth_rad);
  EXPECT_EQ(f.scans[0].grid.elevation_rad, scan.grid.elevation_rad);
  // The XML's cartesianBounds are the valid points' bounds.
  const std::vector<uint8_t> logical = e57::LogicalFromPages(path, EncodeE57({scan}));
  const std::string text(logical.begin(), logical.end());
  float y_min = 1e9f, y_max = -1e9f;  // all y > 0 here: a bound stuck at 0 would show
  for (int64_t c = 0; c < scan.num_cells(); ++c) {
    if (!scan.valid.ptr<uint8_t>()[c]) continue;
    y_min = std::min(y_min, scan.point.ptr<cv::Vec3f>()[c][1]);
    y_max = std::max(y_max, scan.point.ptr<cv::Vec3f>()[c][1]);
  }
  ASSERT_GT(y_min, 0.0f);
  EXPECT_THAT(text,
              HasSubstr(fmt::format("<yMinimum type=\"Float\">{}</yMinimum>", static_cast<double>(y_min))));
  EXPECT_THAT(text,
              HasSubstr(fmt::format("<yMaximum type=\"Float\">{}</yMaximum>", static_cast<double>(y_max))));
  std::filesystem::remove(path);
}

TEST(E57Writer, SeveralScansAndUnstructuredRoundTrip) {
  std::vector<Scan> scans = {SyntheticScan(20, 30, 2, true), SyntheticScan(33, 9, 3, false)};
  // An unstructured scan: 1 x N, all points valid, no grid.
  Scan points = MakeScan(1, 500, true);
  points.name = "points";
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u(-5.0f, 5.0f);
  for (int c = 0; c < 500; ++c) {
    const cv::Vec3f p(u(rng), u(rng), u(rng));
    points.valid.at<uint8_t>(0, c) = kValid;
    points.point.at<cv::Vec3f>(0, c) = p;
    points.range.at<float>(0, c) = static_cast<float>(cv::norm(p));
    points.direction.at<cv::Vec3f>(0, c) = p / points.range.at<float>(0, c);
    points.intensity.at<float>(0, c) = (u(rng) + 5.0f) / 10.0f;
    points.color.at<cv::Vec3b>(0, c) = cv::Vec3b(c & 255, (3 * c) & 255, 7);
  }
  scans.push_back(points);
  const std::string path = TempPath("several.e57");
  WriteE57(path, scans);
  const E57File f = ReadE57(path);
  ASSERT_EQ(f.scans.size(), 3u);
  for (size_t i = 0; i < 2; ++i) ExpectSameScan(scans[i], f.scans[i], 0.0);
  const Scan& b = f.scans[2];
  ASSERT_EQ(b.rows, 1);
  ASSERT_EQ(b.cols, 500);
  for (int c = 0; c < 500; ++c) {
    ASSERT_EQ(b.point.at<cv::Vec3f>(0, c), points.point.at<cv::Vec3f>(0, c));
    ASSERT_EQ(b.intensity.at<float>(0, c), points.intensity.at<float>(0, c));
    ASSERT_EQ(b.color.at<cv::Vec3b>(0, c), points.color.at<cv::Vec3b>(0, c));
  }
  std::filesystem::remove(path);
}

TEST(E57Writer, AScanWithoutIntensityWritesNoIntensityField) {
  Scan scan = SyntheticScan(12, 17, 5, true);
  scan.intensity = cv::Mat();
  const std::vector<uint8_t> bytes = EncodeE57({scan});
  const std::string path = TempPath("no_intensity.e57");
  {
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  }
  const std::vector<uint8_t> logical = e57::LogicalFromPages(path, bytes);
  const std::string text(logical.begin(), logical.end());
  EXPECT_THAT(text, ::testing::Not(HasSubstr("intensity")));
  const E57File f = ReadE57Bytes(bytes, "no_intensity.e57");
  ASSERT_EQ(f.scans.size(), 1u);
  EXPECT_FALSE(f.scans[0].has_intensity());
  EXPECT_THAT(ChannelNames(f.scans[0]), ::testing::Not(::testing::Contains("intensity")));
  EXPECT_EQ(f.scans[0].CountValid(), scan.CountValid());
  std::filesystem::remove(path);
}

TEST(E57Writer, AWholeFileKeepsSecondReturnsAndTheirFlags) {
  // E57 -> E57: second returns of a measured file stay measured; a lidarshop layer keeps its flags.
  const Scan front = SyntheticScan(10, 14, 6, false);
  Scan second = MakeScan(front.rows, front.cols);
  second.world_from_scanner = front.world_from_scanner;
  second.direction = front.direction.clone();
  for (int c = 0; c < front.cols; c += 3) {
    if (!front.valid.at<uint8_t>(4, c)) continue;
    const cv::Vec3f p = front.point.at<cv::Vec3f>(4, c) * 1.5f;
    second.valid.at<uint8_t>(4, c) = kValid;
    second.point.at<cv::Vec3f>(4, c) = p;
    second.range.at<float>(4, c) = static_cast<float>(cv::norm(p));
    second.intensity.at<float>(4, c) = 0.125f;
  }
  ASSERT_GT(second.CountValid(), 0);
  E57File file;
  file.scans = {front, SyntheticScan(5, 6, 7, true)};
  file.second_returns = {second, Scan()};  // the second scan has none
  const E57File back = ReadE57Bytes(EncodeE57(file, {}), "two_layers.e57");
  ASSERT_EQ(back.scans.size(), 2u);
  ASSERT_EQ(back.second_returns.size(), 2u);
  EXPECT_EQ(back.second_returns[0].CountValid(), second.CountValid());
  EXPECT_EQ(back.second_returns[1].num_cells(), 0);
  EXPECT_EQ(back.scans[0].CountValid(), front.CountValid());
  const Scan& layer = back.second_returns[0];
  ASSERT_FALSE(layer.synthesized.empty());
  EXPECT_EQ(cv::countNonZero(layer.synthesized), 0);  // measured, not synthesized
  for (int c = 0; c < front.cols; ++c) {
    if (!second.valid.at<uint8_t>(4, c)) continue;
    EXPECT_EQ(layer.point.at<cv::Vec3f>(4, c), second.point.at<cv::Vec3f>(4, c));
    EXPECT_EQ(layer.intensity.at<float>(4, c), 0.125f);
  }
  // A layer flagged synthesized stays synthesized.
  file.second_returns[0].synthesized = second.valid.clone();
  const E57File flagged = ReadE57Bytes(EncodeE57(file, {}), "flagged.e57");
  EXPECT_EQ(cv::countNonZero(flagged.second_returns[0].synthesized & flagged.second_returns[0].valid),
            second.CountValid());
}

TEST(E57Reader, RecordsOverSeveralDecodingBlocksComeBackExactly) {
  // The reader decodes 65,536 records at a time: 137,557 cells of 9-bit row and column indices (blocks that
  // start inside the packets' chunks), with second returns on every 5th row, must come back cell for cell.
  const Scan front = SyntheticScan(301, 457, 12, true);
  Scan second = MakeScan(front.rows, front.cols, true);
  second.world_from_scanner = front.world_from_scanner;
  second.name = front.name;
  second.direction = front.direction.clone();
  for (int r = 0; r < front.rows; r += 5) {
    for (int c = 0; c < front.cols; ++c) {
      if (!front.valid.at<uint8_t>(r, c)) continue;
      const cv::Vec3f p = front.point.at<cv::Vec3f>(r, c) * 1.25f;
      second.valid.at<uint8_t>(r, c) = kValid;
      second.point.at<cv::Vec3f>(r, c) = p;
      second.range.at<float>(r, c) = static_cast<float>(cv::norm(p));
      second.intensity.at<float>(r, c) = 0.25f;
      second.color.at<cv::Vec3b>(r, c) = cv::Vec3b(r & 255, c & 255, 9);
    }
  }
  ASSERT_GT(front.num_cells() + second.CountValid(), 2 * 65536);
  E57File file;
  file.scans = {front};
  file.second_returns = {second};
  const E57File back = ReadE57Bytes(EncodeE57(file, {}), "blocks.e57");
  ASSERT_EQ(back.scans.size(), 1u);
  ExpectSameScan(front, back.scans[0], 0.0);
  ASSERT_EQ(back.second_returns.size(), 1u);
  const Scan& layer = back.second_returns[0];
  ASSERT_EQ(layer.CountValid(), second.CountValid());
  for (int64_t c = 0; c < second.num_cells(); ++c) {
    if (!second.valid.ptr<uint8_t>()[c]) continue;
    ASSERT_EQ(layer.point.ptr<cv::Vec3f>()[c], second.point.ptr<cv::Vec3f>()[c]) << "cell " << c;
    ASSERT_EQ(layer.intensity.ptr<float>()[c], 0.25f) << "cell " << c;
    ASSERT_EQ(layer.color.ptr<cv::Vec3b>()[c], second.color.ptr<cv::Vec3b>()[c]) << "cell " << c;
  }
}

TEST(E57Reader, TurnsBottomUpAndMirroredGridsIntoImageOrientation) {
  // A file whose rowIndex 0 is the bottom row (like pumpA) and whose columns run against our azimuth.
  const Scan scan = SyntheticScan(30, 50, 11, true);
  for (int code : {0, 1, -1}) {
    SCOPED_TRACE(code);
    Scan turned = Clone(scan);
    for (cv::Mat* m :
         {&turned.direction, &turned.valid, &turned.range, &turned.point, &turned.intensity, &turned.color}) {
      cv::flip(*m, *m, code);
    }
    const E57File f = ReadE57Bytes(EncodeE57({turned}), "turned.e57");
    ExpectSameScan(scan, f.scans[0], 0.0);
  }
}

TEST(E57Writer, ScaledIntegerCoordinatesWithinHalfAStep) {
  const Scan scan = SyntheticScan(25, 40, 5, true);
  E57WriteOptions options;
  options.coordinate_scale_m = 1e-4;
  const std::vector<uint8_t> bytes = EncodeE57({scan}, options);
  const std::vector<uint8_t> float_bytes = EncodeE57({scan});
  EXPECT_LT(bytes.size(), float_bytes.size());  // 19-bit coordinates instead of 32
  const E57File f = ReadE57Bytes(bytes, "scaled.e57");
  ASSERT_EQ(f.scans.size(), 1u);
  ExpectSameScan(scan, f.scans[0], 0.5e-4 + 2e-6);  // half a step + float rounding at 20 m
}

TEST(E57Writer, SameInputSameBytesAndManyPackets) {
  // 300 x 400 cells span many 64 KiB packets and pages.
  const Scan scan = SyntheticScan(300, 400, 6, true);
  const std::vector<uint8_t> a = EncodeE57({scan});
  EXPECT_EQ(a, EncodeE57({scan}));
  EXPECT_GT(a.size(), 10u * e57::kMaxPacketSize);
  const E57File f = ReadE57Bytes(a, "many.e57");
  ExpectSameScan(scan, f.scans[0], 0.0);
}

TEST(E57Writer, AFileWrittenPageByPageEqualsTheBytesInMemory) {
  // WriteE57 writes pages as they fill (page 0, the header's, last); EncodeE57 builds the bytes in memory.
  const Scan scan = SyntheticScan(300, 400, 8, true);
  const std::string path = TempPath("pages.e57");
  WriteE57(path, {scan});
  std::ifstream in(path, std::ios::binary);
  const std::vector<uint8_t> written((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(written, EncodeE57({scan}));
  EXPECT_GT(written.size(), 100 * e57::kPageSize);
  std::filesystem::remove(path);
}

TEST(E57Codec, StreamedCompressedVectorEqualsThePackedOne) {
  // A compressed vector packed as its packets take it equals the one of whole bytestreams, for fields of 0,
  // 1, 7, 13, 32 and 64 bits over several packets.
  std::mt19937_64 rng(21);
  const int64_t n = 70001;
  const int widths[] = {0, 1, 7, 13, 32, 64};
  std::vector<e57::Stream> packed;
  std::vector<std::vector<int64_t>> values;
  for (int bits : widths) {
    e57::Field field = bits == 0    ? e57::IntegerField("f0", 5, 5)
                       : bits == 64 ? e57::IntegerField("f64", std::numeric_limits<int64_t>::min(),
                                                        std::numeric_limits<int64_t>::max())
                                    : e57::IntegerField("f", 0, (int64_t{1} << bits) - 1);
    std::vector<int64_t> v(n);
    for (int64_t& x : v)
      x = bits == 0 ? 5 : bits == 64 ? static_cast<int64_t>(rng()) : rng() % (field.maximum + 1);
    e57::BitWriter writer(field.bits);
    for (int64_t x : v) writer.PutInteger(x, field.minimum);
    packed.push_back({field, writer.Finish()});
    values.push_back(std::move(v));
  }
  std::vector<uint8_t> whole(48, 0);
  e57::AppendCompressedVector(packed, n, &whole);
  std::vector<e57::StreamSource> sources;
  for (size_t i = 0; i < packed.size(); ++i) {
    const std::vector<int64_t>* v = &values[i];
    const int64_t minimum = packed[i].field.minimum;
    sources.push_back({packed[i].field, [v, minimum](int64_t first, int64_t count, e57::BitWriter* w) {
                         for (int64_t k = first; k < first + count; ++k) w->PutInteger((*v)[k], minimum);
                       }});
  }
  std::vector<uint8_t> streamed;
  e57::LogicalSink sink(&streamed);
  sink.AppendZeros(48);
  e57::AppendCompressedVector(sources, n, &sink);
  EXPECT_GT(whole.size(), 4 * e57::kMaxPacketSize);
  EXPECT_EQ(streamed, whole);
}

TEST(E57Writer, NoScansAndRejectsNonRigidPose) {
  const E57File f = ReadE57Bytes(EncodeE57({}), "none.e57");
  EXPECT_TRUE(f.scans.empty());
  Scan scan = SyntheticScan(4, 5, 8, false);
  scan.world_from_scanner(0, 0) = 2.0;
  EXPECT_THROW(EncodeE57({scan}), InputError);
  E57WriteOptions bad;
  bad.coordinate_scale_m = -1;
  EXPECT_THROW(bad.Check(), OptionsError);
}

// Builds a file around a hand-written XML section (no binary sections).
std::vector<uint8_t> FileWithXml(const std::string& xml) {
  std::vector<uint8_t> logical(e57::kHeaderSize, 0);
  e57::Header h;
  h.xml_physical_offset = e57::kHeaderSize;
  h.xml_logical_length = xml.size();
  logical.insert(logical.end(), xml.begin(), xml.end());
  h.file_physical_length = (logical.size() + e57::kPagePayload - 1) / e57::kPagePayload * e57::kPageSize;
  e57::StoreHeader(h, logical.data());
  return e57::PagesFromLogical(logical);
}

TEST(E57Reader, RefusesAbsurdSizesBeforeAllocating) {
  const std::string head =
      R"(<?xml version="1.0"?><e57Root type="Structure"><data3D type="Vector"><vectorChild type="Structure">)";
  const std::string tail = R"(</vectorChild></data3D></e57Root>)";
  // A huge record count with 0-bit fields only would need no bytes at all: refused by the limit on the records
  // of all scans together (max(2^22, 64 per byte of file)), before any scan is read.
  const std::string huge = head +
                           R"(<points type="CompressedVector" fileOffset="48" recordCount="999999999999">
        <prototype type="Structure"><cartesianX type="Integer" minimum="0" maximum="0"/>
        <cartesianY type="Integer" minimum="0" maximum="0"/><cartesianZ type="Integer" minimum="0" maximum="0"/>
        </prototype></points>)" +
                           tail;
  try {
    ReadE57Bytes(FileWithXml(huge), "huge.e57");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), AllOf(HasSubstr("huge.e57"), HasSubstr("recordCount (records of all scans)")));
  }
  // A record count within that limit whose bytestreams cannot fit in the file.
  const std::string big = head +
                          R"(<points type="CompressedVector" fileOffset="48" recordCount="4000000">
        <prototype type="Structure"><cartesianX type="Float"/><cartesianY type="Float"/><cartesianZ type="Float"/>
        </prototype></points>)" +
                          tail;
  try {
    ReadE57Bytes(FileWithXml(big), "big.e57");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("needs 96000000 bytes"));
  }
  // A grid far larger than the cell limit.
  const std::string grid = head +
                           R"(<indexBounds type="Structure"><rowMaximum type="Integer">2000000000</rowMaximum>
        <columnMaximum type="Integer">2000000000</columnMaximum></indexBounds>
        <points type="CompressedVector" fileOffset="48" recordCount="0">
        <prototype type="Structure"><cartesianX type="Float"/><cartesianY type="Float"/><cartesianZ type="Float"/>
        <rowIndex type="Integer" minimum="0" maximum="10"/><columnIndex type="Integer" minimum="0" maximum="10"/>
        </prototype></points>)" +
                           tail;
  EXPECT_THROW(ReadE57Bytes(FileWithXml(grid), "grid.e57"), InputError);
  // Deeply nested prototypes and a missing recordCount.
  std::string deep =
      head +
      R"(<points type="CompressedVector" fileOffset="48" recordCount="0"><prototype type="Structure">)";
  for (int i = 0; i < 10000; ++i) deep += R"(<s type="Structure">)";
  for (int i = 0; i < 10000; ++i) deep += "</s>";
  deep += "</prototype></points>" + tail;
  EXPECT_THROW(ReadE57Bytes(FileWithXml(deep), "deep.e57"), InputError);
  const std::string no_count = head +
                               R"(<points type="CompressedVector" fileOffset="48"><prototype type="Structure">
        <cartesianX type="Float"/><cartesianY type="Float"/><cartesianZ type="Float"/></prototype></points>)" +
                               tail;
  try {
    ReadE57Bytes(FileWithXml(no_count), "no_count.e57");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("'recordCount' is missing"));
  }
  // Broken XML names the offset.
  try {
    ReadE57Bytes(FileWithXml("<e57Root><data3D></e57Root>"), "bad.e57");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("malformed XML"));
  }
}

TEST(E57Reader, TruncatedAndFlippedFilesFailCleanly) {
  const std::vector<uint8_t> good = EncodeE57({SyntheticScan(30, 40, 9, true)});
  // Every truncation to whole pages is refused by the header length; other sizes by the page size.
  for (size_t size : {size_t{0}, size_t{47}, size_t{1024}, good.size() - 1024, good.size() - 1}) {
    std::vector<uint8_t> cut(good.begin(), good.begin() + size);
    EXPECT_THROW(ReadE57Bytes(cut, "cut.e57"), InputError) << size;
  }
  // Corrupt payload bytes with repaired CRCs (so the checks below the page layer run): never a crash.
  std::mt19937 rng(10);
  std::vector<uint8_t> logical = e57::LogicalFromPages("good", good);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<uint8_t> bad = logical;
    for (int k = 0; k < 4; ++k) bad[rng() % bad.size()] = static_cast<uint8_t>(rng());
    try {
      ReadE57Bytes(e57::PagesFromLogical(bad), "bad.e57");
    } catch (const InputError&) {
    }
  }
}

// Inputs the fuzzer (fuzz/run_e57_fuzz.sh) found crashing, stored as logical streams: each must now read or
// fail with an InputError.
TEST(E57Reader, FuzzRegressions) {
  int files = 0;
  for (const auto& entry :
       std::filesystem::directory_iterator(LIDARSHOP_SOURCE_DIR "/data/fuzz_regressions")) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("e57_", 0) != 0) continue;
    SCOPED_TRACE(name);
    std::ifstream in(entry.path(), std::ios::binary);
    const std::vector<uint8_t> logical((std::istreambuf_iterator<char>(in)),
                                       std::istreambuf_iterator<char>());
    try {
      ReadE57Bytes(e57::PagesFromLogical(logical), name);
    } catch (const InputError&) {
    }
    ++files;
  }
  EXPECT_GE(files, 1);
}

}  // namespace
}  // namespace lidarshop
