// The LAZ decoder against the uncompressed twins of the interop files (written by LASzip, liblas, PDAL):
// every decoded record must equal the twin's byte for byte. The files are read here with a few lines from
// the LAS specification (fixed header offsets), not with lidarshop's LAS reader.
#include "lidarshop/io/laz.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <tuple>

#include <gtest/gtest.h>

#include "lidarshop/io/scan_io.h"
#include "lidarshop/util/error.h"

namespace lidarshop::laz {
namespace {

const std::string kInterop = LIDARSHOP_SHARED_DATA_DIR "/interop/";

std::string Slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  EXPECT_TRUE(in.good()) << path << " is missing (the shared data must be present)";
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

template <typename T>
T Load(const std::string& b, size_t at) {
  T v;
  std::memcpy(&v, b.data() + at, sizeof(T));
  return v;
}

// A LAS / LAZ file's header fields (LAS 1.4 R15 table 3) and its laszip VLR's payload.
struct LasFile {
  std::string bytes;
  uint32_t offset_to_points = 0;
  int format = 0;  // without LASzip's bits
  int record_length = 0;
  uint64_t count = 0;
  double scale[3], offset[3];
  size_t data_end = 0;  // the point data's end: the first EVLR (LAS 1.4) or the file's end
  std::string laszip_payload;

