// The byte layout of LAS 1.0-1.4 (ASPRS LAS 1.4 R15, tables 3-4 and 7-16), shared by the reader, the
// writer and the tests (internal to the io module). Every field is little-endian.
#pragma once

#include <bit>
#include <cstdint>
#include <cstring>
#include <string>

namespace lidarshop::las {

static_assert(std::endian::native == std::endian::little,
              "the LAS code copies little-endian fields as they are");

// Public header block: byte offsets of its fields.
namespace header {
constexpr int kSignature = 0;  // "LASF"
constexpr int kFileSourceId = 4;
constexpr int kGlobalEncoding = 6;
constexpr int kVersionMajor = 24;
constexpr int kVersionMinor = 25;
constexpr int kSystemIdentifier = 26;    // 32 chars
constexpr int kGeneratingSoftware = 58;  // 32 chars
constexpr int kCreationDay = 90;
constexpr int kCreationYear = 92;
constexpr int kHeaderSize = 94;             // uint16
constexpr int kOffsetToPointData = 96;      // uint32
constexpr int kNumberOfVlrs = 100;          // uint32
constexpr int kPointFormat = 104;           // uint8
constexpr int kPointRecordLength = 105;     // uint16
constexpr int kLegacyPointCount = 107;      // uint32
constexpr int kLegacyPointsByReturn = 111;  // 5 x uint32
constexpr int kScale = 131;                 // 3 x double (x y z)
constexpr int kOffset = 155;                // 3 x double
constexpr int kMaxX = 179;                  // max x, min x, max y, min y, max z, min z (doubles)
constexpr int kWaveformStart = 227;         // uint64, LAS 1.3+
constexpr int kFirstEvlr = 235;             // uint64, LAS 1.4
constexpr int kNumberOfEvlrs = 243;         // uint32
constexpr int kPointCount = 247;            // uint64
constexpr int kPointsByReturn = 255;        // 15 x uint64
}  // namespace header

// The header size of each minor version (1.0-1.2 / 1.3 / 1.4).
constexpr int kHeaderSize12 = 227;
constexpr int kHeaderSize13 = 235;
constexpr int kHeaderSize14 = 375;
constexpr int kVlrHeaderSize = 54;
constexpr int kEvlrHeaderSize = 60;
// Variable length record header (54 bytes; EVLRs: 60, the length a uint64 at byte 20).
namespace vlr {
constexpr int kUserId = 2;         // 16 chars
constexpr int kRecordId = 18;      // uint16
constexpr int kRecordLength = 20;  // uint16 (EVLR: uint64)
constexpr int kDescription = 22;   // 32 chars (EVLR: at 28)
}  // namespace vlr

// Global encoding bit 4: the coordinate reference system is WKT (required with point formats 6-10).
constexpr uint16_t kGlobalEncodingWkt = 1 << 4;

// Point format byte bits 7 and 6: set by LASzip on compressed (LAZ) files.
constexpr uint8_t kLazFormatBits = 0xC0;

// Size of the point record of `format` (0-10), without extra bytes; 0 for formats that do not exist.
inline int PointRecordSize(int format) {
  constexpr int kSizes[] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
  return format >= 0 && format <= 10 ? kSizes[format] : 0;
}
inline bool IsLegacyFormat(int format) { return format <= 5; }  // 0-5: 5-bit classes, 3-bit returns
inline bool HasGpsTime(int format) { return format != 0 && format != 2; }
inline bool HasNir(int format) { return format == 8 || format == 10; }
constexpr int kNirOffset = 36;  // formats 8 and 10
// Global encoding bit 0: GPS time is adjusted standard GPS time (else GPS week time).
constexpr uint16_t kGlobalEncodingGpsStandard = 1 << 0;
inline bool HasRgb(int format) {
  return format == 2 || format == 3 || format == 5 || format == 7 || format == 8 || format == 10;
}
// Byte offset of R in a point record (formats with RGB).
inline int RgbOffset(int format) {
  switch (format) {
    case 2:
      return 20;
    case 3:
    case 5:
      return 28;
    default:
      return 30;  // 7, 8, 10
  }
}

// Point record fields shared by every format.
namespace point {
constexpr int kX = 0;  // 3 x int32
constexpr int kIntensity = 12;
constexpr int kReturnByte = 14;  // 0-5: return 3 bits, returns 3 bits; 6-10: return 4 bits, returns 4 bits
// 0-5: classification byte (bits 0-4 class, bit 5 synthetic, 6 key-point, 7 withheld)
// 6-10: classification flags (bit 0 synthetic, 1 key-point, 2 withheld, 3 overlap), channel, scan flags
constexpr int kClassByte = 15;
constexpr int kClass14 = 16;  // 6-10: classification (0-255)
constexpr uint8_t kLegacySyntheticBit = 1 << 5;
constexpr uint8_t kLegacyClassMask = 0x1F;
constexpr uint8_t kSyntheticFlag14 = 1 << 0;
constexpr int kScanAngleRank = 16;        // 0-5: int8, degrees
constexpr int kUserDataLegacy = 17;       // 0-5
constexpr int kUserData14 = 17;           // 6-10
constexpr int kScanAngle14 = 18;          // 6-10: int16, 0.006 degrees
constexpr int kPointSourceIdLegacy = 18;  // 0-5
constexpr int kPointSourceId14 = 20;      // 6-10
constexpr int kGpsTimeLegacy = 20;        // 1, 3, 4, 5
constexpr int kGpsTime14 = 22;            // 6-10
}  // namespace point

template <typename T>
T Load(const char* p) {
  T value;
  std::memcpy(&value, p, sizeof(T));
  return value;
}
template <typename T>
void Store(char* p, T value) {
  std::memcpy(p, &value, sizeof(T));
}

}  // namespace lidarshop::las
