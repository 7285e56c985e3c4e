// The writer's binary sections: compressed vectors of bit-packed bytestreams (see e57_format.h).
#include <algorithm>
#include <cstring>

#include "lidarshop/io/e57_format.h"
#include "lidarshop/util/error.h"

namespace lidarshop::e57 {

Field IntegerField(const char* name, int64_t minimum, int64_t maximum) {
  Field f;
  f.name = name;
  f.type = Field::Type::kInteger;
  f.minimum = minimum;
  f.maximum = maximum;
  f.bits = BitsForRange(minimum, maximum);
  return f;
}

uint64_t AppendCompressedVector(const std::vector<Stream>& streams, int64_t record_count,
                                std::vector<uint8_t>* logical) {
  while (logical->size() % 8) logical->push_back(0);
  const uint64_t start = logical->size();
  logical->resize(start + 32, 0);
  (*logical)[start] = 1;  // sectionId: compressed vector
  const uint64_t data_start = logical->size();
  const size_t n = streams.size();
  uint64_t bits_per_record = 0;
  for (const Stream& s : streams) bits_per_record += s.field.bits;
  // Records per packet so that every packet (header + one chunk per stream + rounding) fits in 64 KiB.
  const uint64_t budget = kMaxPacketSize - 6 - 2 * n - n - 4;
  const int64_t per_packet = bits_per_record == 0
                                 ? std::max<int64_t>(record_count, 1)
                                 : std::max<int64_t>(1, static_cast<int64_t>(budget * 8 / bits_per_record));
  auto byte_at = [&](const Stream& s, int64_t record) {
    return std::min<uint64_t>(s.bytes.size(), (static_cast<uint64_t>(record) * s.field.bits + 7) / 8);
  };
  for (int64_t first = 0; first < std::max<int64_t>(record_count, 1); first += per_packet) {
    const int64_t last = std::min(record_count, first + per_packet);
    const uint64_t packet_start = logical->size();
    logical->push_back(1);           // data packet
    logical->push_back(0);           // flags
    AppendLe<uint16_t>(logical, 0);  // length - 1, patched below
    AppendLe<uint16_t>(logical, static_cast<uint16_t>(n));
    std::vector<std::pair<uint64_t, uint64_t>> ranges(n);
    for (size_t i = 0; i < n; ++i) {
      // The last packet takes whatever is left (the final partial byte).
      const uint64_t b = byte_at(streams[i], first);
      const uint64_t e = last >= record_count ? streams[i].bytes.size() : byte_at(streams[i], last);
      ranges[i] = {b, e};
      AppendLe<uint16_t>(logical, static_cast<uint16_t>(e - b));
    }
    for (size_t i = 0; i < n; ++i) {
      logical->insert(logical->end(), streams[i].bytes.begin() + ranges[i].first,
                      streams[i].bytes.begin() + ranges[i].second);
    }
    while ((logical->size() - packet_start) % 4) logical->push_back(0);
    const uint64_t length = logical->size() - packet_start;
    LIDARSHOP_CHECK(length <= kMaxPacketSize);
    const uint16_t length_minus_1 = static_cast<uint16_t>(length - 1);
    std::memcpy(logical->data() + packet_start + 2, &length_minus_1, 2);
  }
  const uint64_t section_length = logical->size() - start;
  const uint64_t data_physical = PhysicalFromLogical(data_start);
  const uint64_t index_physical = 0;
  std::memcpy(logical->data() + start + 8, &section_length, 8);
  std::memcpy(logical->data() + start + 16, &data_physical, 8);
  std::memcpy(logical->data() + start + 24, &index_physical, 8);
  return PhysicalFromLogical(start);
}

}  // namespace lidarshop::e57