  explicit LasFile(const std::string& path) : bytes(Slurp(path)) {
    if (bytes.size() < 227) {
      ADD_FAILURE() << path << " is too short";
      return;
    }
    offset_to_points = Load<uint32_t>(bytes, 96);
    format = static_cast<uint8_t>(bytes[104]) & 0x3F;
    record_length = Load<uint16_t>(bytes, 105);
    count = Load<uint32_t>(bytes, 107);
    if (bytes[25] >= 4 && count == 0) count = Load<uint64_t>(bytes, 247);
    data_end = bytes.size();
    if (bytes[25] >= 4 && Load<uint32_t>(bytes, 243) > 0) data_end = Load<uint64_t>(bytes, 235);
    for (int i = 0; i < 3; ++i) {
      scale[i] = Load<double>(bytes, 131 + 8 * i);
      offset[i] = Load<double>(bytes, 155 + 8 * i);
    }
    size_t at = Load<uint16_t>(bytes, 94);
    for (uint32_t i = 0, n = Load<uint32_t>(bytes, 100); i < n && at + 54 <= bytes.size(); ++i) {
      const uint16_t length = Load<uint16_t>(bytes, at + 20);
      if (bytes.compare(at + 2, 14, "laszip encoded") == 0 && Load<uint16_t>(bytes, at + 18) == 22204) {
        laszip_payload = bytes.substr(at + 54, length);
      }
      at += 54 + length;
    }
  }
  std::string Records() const { return bytes.substr(offset_to_points, count * record_length); }
  std::string Decode(const std::string& data, const std::string& payload) const {
    return DecodeLazPoints(payload, data, offset_to_points, count, format, record_length, "test.laz");
  }
  std::string Decode() const { return Decode(bytes, laszip_payload); }
};

struct Pair {
  const char* laz;
  const char* las;
};
// interop/SOURCES.md: each LAZ and its uncompressed twin.
const Pair kPairs[] = {
    {"simple.laz", "simple.las"},            // LASzip 3.4: pointwise chunked, items v2, format 3
    {"laszip-generated.laz", "simple.las"},  // LASzip 2.0.1
    {"laszip-generated_with2bytespadding.laz", "simple.las"},
    {"liblas-generated.laz", "simple.las"},
    {"simple-laszip-compressor-version-1.2r0.laz", "simple.las"},  // pointwise (not chunked), items v1
    {"autzen_trim.laz", "autzen_trim.las"},                        // 110000 points in 3 chunks
};

TEST(Laz, DecodesEveryInteropFileToItsUncompressedTwin) {
  for (const Pair& pair : kPairs) {
    SCOPED_TRACE(pair.laz);
    const LasFile laz(kInterop + "laz/" + pair.laz);
    const LasFile las(kInterop + "las/" + pair.las);
    ASSERT_FALSE(laz.laszip_payload.empty());
    ASSERT_EQ(laz.format, las.format);
    ASSERT_EQ(laz.record_length, las.record_length);
    ASSERT_EQ(laz.count, las.count);
    ASSERT_GT(las.count, 1000u);
    const std::string decoded = laz.Decode();
    const std::string expected = las.Records();
    ASSERT_EQ(decoded.size(), expected.size());
    for (uint64_t i = 0; i < las.count; ++i) {
      ASSERT_EQ(decoded.compare(i * las.record_length, las.record_length, expected, i * las.record_length,
                                las.record_length),
                0)
          << "point " << i;
    }
  }
}

TEST(Laz, ParsesTheVlrOfEachCompressor) {
  const LazVlr v1 =
      ParseLazVlr(LasFile(kInterop + "laz/simple-laszip-compressor-version-1.2r0.laz").laszip_payload, "f");
  EXPECT_EQ(v1.compressor, 1);
  ASSERT_EQ(v1.items.size(), 3u);
  EXPECT_EQ(v1.items[2].type, 8);  // RGB12
  EXPECT_EQ(v1.items[2].version, 1);
  const LazVlr v2 = ParseLazVlr(LasFile(kInterop + "laz/autzen_trim.laz").laszip_payload, "f");
  EXPECT_EQ(v2.compressor, 2);
  EXPECT_EQ(v2.chunk_size, 50000u);
  const LazVlr v3 = ParseLazVlr(LasFile(kInterop + "laz/1.2-with-color.copc.laz").laszip_payload, "f");
  EXPECT_EQ(v3.compressor, 3);
  EXPECT_EQ(v3.chunk_size, kVariableChunkSize);
  ASSERT_EQ(v3.items.size(), 2u);
  EXPECT_EQ(v3.items[0].type, 10);  // POINT14
  EXPECT_EQ(v3.items[1].type, 11);  // RGB14
}

// The COPC file holds 1.2-with-color.las's points in point format 7 (layered, variable chunks), in another
// order and with another coordinate offset; compared as sets with the format 3 -> 7 attribute mapping.
TEST(Laz, DecodesTheCopcFileToTheSamePointsAsItsFormat3Twin) {
  const LasFile copc(kInterop + "laz/1.2-with-color.copc.laz");
  const LasFile las(kInterop + "las/1.2-with-color.las");
  ASSERT_EQ(copc.format, 7);
  ASSERT_EQ(las.format, 3);
  ASSERT_EQ(copc.count, las.count);
  ASSERT_GT(las.count, 1000u);
  const std::string decoded = copc.Decode();
  ASSERT_EQ(decoded.size(), copc.count * copc.record_length);
  using Point = std::tuple<int64_t, int64_t, int64_t, int, int, int, int, int, int, int, int, int, int,
                           uint64_t, int, int, int>;
  auto coordinate = [](const LasFile& f, const char* record, int axis) {
    // World coordinate in 1/100 of the scale step of the LAS file (both files have scale 0.01).
    return std::llround((Load<int32_t>(std::string(record, 12), 4 * axis) * f.scale[axis] + f.offset[axis]) /
                        f.scale[axis]);
  };
  std::vector<Point> expected, actual;
  const std::string records = las.Records();
  for (uint64_t i = 0; i < las.count; ++i) {
    const char* r = records.data() + i * las.record_length;
    const std::string s(r, las.record_length);
    const auto bits = static_cast<uint8_t>(s[14]), cls = static_cast<uint8_t>(s[15]);
    expected.emplace_back(coordinate(las, r, 0), coordinate(las, r, 1), coordinate(las, r, 2),
                          Load<uint16_t>(s, 12), bits & 7, (bits >> 3) & 7, (bits >> 6) & 1, bits >> 7,
                          cls & 31, cls >> 5, static_cast<int8_t>(s[16]), static_cast<uint8_t>(s[17]),
                          Load<uint16_t>(s, 18), Load<uint64_t>(s, 20), Load<uint16_t>(s, 28),
                          Load<uint16_t>(s, 30), Load<uint16_t>(s, 32));
  }
  for (uint64_t i = 0; i < copc.count; ++i) {
    const char* r = decoded.data() + i * copc.record_length;
    const std::string s(r, copc.record_length);
    const auto returns = static_cast<uint8_t>(s[14]), flags = static_cast<uint8_t>(s[15]);
    EXPECT_EQ((flags >> 4) & 3, 0) << "scanner channel of point " << i;
    // Format 7's scan angle is in 0.006 degree steps, format 3's rank in degrees.
    const int scan_angle_degrees = static_cast<int>(std::lround(Load<int16_t>(s, 18) * 0.006));
    actual.emplace_back(coordinate(copc, r, 0), coordinate(copc, r, 1), coordinate(copc, r, 2),
                        Load<uint16_t>(s, 12), returns & 15, returns >> 4, (flags >> 6) & 1, flags >> 7,
                        static_cast<uint8_t>(s[16]), flags & 15, scan_angle_degrees,
                        static_cast<uint8_t>(s[17]), Load<uint16_t>(s, 20), Load<uint64_t>(s, 22),
                        Load<uint16_t>(s, 30), Load<uint16_t>(s, 32), Load<uint16_t>(s, 34));
  }
  EXPECT_NE(expected, actual) << "the COPC order differs from the LAS order (else this test is too weak)";
  std::sort(expected.begin(), expected.end());
  std::sort(actual.begin(), actual.end());
  EXPECT_EQ(expected, actual);
}

// Cuts and bit flips: an InputError naming the file, or (a flip inside arithmetic-coded data, which has no
// checksum) records of the right size; never a crash. Run under ASan/UBSan to check the "never".
TEST(Laz, RefusesTruncatedFiles) {
  for (const char* name : {"simple.laz", "simple-laszip-compressor-version-1.2r0.laz", "autzen_trim.laz",
                           "1.2-with-color.copc.laz"}) {
    SCOPED_TRACE(name);
    const LasFile laz(kInterop + std::string("laz/") + name);
    const size_t size = laz.data_end;  // EVLRs after the points are not the decoder's concern
    for (size_t keep : {size - 1, size - 9, size * 9 / 10, size / 2, size_t{laz.offset_to_points} + 40,
                        size_t{laz.offset_to_points} + 4, size_t{laz.offset_to_points}}) {
      SCOPED_TRACE(keep);
      try {
        laz.Decode(laz.bytes.substr(0, keep), laz.laszip_payload);
        ADD_FAILURE() << "a file cut to " << keep << " of " << size << " bytes was decoded";
      } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("test.laz"), std::string::npos) << e.what();
      }
    }
  }
}

