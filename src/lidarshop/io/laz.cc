#include "lidarshop/io/laz.h"

#include <algorithm>
#include <memory>

#include <fmt/format.h>

#include "lidarshop/io/laz_arithmetic.h"
#include "lidarshop/io/laz_items.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/memory_budget.h"

namespace lidarshop::laz {
namespace {

constexpr size_t kVlrFixedBytes = 34;  // the payload before the item list
constexpr uint64_t kMaxPointsPerCompressedByte = 4;

const char* ItemName(uint16_t type) {
  switch (type) {
    case kByte:
      return "BYTE";
    case kPoint10:
      return "POINT10";
    case kGpsTime11:
      return "GPSTIME11";
    case kRgb12:
      return "RGB12";
    case kWavePacket13:
      return "WAVEPACKET13";
    case kPoint14:
      return "POINT14";
    case kRgb14:
      return "RGB14";
    case kRgbNir14:
      return "RGBNIR14";
    case kWavePacket14:
      return "WAVEPACKET14";
    case kByte14:
      return "BYTE14";
    default:
      return nullptr;
  }
}

// The fixed size of an item type; 0 for the byte items, whose size is the number of extra bytes.
int ItemSize(uint16_t type) {
  switch (type) {
    case kPoint10:
      return 20;
    case kGpsTime11:
      return 8;
    case kRgb12:
    case kRgb14:
      return 6;
    case kRgbNir14:
      return 8;
    case kWavePacket13:
    case kWavePacket14:
      return 29;
    case kPoint14:
      return 30;
    default:
      return 0;
  }
}

// The items LASzip writes for `format` (before any extra bytes).
std::vector<uint16_t> ItemsOfFormat(int format) {
  switch (format) {
    case 0:
      return {kPoint10};
    case 1:
      return {kPoint10, kGpsTime11};
    case 2:
      return {kPoint10, kRgb12};
    case 3:
      return {kPoint10, kGpsTime11, kRgb12};
    case 4:
      return {kPoint10, kGpsTime11, kWavePacket13};
    case 5:
      return {kPoint10, kGpsTime11, kRgb12, kWavePacket13};
    case 6:
      return {kPoint14};
    case 7:
      return {kPoint14, kRgb14};
    case 8:
      return {kPoint14, kRgbNir14};
    case 9:
      return {kPoint14, kWavePacket14};
    case 10:
      return {kPoint14, kRgbNir14, kWavePacket14};
    default:
      return {};
  }
}

struct Chunk {
  uint64_t start = 0;  // byte in the file
  uint64_t bytes = 0;
  uint64_t points = 0;    // decoded (the header's count may end the file inside the last chunk)
  uint64_t declared = 0;  // in the chunk table (variable chunks) or the chunk size (fixed)
};

std::string ChunkPlace(size_t chunk, const Chunk& c) {
  return fmt::format("LAZ chunk {} (byte {})", chunk, c.start);
}

// The chunks of a chunked (compressor 2 or 3) file, from the chunk table whose offset is the first 8 bytes of
// the point data; none when the file has no table but fixed-size chunks (decoded one after the other).
std::vector<Chunk> ReadChunkTable(const LazVlr& vlr, std::string_view file_bytes, uint64_t offset,
                                  uint64_t point_count, int record_length, const std::string& file) {
  const uint64_t size = file_bytes.size();
  const auto* data = reinterpret_cast<const uint8_t*>(file_bytes.data());
  if (offset + 8 > size) {
    ThrowInputError(file, fmt::format("byte {}", offset), "LAZ chunk table offset",
                    "truncated: the file ends before the chunk table's offset");
  }
  int64_t table = LoadLe<int64_t>(data + offset);
  const uint64_t chunks_start = offset + 8;
  if (table == -1 && size >= 8)
    table = LoadLe<int64_t>(data + size - 8);  // written last by a streaming writer
  if (table >= 0 && static_cast<uint64_t>(table) + 8 == chunks_start) {
    // The writer was interrupted before it wrote the table: fixed-size chunks can still be decoded one after
    // the other (each ends where its decoder stopped), variable ones not.
    if (vlr.chunk_size != kVariableChunkSize) return {};
    ThrowInputError(file, fmt::format("byte {}", offset), "LAZ chunk table offset",
                    "the file has no chunk table (its writer was interrupted) and its chunks are of variable "
                    "size");
  }
  if (table < 0 || static_cast<uint64_t>(table) < chunks_start || static_cast<uint64_t>(table) + 8 > size) {
    ThrowInputError(file, fmt::format("byte {}", offset), "LAZ chunk table offset",
                    fmt::format("{} is not between the first chunk (byte {}) and the file's end ({})", table,
                                chunks_start, size));
  }
  const uint64_t table_at = static_cast<uint64_t>(table);
  const uint32_t version = LoadLe<uint32_t>(data + table_at);
  if (version != 0) {
    ThrowInputError(file, fmt::format("byte {}", table_at), "LAZ chunk table version",
                    fmt::format("{} (only 0 exists)", version));
  }
  const uint32_t number = LoadLe<uint32_t>(data + table_at + 4);
  // Every chunk holds at least its raw first point.
  if (number == 0 || number > (table_at - chunks_start) / record_length) {
    ThrowInputError(file, fmt::format("byte {}", table_at + 4), "LAZ number of chunks",
                    fmt::format("{} chunks cannot lie in the {} bytes before the chunk table (each holds at "
                                "least one {}-byte point)",
                                number, table_at - chunks_start, record_length));
  }
  const bool variable = vlr.chunk_size == kVariableChunkSize;
  std::vector<Chunk> chunks(number);
  try {
    ArithmeticDecoder decoder;
    decoder.Start(data + table_at + 8, data + size);
    IntegerDecompressor ic(decoder, 32, 2);
    uint32_t last_points = 0, last_bytes = 0;
    uint64_t start = chunks_start;
    for (Chunk& c : chunks) {
      if (variable)
        c.points = last_points = static_cast<uint32_t>(ic.Decompress(static_cast<int32_t>(last_points), 0));
      c.bytes = last_bytes = static_cast<uint32_t>(ic.Decompress(static_cast<int32_t>(last_bytes), 1));
      c.start = start;
      start += c.bytes;
    }
  } catch (const LazCorrupt& e) {
    ThrowInputError(file, fmt::format("byte {}", table_at + 8), "LAZ chunk table", e.what());
  }
  uint64_t remaining = point_count;
  for (size_t i = 0; i < chunks.size(); ++i) {
    Chunk& c = chunks[i];
    if (!variable) c.points = std::min<uint64_t>(vlr.chunk_size, remaining);
    c.declared = c.points;
    c.points = std::min(c.points, remaining);
    remaining -= c.points;
    if (c.start + c.bytes > table_at) {
      ThrowInputError(
          file, ChunkPlace(i, c), "LAZ chunk table",
          fmt::format("the chunk's {} bytes run past the chunk table (byte {})", c.bytes, table_at));
    }
    if (c.points != 0 && c.bytes < static_cast<uint64_t>(record_length)) {
      ThrowInputError(
          file, ChunkPlace(i, c), "LAZ chunk table",
          fmt::format("{} bytes cannot hold the chunk's raw first point ({} bytes)", c.bytes, record_length));
    }
    if (c.points > 1 && c.points - 1 > kMaxPointsPerCompressedByte * c.bytes) {
      ThrowInputError(file, ChunkPlace(i, c), "LAZ chunk table",
                      fmt::format("{} points cannot be coded in {} bytes", c.points, c.bytes));
    }
  }
  if (remaining != 0) {
    ThrowInputError(file, fmt::format("byte {}", table_at), "LAZ chunk table",
                    fmt::format("its {} chunks hold {} points, the header announces {}", number,
                                point_count - remaining, point_count));
  }
  return chunks;
}

struct ItemSlot {
  LazVlr::Item item;
  int offset = 0;  // byte in the record
};

// Both chunk decoders return where the chunk's data ended (the next chunk's start when there is no table).
const uint8_t* DecodePointwiseChunk(const std::vector<ItemSlot>& items, const uint8_t* begin,
                                    const uint8_t* end, uint64_t points, int record_length, uint8_t* out,
                                    uint64_t& point) {
  if (end - begin < record_length) throw LazCorrupt("the chunk ends inside its raw first point");
  std::memcpy(out, begin, record_length);  // the first point is stored raw
  ++point;
  if (points == 1) return begin + record_length;
  ArithmeticDecoder decoder;
  std::vector<std::unique_ptr<PointwiseItemDecoder>> decoders;
  for (const ItemSlot& slot : items) {
    decoders.push_back(MakePointwiseItemDecoder(slot.item.type, slot.item.version, slot.item.size, decoder,
                                                out + slot.offset));
  }
  decoder.Start(begin + record_length, end);
  for (uint64_t j = 1; j < points; ++j, ++point) {
    uint8_t* record = out + j * record_length;
    for (size_t i = 0; i < items.size(); ++i) decoders[i]->Decode(record + items[i].offset);
  }
  return decoder.position();  // LASzip's encoder pads each chunk so that its decoder stops at the end
}

const uint8_t* DecodeLayeredChunk(const std::vector<ItemSlot>& items, const uint8_t* begin,
                                  const uint8_t* end, uint64_t points, uint64_t declared, int record_length,
                                  uint8_t* out, uint64_t& point) {
  if (end - begin < record_length) throw LazCorrupt("the chunk ends inside its raw first point");
  std::memcpy(out, begin, record_length);  // the first point is stored raw
  ++point;
  if (points == 1) return begin + record_length;
  const uint8_t* p = begin + record_length;
  auto read_u32 = [&](const char* what) {
    if (end - p < 4) throw LazCorrupt(fmt::format("the chunk ends inside the {}", what));
    const uint32_t value = LoadLe<uint32_t>(p);
    p += 4;
    return value;
  };
  const uint32_t count = read_u32("point count");
  if (count != declared) {
    throw LazCorrupt(fmt::format("the chunk says it holds {} points, the chunk table {}", count, declared));
  }
  std::vector<std::unique_ptr<LayeredItemDecoder>> decoders;
  std::vector<std::vector<Layer>> layers(items.size());
  for (size_t i = 0; i < items.size(); ++i) {
    decoders.push_back(MakeLayeredItemDecoder(items[i].item.type, items[i].item.version, items[i].item.size));
    layers[i].resize(decoders[i]->LayerCount());
  }
  std::vector<std::vector<uint32_t>> sizes(items.size());
  for (size_t i = 0; i < items.size(); ++i) {
    for (size_t k = 0; k < layers[i].size(); ++k) sizes[i].push_back(read_u32("layer sizes"));
  }
  for (size_t i = 0; i < items.size(); ++i) {
    for (size_t k = 0; k < layers[i].size(); ++k) {
      if (static_cast<uint64_t>(end - p) < sizes[i][k]) {
        throw LazCorrupt(fmt::format("layer {} of item {} ({} bytes) runs past the chunk's end", k,
                                     ItemName(items[i].item.type), sizes[i][k]));
      }
      layers[i][k] = Layer(p, sizes[i][k]);
      p += sizes[i][k];
    }
  }
  uint32_t context = 0;
  for (size_t i = 0; i < items.size(); ++i) decoders[i]->Start(out + items[i].offset, layers[i], context);
  for (uint64_t j = 1; j < points; ++j, ++point) {
    uint8_t* record = out + j * record_length;
    for (size_t i = 0; i < items.size(); ++i) decoders[i]->Decode(record + items[i].offset, context);
  }
  return p;
}

}  // namespace

LazVlr ParseLazVlr(std::string_view payload, const std::string& file) {
  auto fail = [&](size_t byte, const char* field, const std::string& message) {
    ThrowInputError(file, fmt::format("laszip VLR byte {}", byte), field, message);
  };
  const auto* p = reinterpret_cast<const uint8_t*>(payload.data());
  if (payload.size() < kVlrFixedBytes) {
    fail(0, "", fmt::format("{} bytes, the laszip record takes at least {}", payload.size(), kVlrFixedBytes));
  }
  LazVlr vlr;
  vlr.compressor = LoadLe<uint16_t>(p);
  vlr.coder = LoadLe<uint16_t>(p + 2);
  vlr.version_major = p[4];
  vlr.version_minor = p[5];
  vlr.version_revision = LoadLe<uint16_t>(p + 6);
  vlr.options = LoadLe<uint32_t>(p + 8);
  vlr.chunk_size = LoadLe<uint32_t>(p + 12);
  const uint16_t count = LoadLe<uint16_t>(p + 32);
  if (vlr.compressor < 1 || vlr.compressor > 3) {
    fail(0, "compressor",
         fmt::format("{} (1 pointwise, 2 pointwise chunked, 3 layered chunked)", vlr.compressor));
  }
  if (vlr.coder != 0) fail(2, "coder", fmt::format("{} (only 0, arithmetic, exists)", vlr.coder));
  if (vlr.compressor != 1 && vlr.chunk_size == 0) fail(12, "chunk size", "0 points per chunk");
  if (count == 0) fail(32, "number of items", "0");
  if (payload.size() < kVlrFixedBytes + 6 * size_t{count}) {
    fail(32, "number of items",
         fmt::format("{} items take {} bytes, the record has {}", count, 6 * count,
                     payload.size() - kVlrFixedBytes));
  }
  for (uint16_t i = 0; i < count; ++i) {
    const size_t at = kVlrFixedBytes + 6 * size_t{i};
    LazVlr::Item item{LoadLe<uint16_t>(p + at), LoadLe<uint16_t>(p + at + 2), LoadLe<uint16_t>(p + at + 4)};
    if (ItemName(item.type) == nullptr || (item.type >= 1 && item.type <= 5)) {
      fail(at, "item type", fmt::format("{} is not a LASzip item LASzip writes", item.type));
    }
    const int size = ItemSize(item.type);
    if ((size != 0 && item.size != size) || item.size == 0) {
      fail(at + 2, "item size",
           fmt::format("{} bytes for {} (it has {})", item.size, ItemName(item.type), size));
    }
    const bool layered_item = item.type >= kPoint14;
    if (layered_item != (vlr.compressor == 3)) {
      fail(at, "item type",
           fmt::format("{} with compressor {}: items of point formats 6-10 are layered (compressor 3), the "
                       "others pointwise (1 or 2)",
                       ItemName(item.type), vlr.compressor));
    }
    vlr.items.push_back(item);
  }
  return vlr;
}

std::string DecodeLazPoints(std::string_view laszip_vlr_payload, std::string_view file_bytes,
                            uint64_t offset_to_point_data, uint64_t point_count, int point_format,
                            int point_record_length, const std::string& file) {
  const LazVlr vlr = ParseLazVlr(laszip_vlr_payload, file);
  // The items must be the point format's, in order, then the extra bytes.
  const std::vector<uint16_t> expected = ItemsOfFormat(point_format);
  std::vector<ItemSlot> items;
  int offset = 0;
  for (size_t i = 0; i < vlr.items.size(); ++i) {
    const LazVlr::Item& item = vlr.items[i];
    const bool extra_bytes = i >= expected.size() && i + 1 == vlr.items.size() &&
                             item.type == (vlr.compressor == 3 ? kByte14 : kByte);
    if (!(i < expected.size() && item.type == expected[i]) && !extra_bytes) {
      ThrowInputError(file, "laszip VLR", "items",
                      fmt::format("item {} is {}, which point format {} does not have there", i,
                                  ItemName(item.type), point_format));
    }
    const bool supported = vlr.compressor == 3 ? item.version == 3 : (item.version == 1 || item.version == 2);
    if (item.type == kWavePacket13 || item.type == kWavePacket14 || !supported) {
      ThrowInputError(file, "laszip VLR", "items",
                      fmt::format("LAZ item {} version {} is not supported (wave packets are not read; items "
                                  "of formats 0-5 are versions 1-2, of 6-10 version 3)",
                                  ItemName(item.type), item.version));
    }
    items.push_back({item, offset});
    offset += item.size;
  }
  if (vlr.items.size() < expected.size() || offset != point_record_length) {
    ThrowInputError(file, "laszip VLR", "items",
                    fmt::format("they make {}-byte records of {} items, the header says {} bytes of point "
                                "format {}",
                                offset, vlr.items.size(), point_record_length, point_format));
  }

  const uint64_t size = file_bytes.size();
  if (offset_to_point_data > size) {
    ThrowInputError(file, "header", "Offset to Point Data", "past the file's end");
  }
  if (point_count == 0) return {};
  const uint64_t compressed = size - offset_to_point_data;
  if (point_count > kMaxPointsPerCompressedByte * compressed) {
    ThrowInputError(
        file, "header", "Number of Point Records",
        fmt::format("{} points cannot be coded in the {} bytes of compressed point data (LAZ takes "
                    "at least 2 bits a point)",
                    point_count, compressed));
  }
  std::vector<Chunk> chunks;
  if (vlr.compressor == 1) {
    chunks.push_back({offset_to_point_data, compressed, point_count, point_count});
    if (compressed < static_cast<uint64_t>(point_record_length)) {
      ThrowInputError(file, ChunkPlace(0, chunks[0]), "", "truncated: no room for the raw first point");
    }
  } else {
    chunks = ReadChunkTable(vlr, file_bytes, offset_to_point_data, point_count, point_record_length, file);
  }

  CheckMemoryBudget(SaturatingBytes(static_cast<int64_t>(point_count), point_record_length),
                    fmt::format("{}: {} decompressed LAZ points", file, point_count));
  std::string out(point_count * static_cast<uint64_t>(point_record_length), '\0');
  auto* records = reinterpret_cast<uint8_t*>(out.data());
  const auto* data = reinterpret_cast<const uint8_t*>(file_bytes.data());
  uint64_t point = 0;
  // Without a chunk table, each fixed-size chunk starts where the previous one ended.
  const bool sequential = chunks.empty();
  uint64_t next_start = offset_to_point_data + 8;
  for (size_t i = 0; sequential ? point < point_count : i < chunks.size(); ++i) {
    const Chunk c = sequential ? Chunk{next_start, size - next_start,
                                       std::min<uint64_t>(vlr.chunk_size, point_count - point),
                                       std::min<uint64_t>(vlr.chunk_size, point_count - point)}
                               : chunks[i];
    if (c.points == 0) continue;
    const uint64_t first_point = point;
    try {
      uint8_t* chunk_out = records + point * point_record_length;
      const uint8_t* end;
      if (vlr.compressor == 3) {
        end = DecodeLayeredChunk(items, data + c.start, data + c.start + c.bytes, c.points, c.declared,
                                 point_record_length, chunk_out, point);
      } else {
        end = DecodePointwiseChunk(items, data + c.start, data + c.start + c.bytes, c.points,
                                   point_record_length, chunk_out, point);
      }
      next_start = static_cast<uint64_t>(end - data);
    } catch (const LazCorrupt& e) {
      ThrowInputError(
          file, ChunkPlace(i, c), "",
          fmt::format("point {} (the chunk's point {}): {}", point, point - first_point, e.what()));
    }
  }
  return out;
}

}  // namespace lidarshop::laz
