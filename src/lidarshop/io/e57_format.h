// Internals of the E57 (ASTM E2807) reader and writer, shared by e57_*.cc and their tests. Not a public
// contract: use io/e57.h.
//
// An E57 file is a sequence of 1024-byte *physical* pages; each page holds 1020 bytes of payload followed by
// the CRC-32C (Castagnoli) of those bytes, stored big-endian. Removing the checksums gives the *logical* byte
// stream, in which everything else lives: the 48-byte header, binary sections (blobs, compressed vectors) and
// the XML section. Offsets in the header and in the XML are physical; lengths are logical.
//
// A compressed vector section holds data packets; each packet carries one chunk of every bytestream (one
// bytestream per terminal field of the prototype, in depth-first order). A bytestream is the concatenation of
// its chunks over all packets and holds the field's values bit-packed little-endian, LSB first: an Integer /
// ScaledInteger field in [min, max] takes ceil(log2(max - min + 1)) bits and stores value - min; a Float
// field takes 32 or 64 bits (IEEE).
#pragma once

#include <cstdint>
#include <cstring>
#include <functional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include <pugixml.hpp>

namespace lidarshop::e57 {

constexpr uint64_t kPageSize = 1024;     // physical bytes per page
constexpr uint64_t kPagePayload = 1020;  // logical bytes per page (the CRC takes the last 4)
constexpr uint64_t kHeaderSize = 48;
constexpr uint64_t kMaxPacketSize = 65536;  // logical bytes per packet (16-bit length minus one)
constexpr int kMaxPrototypeFields = 4096;   // more bytestreams than this is a corrupt file

// How the writer spells lidarshop's extension (e57.h, kLidarshopE57Namespace). The reader looks the prefix up
// by the namespace URI instead, as a file may bind it to another prefix.
constexpr char kExtensionXmlns[] = "xmlns:lidarshop";
constexpr char kSynthesizedField[] = "lidarshop:synthesized";
constexpr char kSynthesizedLocalName[] = "synthesized";
// Scan::from_station (Integer 0..255: 1 + the index of the station a cell's return was taken from, 0 = not).
constexpr char kFromStationField[] = "lidarshop:fromStation";
constexpr char kFromStationLocalName[] = "fromStation";
// The rays of a scan's cells without a return (e57.h): a Structure under the data3D entry holding a `points`
// CompressedVector of rowIndex, columnIndex and the unit ray as cartesianX/Y/Z.
constexpr char kNoReturnDirectionsField[] = "lidarshop:noReturnDirections";
constexpr char kNoReturnDirectionsLocalName[] = "noReturnDirections";
// A scan's angular grid (e57.h): a Structure under the data3D entry holding `azimuth` (one double Float per
// columnIndex) and `elevation` (one per rowIndex), radians in lidarshop's scanner frame, and `fitted` (0 / 1).
constexpr char kAngularGridField[] = "lidarshop:angularGrid";
constexpr char kAngularGridLocalName[] = "angularGrid";

// The largest record count or grid (cells) a file may claim; kMaxScanCells unless lowered (the fuzzer does,
// to keep its memory bounded). Not thread-safe to change while reading.
extern int64_t g_max_cells;

// CRC-32C (Castagnoli, reflected polynomial 0x82F63B78): SSE 4.2's CRC32 instruction where the CPU has it,
// else Crc32cPortable (slicing-by-8); the same value either way (e57_writer_test).
uint32_t Crc32c(const uint8_t* data, size_t size);
uint32_t Crc32cPortable(const uint8_t* data, size_t size);
uint32_t Crc32cPortableFrom(uint32_t previous, const uint8_t* data, size_t size);

// Checks one physical page's stored CRC against its payload; throws InputError naming `path`, the page index
// and its byte offset on a mismatch.
void CheckPageCrc(const std::string& path, const uint8_t* page, uint64_t page_index);

inline uint64_t LogicalFromPhysical(uint64_t physical) {
  return physical / kPageSize * kPagePayload + physical % kPageSize;
}
inline uint64_t PhysicalFromLogical(uint64_t logical) {
  return logical / kPagePayload * kPageSize + logical % kPagePayload;
}

// Verifies every page's CRC and returns the logical bytes. Throws InputError naming `path`, the page index
// and its byte offset when a checksum does not match or the size is not whole pages.
std::vector<uint8_t> LogicalFromPages(const std::string& path, const std::vector<uint8_t>& physical);

// The logical bytes of an E57 file, held in memory or read from the file a range at a time. Opening a file
// checks every page's CRC, as reading it whole does, without keeping the bytes; each later read checks its
// pages again, so a file changed meanwhile is refused rather than misread. A station's E57 is gigabytes: the
// reader holds the ranges it decodes, not the file. Not thread-safe (one reader at a time).
class LogicalBytes {
 public:
  explicit LogicalBytes(std::vector<uint8_t> logical) : memory_(std::move(logical)), size_(memory_.size()) {}
  // Throws InputError naming `path` (and the page) when it cannot be read or a checksum does not match.
  static LogicalBytes OpenFile(const std::string& path);
  LogicalBytes(LogicalBytes&& other) noexcept;
  LogicalBytes& operator=(LogicalBytes&&) = delete;
  LogicalBytes(const LogicalBytes&) = delete;
  ~LogicalBytes();

