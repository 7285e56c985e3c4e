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

namespace {

// Records per packet so that every packet (header + one chunk per stream of `bits` per value + rounding) fits
// in 64 KiB.
int64_t RecordsPerPacket(const std::vector<int>& bits, int64_t record_count) {
  const uint64_t n = bits.size();
  uint64_t bits_per_record = 0;
  for (int b : bits) bits_per_record += static_cast<uint64_t>(b);
  const uint64_t budget = kMaxPacketSize - 6 - 2 * n - n - 4;
  return bits_per_record == 0 ? std::max<int64_t>(record_count, 1)
                              : std::max<int64_t>(1, static_cast<int64_t>(budget * 8 / bits_per_record));
}

}  // namespace

uint64_t AppendCompressedVector(const std::vector<Stream>& streams, int64_t record_count,
                                std::vector<uint8_t>* logical) {
  while (logical->size() % 8) logical->push_back(0);
  const uint64_t start = logical->size();
  logical->resize(start + 32, 0);
  (*logical)[start] = 1;  // sectionId: compressed vector
  const uint64_t data_start = logical->size();
  const size_t n = streams.size();
  std::vector<int> bits(n);
  for (size_t i = 0; i < n; ++i) bits[i] = streams[i].field.bits;
  const int64_t per_packet = RecordsPerPacket(bits, record_count);
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

uint64_t AppendCompressedVector(const std::vector<StreamSource>& sources, int64_t record_count,
                                LogicalSink* sink) {
  // The same layout as the version above (its packets, byte for byte), with each stream packed only as far as
  // the packet being written needs.
  sink->AlignTo8();
  const uint64_t start = sink->size();
  const size_t n = sources.size();
  std::vector<int> bits(n);
  for (size_t i = 0; i < n; ++i) bits[i] = sources[i].field.bits;
  const int64_t per_packet = RecordsPerPacket(bits, record_count);
  std::vector<uint64_t> total(n);
  for (size_t i = 0; i < n; ++i) {
    total[i] = (static_cast<uint64_t>(record_count) * sources[i].field.bits + 7) / 8;
  }
  auto byte_at = [&](size_t i, int64_t record) {
    return std::min<uint64_t>(total[i], (static_cast<uint64_t>(record) * sources[i].field.bits + 7) / 8);
  };
  auto chunk = [&](size_t i, int64_t first, int64_t last) {
    return std::make_pair(byte_at(i, first), last >= record_count ? total[i] : byte_at(i, last));
  };
  const int64_t packets_end = std::max<int64_t>(record_count, 1);
  auto packet_length = [&](int64_t first, int64_t last) {
    uint64_t length = 6 + 2 * n;
    for (size_t i = 0; i < n; ++i) {
      const auto [b, e] = chunk(i, first, last);
      length += e - b;
    }
    return (length + 3) / 4 * 4;
  };
  // The section's length goes in its header, before the packets.
  uint64_t section_length = 32;
  for (int64_t first = 0; first < packets_end; first += per_packet) {
    section_length += packet_length(first, std::min(record_count, first + per_packet));
  }
  uint8_t header[32] = {};
  header[0] = 1;  // sectionId: compressed vector
  const uint64_t data_physical = PhysicalFromLogical(start + 32);
  std::memcpy(header + 8, &section_length, 8);
  std::memcpy(header + 16, &data_physical, 8);
  sink->Append(header, sizeof(header));

  std::vector<BitWriter> writers;
  for (const StreamSource& s : sources) writers.emplace_back(s.field.bits);
  std::vector<int64_t> fed(n, 0);
  std::vector<uint8_t> packet;
  for (int64_t first = 0; first < packets_end; first += per_packet) {
    const int64_t last = std::min(record_count, first + per_packet);
    const uint64_t length = packet_length(first, last);
    LIDARSHOP_CHECK(length <= kMaxPacketSize);
    packet.assign(6 + 2 * n, 0);
    packet[0] = 1;  // data packet
    const uint16_t length_minus_1 = static_cast<uint16_t>(length - 1);
    std::memcpy(packet.data() + 2, &length_minus_1, 2);
    const uint16_t count = static_cast<uint16_t>(n);
    std::memcpy(packet.data() + 4, &count, 2);
    for (size_t i = 0; i < n; ++i) {
      const auto [b, e] = chunk(i, first, last);
      const uint16_t bytes = static_cast<uint16_t>(e - b);
      std::memcpy(packet.data() + 6 + 2 * i, &bytes, 2);
    }
    for (size_t i = 0; i < n; ++i) {
      const auto [b, e] = chunk(i, first, last);
      if (e == b) continue;
      BitWriter& writer = writers[i];
      if (writer.available() < e - b && fed[i] < record_count) {
        // Whole bytes up to e need the records whose bits reach 8e (the byte at e holds the next record's).
        const uint64_t bits = static_cast<uint64_t>(sources[i].field.bits);
        const int64_t target =
            std::min<int64_t>(record_count, static_cast<int64_t>((8 * e + bits - 1) / bits));
        sources[i].put(fed[i], target - fed[i], &writer);
        fed[i] = target;
        if (fed[i] == record_count) writer.FlushPartialByte();
      }
      const size_t at = packet.size();
      packet.resize(at + (e - b));
      writer.TakeFront(e - b, packet.data() + at);
    }
    packet.resize(length, 0);
    sink->Append(packet.data(), packet.size());
  }
  return PhysicalFromLogical(start);
}

}  // namespace lidarshop::e57
