// E57 physical pages: CRC-32C and the logical/physical mapping (see e57_format.h).
#include <algorithm>
#include <array>
#include <cstring>
#include <fstream>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fmt/format.h>

#include "lidarshop/io/e57_format.h"
#include "lidarshop/util/error.h"

namespace lidarshop::e57 {
namespace {

// tables[k][b]: CRC of byte b followed by k zero bytes (slicing-by-8, Kounavis & Berry 2008).
struct CrcTables {
  std::array<std::array<uint32_t, 256>, 8> t;
  CrcTables() {
    for (uint32_t b = 0; b < 256; ++b) {
      uint32_t c = b;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? (c >> 1) ^ 0x82F63B78u : c >> 1;
      t[0][b] = c;
    }
    for (uint32_t b = 0; b < 256; ++b) {
      for (int k = 1; k < 8; ++k) t[k][b] = (t[k - 1][b] >> 8) ^ t[0][t[k - 1][b] & 0xFF];
    }
  }
};
const CrcTables& Tables() {
  static const CrcTables tables;
  return tables;
}

}  // namespace

void CheckPageCrc(const std::string& path, const uint8_t* page, uint64_t page_index) {
  const uint32_t stored = (uint32_t{page[1020]} << 24) | (uint32_t{page[1021]} << 16) |
                          (uint32_t{page[1022]} << 8) | uint32_t{page[1023]};
  const uint32_t computed = Crc32c(page, kPagePayload);
  if (stored != computed) {
    ThrowInputError(path, fmt::format("page {} (byte offset {})", page_index, page_index * kPageSize),
                    "CRC-32C",
                    fmt::format("checksum mismatch: stored 0x{:08x}, computed 0x{:08x} (corrupt page)",
                                stored, computed));
  }
}

namespace {

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
// SSE 4.2's CRC32 instruction computes CRC-32C itself (the same polynomial, reflected): 8 bytes an instruction,
// several times the tables' speed on the hundreds of MB of a big station's pages.
__attribute__((target("sse4.2"))) uint32_t Crc32cHardware(const uint8_t* data, size_t size,
                                                          uint32_t previous = 0) {
  uint64_t crc = previous ^ 0xFFFFFFFFu;
  while (size >= 8) {
    uint64_t word;
    std::memcpy(&word, data, 8);
    crc = __builtin_ia32_crc32di(crc, word);
    data += 8;
    size -= 8;
  }
  uint32_t crc32 = static_cast<uint32_t>(crc);
  while (size--) crc32 = __builtin_ia32_crc32qi(crc32, *data++);
  return crc32 ^ 0xFFFFFFFFu;
}
bool HasCrc32Instruction() {
  static const bool has = __builtin_cpu_supports("sse4.2");
  return has;
}
#else
uint32_t Crc32cHardware(const uint8_t*, size_t, uint32_t = 0) { return 0; }
bool HasCrc32Instruction() { return false; }
#endif

}  // namespace

uint32_t Crc32cPortable(const uint8_t* data, size_t size) { return Crc32cPortableFrom(0, data, size); }

uint32_t Crc32cPortableFrom(uint32_t previous, const uint8_t* data, size_t size) {
  const auto& t = Tables().t;
  uint32_t crc = previous ^ 0xFFFFFFFFu;
  while (size >= 8) {
    const uint32_t lo = LoadLe<uint32_t>(data) ^ crc;
    const uint32_t hi = LoadLe<uint32_t>(data + 4);
    crc = t[7][lo & 0xFF] ^ t[6][(lo >> 8) & 0xFF] ^ t[5][(lo >> 16) & 0xFF] ^ t[4][lo >> 24] ^
          t[3][hi & 0xFF] ^ t[2][(hi >> 8) & 0xFF] ^ t[1][(hi >> 16) & 0xFF] ^ t[0][hi >> 24];
    data += 8;
    size -= 8;
  }
  while (size--) crc = t[0][(crc ^ *data++) & 0xFF] ^ (crc >> 8);
  return crc ^ 0xFFFFFFFFu;
}

uint32_t Crc32c(const uint8_t* data, size_t size) { return Crc32cExtend(0, data, size); }

uint32_t Crc32cExtend(uint32_t crc, const uint8_t* data, size_t size) {
  return HasCrc32Instruction() ? Crc32cHardware(data, size, crc) : Crc32cPortableFrom(crc, data, size);
}

void LogicalSink::Keep(const uint8_t* data, size_t n) {
  crc_ = Crc32cExtend(crc_, data, n);
  const size_t ring = tail_.size();
  const size_t skip = n > ring ? n - ring : 0;
  for (size_t i = skip; i < n; ++i) tail_[(size_ + i) % ring] = data[i];
  size_ += n;
}

uint32_t LogicalSink::TailCrc(size_t n) const {
  LIDARSHOP_CHECK(n <= tail_.size());
  n = static_cast<size_t>(std::min<uint64_t>(n, size_));
  std::vector<uint8_t> last(n);
  for (size_t i = 0; i < n; ++i) last[i] = tail_[(size_ - n + i) % tail_.size()];
  return Crc32c(last.data(), n);
}

namespace {

// A page of `n` <= kPagePayload payload bytes, zero-padded, with its CRC, into `page` (kPageSize bytes).
void MakePage(const uint8_t* payload, size_t n, uint8_t* page) {
  std::memset(page, 0, kPageSize);
  if (n) std::memcpy(page, payload, n);
  const uint32_t crc = Crc32c(page, kPagePayload);
  page[1020] = crc >> 24;
  page[1021] = (crc >> 16) & 0xFF;
  page[1022] = (crc >> 8) & 0xFF;
  page[1023] = crc & 0xFF;
}

}  // namespace

void LogicalSink::WritePage(uint64_t index, const uint8_t* payload, size_t n) {
  uint8_t page[kPageSize];
  MakePage(payload, n, page);
  if (index == 0) pages_->seekp(0);  // the other pages follow each other
  pages_->write(reinterpret_cast<const char*>(page), kPageSize);
}

void LogicalSink::Append(const uint8_t* data, size_t n) {
  if (memory_ != nullptr) {
    memory_->insert(memory_->end(), data, data + n);
    Keep(data, n);
    return;
  }
  while (n > 0) {
    std::vector<uint8_t>& target = size_ < kPagePayload ? first_page_ : page_;
    const size_t take = std::min<size_t>(n, kPagePayload - size_ % kPagePayload);
    target.insert(target.end(), data, data + take);
    Keep(data, take);
    data += take;
    n -= take;
    if (size_ % kPagePayload == 0 && size_ > kPagePayload) {  // a full page past page 0
      WritePage(size_ / kPagePayload - 1, page_.data(), page_.size());
      page_.clear();
    }
  }
}

void LogicalSink::AppendZeros(size_t n) {
  const uint8_t zeros[64] = {};
  while (n > 0) {
    const size_t take = std::min<size_t>(n, sizeof(zeros));
    Append(zeros, take);
    n -= take;
  }
}

void LogicalSink::StoreFileHeader(const Header& header) {
  std::vector<uint8_t>& target = memory_ != nullptr ? *memory_ : first_page_;
  LIDARSHOP_CHECK(target.size() >= kHeaderSize);
  e57::StoreHeader(header, target.data());
}

void LogicalSink::Finish() {
  if (memory_ != nullptr) return;
  if (!page_.empty()) WritePage((size_ - 1) / kPagePayload, page_.data(), page_.size());
  WritePage(0, first_page_.data(), first_page_.size());
  pages_->seekp(0, std::ios::end);
}

namespace {

// Throws unless `size` bytes are a whole, non-zero number of pages.
void CheckWholePages(const std::string& path, uint64_t size) {
  if (size < kPageSize || size % kPageSize != 0) {
    ThrowInputError(
        path, fmt::format("file size {} bytes", size), "",
        fmt::format("not a whole number of {}-byte E57 pages (truncated or not an E57 file)", kPageSize));
  }
}

// Checks the CRCs of `count` pages starting with page `first` and copies their payloads to `logical`.
void CopyPayloads(const std::string& path, const uint8_t* pages, uint64_t first, uint64_t count,
                  uint8_t* logical) {
  for (uint64_t p = 0; p < count; ++p) {
    const uint8_t* page = pages + p * kPageSize;
    CheckPageCrc(path, page, first + p);
    std::memcpy(logical + (first + p) * kPagePayload, page, kPagePayload);
  }
}

uint64_t PageCount(const std::vector<uint8_t>& logical) {
  return std::max<uint64_t>(1, (logical.size() + kPagePayload - 1) / kPagePayload);
}

constexpr uint64_t kPagesPerChunk = 1024;  // 1 MiB of file read at a time when a file is opened

}  // namespace

std::vector<uint8_t> LogicalFromPages(const std::string& path, const std::vector<uint8_t>& physical) {
  CheckWholePages(path, physical.size());
  const uint64_t pages = physical.size() / kPageSize;
  std::vector<uint8_t> logical(pages * kPagePayload);
  CopyPayloads(path, physical.data(), 0, pages, logical.data());
  return logical;
}

LogicalBytes LogicalBytes::OpenFile(const std::string& path) {
  LogicalBytes bytes;
  bytes.path_ = path;
  bytes.fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (bytes.fd_ < 0) ThrowInputError(path, "", "", "cannot open for reading");
  struct stat info {};
  if (::fstat(bytes.fd_, &info) != 0) ThrowInputError(path, "", "", "cannot determine the file size");
  const uint64_t size = static_cast<uint64_t>(info.st_size);
  CheckWholePages(path, size);
  const uint64_t pages = size / kPageSize;
  std::vector<uint8_t> chunk(std::min(pages, kPagesPerChunk) * kPageSize);
  for (uint64_t first = 0; first < pages; first += kPagesPerChunk) {
    const uint64_t count = std::min(kPagesPerChunk, pages - first);
    const ssize_t got =
        ::pread(bytes.fd_, chunk.data(), count * kPageSize, static_cast<off_t>(first * kPageSize));
    if (got != static_cast<ssize_t>(count * kPageSize)) {
      ThrowInputError(path, fmt::format("page {} (byte offset {})", first, first * kPageSize), "",
                      "read failed (the file changed while it was read?)");
    }
    for (uint64_t p = 0; p < count; ++p) CheckPageCrc(path, chunk.data() + p * kPageSize, first + p);
  }
  bytes.size_ = pages * kPagePayload;
  return bytes;
}

LogicalBytes::LogicalBytes(LogicalBytes&& other) noexcept
    : path_(std::move(other.path_)), memory_(std::move(other.memory_)), fd_(other.fd_), size_(other.size_) {
  other.fd_ = -1;
}

LogicalBytes::~LogicalBytes() {
  if (fd_ >= 0) ::close(fd_);
}

void LogicalBytes::Read(uint64_t offset, uint64_t n, uint8_t* out) const {
  if (n == 0) return;
  LIDARSHOP_CHECK(offset <= size_ && n <= size_ - offset);
  if (fd_ < 0) {
    std::memcpy(out, memory_.data() + offset, n);
    return;
  }
  const uint64_t first = offset / kPagePayload, last = (offset + n - 1) / kPagePayload;
  pages_.resize((last - first + 1) * kPageSize);
  const ssize_t got = ::pread(fd_, pages_.data(), pages_.size(), static_cast<off_t>(first * kPageSize));
  if (got != static_cast<ssize_t>(pages_.size())) {
    ThrowInputError(path_, fmt::format("page {} (byte offset {})", first, first * kPageSize), "",
                    "read failed (the file changed while it was read?)");
  }
  uint64_t at = offset;
  for (uint64_t p = first; p <= last; ++p) {
    const uint8_t* page = pages_.data() + (p - first) * kPageSize;
    CheckPageCrc(path_, page, p);
    const uint64_t from = at - p * kPagePayload;
    const uint64_t take = std::min(kPagePayload - from, offset + n - at);
    std::memcpy(out + (at - offset), page + from, take);
    at += take;
  }
}

std::vector<uint8_t> PagesFromLogical(const std::vector<uint8_t>& logical) {
  const uint64_t pages = PageCount(logical);
  std::vector<uint8_t> physical(pages * kPageSize);
  for (uint64_t p = 0; p < pages; ++p) {
    const size_t begin = p * kPagePayload;
    const size_t n = std::min<size_t>(kPagePayload, logical.size() - std::min(begin, logical.size()));
    MakePage(logical.data() + begin, n, physical.data() + p * kPageSize);
  }
  return physical;
}

Header ParseHeader(const std::string& path, const std::vector<uint8_t>& logical) {
  if (logical.size() < kHeaderSize) ThrowInputError(path, "byte offset 0", "header", "shorter than 48 bytes");
  Header h;
  std::memcpy(h.signature, logical.data(), 8);
  if (std::memcmp(h.signature, "ASTM-E57", 8) != 0) {
    ThrowInputError(path, "byte offset 0", "fileSignature", "not 'ASTM-E57': not an E57 file");
  }
  h.major_version = LoadLe<uint32_t>(logical.data() + 8);
  h.minor_version = LoadLe<uint32_t>(logical.data() + 12);
  h.file_physical_length = LoadLe<uint64_t>(logical.data() + 16);
  h.xml_physical_offset = LoadLe<uint64_t>(logical.data() + 24);
  h.xml_logical_length = LoadLe<uint64_t>(logical.data() + 32);
  h.page_size = LoadLe<uint64_t>(logical.data() + 40);
  if (h.major_version != 1) {
    ThrowInputError(path, "byte offset 8", "majorVersion",
                    fmt::format("unsupported E57 major version {} (expected 1)", h.major_version));
  }
  if (h.page_size != kPageSize) {
    ThrowInputError(path, "byte offset 40", "pageSize",
                    fmt::format("{} (only 1024 is defined)", h.page_size));
  }
  return h;
}

std::string ElementPath(pugi::xml_node node) {
  std::string p;
  for (pugi::xml_node n = node; n && n.type() == pugi::node_element; n = n.parent()) {
    p = p.empty() ? std::string(n.name()) : std::string(n.name()) + "/" + p;
  }
  return p;
}

void CheckXmlUtf8(const std::string& path, const char* xml, size_t size) {
  const auto* b = reinterpret_cast<const uint8_t*>(xml);
  for (size_t i = 0; i < size;) {
    const uint8_t c = b[i];
    if (c < 0x80) {
      ++i;
      continue;
    }
    // The length of the sequence and the range of its second byte (no overlong forms, no surrogates, at most
    // U+10FFFF: RFC 3629's table).
    const int length = c >= 0xc2 && c <= 0xdf   ? 2
                       : c >= 0xe0 && c <= 0xef ? 3
                       : c >= 0xf0 && c <= 0xf4 ? 4
                                                : 0;
    const uint8_t low = c == 0xe0 ? 0xa0 : c == 0xf0 ? 0x90 : 0x80;
    const uint8_t high = c == 0xed ? 0x9f : c == 0xf4 ? 0x8f : 0xbf;
    bool valid = length > 0 && i + length <= size && b[i + 1] >= low && b[i + 1] <= high;
    for (int k = 2; valid && k < length; ++k) valid = b[i + k] >= 0x80 && b[i + k] <= 0xbf;
    if (!valid) {
      ThrowInputError(path, fmt::format("XML section, byte {}", i), "",
                      fmt::format("byte 0x{:02x} is not UTF-8 (E57 XML is UTF-8; a Latin-1 name?)", c));
    }
    i += length;
  }
}

void StoreHeader(const Header& h, uint8_t* out) {
  std::memcpy(out, h.signature, 8);
  std::memcpy(out + 8, &h.major_version, 4);
  std::memcpy(out + 12, &h.minor_version, 4);
  std::memcpy(out + 16, &h.file_physical_length, 8);
  std::memcpy(out + 24, &h.xml_physical_offset, 8);
  std::memcpy(out + 32, &h.xml_logical_length, 8);
  std::memcpy(out + 40, &h.page_size, 8);
}

}  // namespace lidarshop::e57