TEST(Laz, SurvivesBitFlipsAndRefusesBrokenStructure) {
  for (const char* name :
       {"simple.laz", "simple-laszip-compressor-version-1.2r0.laz", "1.2-with-color.copc.laz"}) {
    SCOPED_TRACE(name);
    const LasFile laz(kInterop + std::string("laz/") + name);
    const std::string good = laz.Decode();
    int refused = 0, changed = 0, flips = 0;
    for (size_t at = laz.offset_to_points; at < laz.data_end; at += 97) {
      std::string bad = laz.bytes;
      bad[at] = static_cast<char>(bad[at] ^ (1 << (at % 8)));
      ++flips;
      try {
        const std::string decoded = laz.Decode(bad, laz.laszip_payload);
        ASSERT_EQ(decoded.size(), good.size());
        changed += decoded != good;
      } catch (const InputError&) {
        ++refused;
      }
    }
    // A flip goes unnoticed only in bytes no decoded value depends on: the 2-3 bytes that end each
    // arithmetic-coded stream (a chunk, or each of a layered chunk's layers) as padding.
    EXPECT_GE(refused + changed, flips * 9 / 10)
        << refused << " refused, " << changed << " changed of " << flips;
    EXPECT_GT(refused, 0);
    RecordProperty(std::string(name) + "_refused_of_flips",
                   std::to_string(refused) + "/" + std::to_string(flips));
  }
}

TEST(Laz, RefusesTheChunkTableOffsetPointingElsewhere) {
  const LasFile laz(kInterop + "laz/autzen_trim.laz");
  for (int64_t table : {int64_t{0}, int64_t{1} << 40, int64_t{laz.offset_to_points} + 8}) {
    std::string bad = laz.bytes;
    std::memcpy(bad.data() + laz.offset_to_points, &table, 8);
    EXPECT_THROW(laz.Decode(bad, laz.laszip_payload), InputError) << table;
  }
}

// A writer interrupted before the chunk table leaves its offset pointing at itself: fixed-size chunks are then
// decoded one after the other, variable ones (whose point counts only the table holds) are refused.
TEST(Laz, DecodesFixedSizeChunksWithoutTheChunkTable) {
  const LasFile laz(kInterop + "laz/autzen_trim.laz");
  const LasFile las(kInterop + "las/autzen_trim.las");
  ASSERT_GT(las.count, 2 * 50000u);  // three chunks
  std::string no_table = laz.bytes;
  const int64_t itself = laz.offset_to_points;
  std::memcpy(no_table.data() + laz.offset_to_points, &itself, 8);
  EXPECT_TRUE(laz.Decode(no_table, laz.laszip_payload) == las.Records());
  const LasFile copc(kInterop + "laz/1.2-with-color.copc.laz");
  std::string copc_no_table = copc.bytes;
  const int64_t copc_itself = copc.offset_to_points;
  std::memcpy(copc_no_table.data() + copc.offset_to_points, &copc_itself, 8);
  try {
    copc.Decode(copc_no_table, copc.laszip_payload);
    ADD_FAILURE() << "variable chunks without a table were decoded";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("variable"), std::string::npos) << e.what();
  }
}