  uint64_t size() const { return size_; }
  // Copies bytes [offset, offset + n) to `out`; the range must lie within size() (callers check offsets
  // taken from the file first).
  void Read(uint64_t offset, uint64_t n, uint8_t* out) const;
  std::vector<uint8_t> Bytes(uint64_t offset, uint64_t n) const {
    std::vector<uint8_t> bytes(n);
    Read(offset, n, bytes.data());
    return bytes;
  }
  template <typename T>
  T Load(uint64_t offset) const {
    T value;
    Read(offset, sizeof(T), reinterpret_cast<uint8_t*>(&value));  // little-endian, as LoadLe
    return value;
  }

 private:
  LogicalBytes() = default;
  std::string path_;
  std::vector<uint8_t> memory_;
  int fd_ = -1;
  uint64_t size_ = 0;
  mutable std::vector<uint8_t> pages_;  // scratch for the pages of one read
};

// E57's XML is UTF-8 (E2807 8.4): throws InputError naming `path` and the byte of the XML section where the
// `size` bytes at `xml` are not (a Latin-1 scan name), before pugixml, which does not check, passes them on
// to JSON output and written files.
void CheckXmlUtf8(const std::string& path, const char* xml, size_t size);

// The element names from the document's root down to `node`, joined by '/': where an XML error is.
std::string ElementPath(pugi::xml_node node);

// Splits logical bytes into pages with their CRCs (the last page is zero-padded).
std::vector<uint8_t> PagesFromLogical(const std::vector<uint8_t>& logical);

// The 48-byte file header.
struct Header {
  char signature[8] = {'A', 'S', 'T', 'M', '-', 'E', '5', '7'};
  uint32_t major_version = 1;
  uint32_t minor_version = 0;
  uint64_t file_physical_length = 0;
  uint64_t xml_physical_offset = 0;
  uint64_t xml_logical_length = 0;
  uint64_t page_size = kPageSize;
};
Header ParseHeader(const std::string& path, const std::vector<uint8_t>& logical);
void StoreHeader(const Header& header, uint8_t* out48);

template <typename T>
inline T LoadLe(const uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));  // E57 is little-endian; so is every machine we build for
  return v;
}
template <typename T>
inline void AppendLe(std::vector<uint8_t>* out, T v) {
  const size_t at = out->size();
  out->resize(at + sizeof(T));
  std::memcpy(out->data() + at, &v, sizeof(T));
}

// One terminal field of a compressed vector's prototype.
struct Field {
  enum class Type { kInteger, kScaledInteger, kFloat, kDouble };
  std::string name;  // top-level element name, e.g. "cartesianX" (nested ones: "parent/child")
  Type type = Type::kInteger;
  int64_t minimum = 0;  // Integer / ScaledInteger
  int64_t maximum = 0;
  double scale = 1.0;  // ScaledInteger: value = raw * scale + offset
  double offset = 0.0;
  int bits = 0;  // bits per value in the bytestream
};

// Bits needed for an integer in [minimum, maximum] (0 when minimum == maximum).
int BitsForRange(int64_t minimum, int64_t maximum);

// Throws InputError (naming `where`) when a bytestream of `stream_size` bytes holds fewer than `count` values
// of `field`.
void CheckStreamHolds(const Field& field, uint64_t stream_size, int64_t count, const std::string& where);

// Decodes `count` values of `field` from its bytestream into `out` (as doubles: scaled integers are scaled).
// Throws InputError (naming `where`) when the stream holds fewer values.
void DecodeField(const Field& field, const uint8_t* stream, size_t stream_size, int64_t count, double* out,
                 const std::string& where);

// Bit-packs raw values (integers already offset by nothing: pass the integer
// itself, minimum is subtracted here).
class BitWriter {
 public:
  explicit BitWriter(int bits) : bits_(bits) {}
  // Room for `values` values of the writer's width (no reallocation while they are put).
  void Reserve(int64_t values) { bytes_.reserve(static_cast<size_t>((values * bits_ + 7) / 8)); }
  void PutInteger(int64_t value, int64_t minimum);
  void PutFloat(float value) { PutRaw(BitsOf(value), 32); }
  void PutDouble(double value) { PutRaw(BitsOf(value), 64); }
  // The stream, flushed to whole bytes.
  std::vector<uint8_t> Finish();
  // Streaming use: the whole bytes packed and not yet taken, the last partial byte flushed (once all values
  // are put), and the first `n` of them moved to `out`.
  size_t available() const { return bytes_.size(); }
  void FlushPartialByte();
  void TakeFront(size_t n, uint8_t* out);