TEST(Laz, RefusesBadVlrsAndMismatchedHeaders) {
  const LasFile laz(kInterop + "laz/simple.laz");
  auto with = [&](size_t at, uint16_t value) {
    std::string payload = laz.laszip_payload;
    std::memcpy(payload.data() + at, &value, 2);
    return payload;
  };
  EXPECT_THROW(laz.Decode(laz.bytes, laz.laszip_payload.substr(0, 20)), InputError);  // too short
  EXPECT_THROW(laz.Decode(laz.bytes, with(0, 0)), InputError);                        // compressor 0
  EXPECT_THROW(laz.Decode(laz.bytes, with(0, 3)), InputError);           // layered with point10 items
  EXPECT_THROW(laz.Decode(laz.bytes, with(2, 1)), InputError);           // coder 1
  EXPECT_THROW(laz.Decode(laz.bytes, with(32, 9)), InputError);          // more items than the record holds
  EXPECT_THROW(laz.Decode(laz.bytes, with(34 + 2, 21)), InputError);     // POINT10 of 21 bytes
  EXPECT_THROW(laz.Decode(laz.bytes, with(34 + 6 + 4, 7)), InputError);  // GPSTIME11 version 7
  EXPECT_THROW(laz.Decode(laz.bytes, with(34 + 12, 9)), InputError);     // RGB12 replaced by a wave packet
  // The header's format and record length must match the items.
  EXPECT_THROW(DecodeLazPoints(laz.laszip_payload, laz.bytes, laz.offset_to_points, laz.count, 1,
                               laz.record_length, "f"),
               InputError);
  EXPECT_THROW(DecodeLazPoints(laz.laszip_payload, laz.bytes, laz.offset_to_points, laz.count, 3, 36, "f"),
               InputError);
  // More points than the data could code: refused before the output is allocated.
  try {
    DecodeLazPoints(laz.laszip_payload, laz.bytes, laz.offset_to_points, uint64_t{1} << 40, 3, 34, "f.laz");
    ADD_FAILURE() << "2^40 points were accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("Number of Point Records"), std::string::npos) << e.what();
  }
  // More points than the chunk table holds.
  EXPECT_THROW(
      DecodeLazPoints(laz.laszip_payload, laz.bytes, laz.offset_to_points, laz.count + 1, 3, 34, "f"),
      InputError);
}

bool SameMat(const cv::Mat& a, const cv::Mat& b) {
  return a.empty() == b.empty() &&
         (a.empty() || (a.size == b.size && a.type() == b.type() &&
                        std::memcmp(a.data, b.data, a.total() * a.elemSize()) == 0));
}

// Through the scan reader: a .laz reads as the same scan as its .las twin.
TEST(Laz, ReadScanFileReadsLazAsItsTwin) {
  for (const Pair& pair : kPairs) {
    SCOPED_TRACE(pair.laz);
    const ScanFile laz = ReadScanFile(kInterop + "laz/" + pair.laz);
    const ScanFile las = ReadScanFile(kInterop + "las/" + pair.las);
    EXPECT_EQ(laz.format, "laz");
    ASSERT_EQ(laz.scans.size(), 1u);
    const Scan& a = laz.scans[0];
    const Scan& b = las.scans[0];
    ASSERT_GT(b.CountValid(), 1000);
    EXPECT_EQ(a.CountValid(), b.CountValid());
    EXPECT_TRUE(a.world_from_scanner.isApprox(b.world_from_scanner));
    EXPECT_TRUE(SameMat(a.point, b.point));
    EXPECT_TRUE(SameMat(a.valid, b.valid));
    EXPECT_TRUE(SameMat(a.color, b.color));
    EXPECT_TRUE(SameMat(a.intensity, b.intensity));
    EXPECT_TRUE(SameMat(a.label, b.label));
  }
}

}  // namespace
}  // namespace lidarshop::laz