 private:
  template <typename F>
  static uint64_t BitsOf(F value) {
    if constexpr (sizeof(F) == 4) {
      uint32_t b;
      std::memcpy(&b, &value, 4);
      return b;
    } else {
      uint64_t b;
      std::memcpy(&b, &value, 8);
      return b;
    }
  }
  void PutRaw(uint64_t value, int bits);
  int bits_;
  std::vector<uint8_t> bytes_;
  uint64_t accumulator_ = 0;
  int pending_ = 0;  // bits in accumulator_
};

// Writing (e57_sections.cc). A bytestream the writer has packed, with its prototype field.
struct Stream {
  Field field;
  std::vector<uint8_t> bytes;
};

// An Integer field in [minimum, maximum] with the fewest bits.
Field IntegerField(const char* name, int64_t minimum, int64_t maximum);

// Appends a compressed vector section of `record_count` records at the end of `logical` (8-byte aligned; data
// packets of at most 64 KiB, no index packets) and returns its physical offset.
uint64_t AppendCompressedVector(const std::vector<Stream>& streams, int64_t record_count,
                                std::vector<uint8_t>* logical);

// The logical bytes of a file being written, kept in memory or written to a stream as pages with their CRCs
// as soon as each page is full (page 0, which holds the header, is written last). Keeps the CRC of every byte
// and the last 4096 bytes, which the writer's guids are made of.
class LogicalSink {
 public:
  explicit LogicalSink(std::vector<uint8_t>* memory) : memory_(memory) {
    for (uint8_t b : *memory) Keep(&b, 1);
  }
  // Page 0 is written as zeros first and again at Finish.
  explicit LogicalSink(std::ostream* pages) : pages_(pages) {
    const char zeros[kPageSize] = {};
    pages_->write(zeros, kPageSize);
  }
  uint64_t size() const { return size_; }
  void Append(const uint8_t* data, size_t n);
  void AppendZeros(size_t n);
  void AlignTo8() { AppendZeros((8 - size_ % 8) % 8); }
  uint32_t crc() const { return crc_; }  // Crc32c of every byte appended
  // Crc32c of the last min(n, size()) bytes; n <= 4096.
  uint32_t TailCrc(size_t n) const;
  // Overwrites the first 48 bytes (the file header; written with page 0 at Finish).
  void StoreFileHeader(const Header& header);
  // Writes what is left: the last page (zero-padded) and page 0.
  void Finish();

 private:
  void Keep(const uint8_t* data, size_t n);  // the CRC and the tail
  void WritePage(uint64_t index, const uint8_t* payload, size_t n);
  std::vector<uint8_t>* memory_ = nullptr;
  std::ostream* pages_ = nullptr;
  uint64_t size_ = 0;
  uint32_t crc_ = 0;
  std::vector<uint8_t> tail_ = std::vector<uint8_t>(4096);  // a ring of the last bytes
  std::vector<uint8_t> first_page_;                         // page 0's payload (pages_ only)
  std::vector<uint8_t> page_;                               // the page being filled (pages_ only)
};

// Crc32c of `data` following bytes whose Crc32c was `crc` (0 for none).
uint32_t Crc32cExtend(uint32_t crc, const uint8_t* data, size_t size);

// A bytestream made as the packets take it: `put(first, count, writer)` packs the values of records [first,
// first + count), called in record order. Holds one packet's worth of bytes, not the stream.
struct StreamSource {
  Field field;
  std::function<void(int64_t first, int64_t count, BitWriter* writer)> put;
};

// AppendCompressedVector of streams made as they are written (a station's streams are hundreds of MB).
uint64_t AppendCompressedVector(const std::vector<StreamSource>& sources, int64_t record_count,
                                LogicalSink* sink);

// A data3D entry's metadata that ReadE57 keeps in Scan::source_metadata and the writers write back, so that
// E57 -> edit -> E57 keeps the scan's identity and date: {E57 element, source_metadata key}. The times are
// the DateTime's dateTimeValue (GPS seconds) as text. Without "e57.guid" the writer makes a guid.
inline constexpr std::pair<const char*, const char*> kE57MetadataStrings[] = {
    {"guid", "e57.guid"},
    {"sensorVendor", "e57.sensor_vendor"},
    {"sensorModel", "e57.sensor_model"},
    {"sensorSerialNumber", "e57.sensor_serial_number"}};
inline constexpr std::pair<const char*, const char*> kE57MetadataTimes[] = {
    {"acquisitionStart", "e57.acquisition_start_gps_s"}, {"acquisitionEnd", "e57.acquisition_end_gps_s"}};

}  // namespace lidarshop::e57
