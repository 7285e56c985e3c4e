// LAZ (LASzip-compressed LAS) point data, decoded by hand from the LAZ specification (rapidlasso, "LASzip
// compression"; no LASzip library is packaged for lidarshop's platform). Internal to the io module: the LAS
// reader finds the laszip VLR, decodes the points with DecodeLazPoints and parses them as uncompressed ones.
//
// Supported: compressors 1 (pointwise), 2 (pointwise chunked) and 3 (layered chunked), the arithmetic coder
// (0), items POINT10, GPSTIME11, RGB12, BYTE (versions 1 and 2: point formats 0-3 and extra bytes) and
// POINT14, RGB14, RGBNIR14, BYTE14 (version 3: point formats 6-8, as COPC uses), fixed and variable chunk
// sizes (fixed-size chunks also without a chunk table). Wave packets (formats 4, 5, 9, 10) are refused.
//
// Bounds: a point takes at least 2 bits of compressed data (real LAZ takes 1.5-10 bytes a point; LASzip's
// adaptive models cannot go much below a few hundredths of a bit even for identical points, which no scanner
// writes), so the point count may be at most 4 x the compressed bytes; only then is the output
// (count x record length) allocated. Every chunk start, size and point count comes from the chunk table and
// is checked against the file; the decoder never reads outside a chunk (or a layer) and decodes exactly the
// points the header announces, so garbage ends in an InputError, never a crash or an endless loop.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace lidarshop::laz {

// The "laszip encoded" VLR (record id 22204): how the points are compressed.
struct LazVlr {
  struct Item {
    uint16_t type = 0;  // laz_items.h ItemType
    uint16_t size = 0;  // bytes
    uint16_t version = 0;
  };
  uint16_t compressor = 0;  // 1 pointwise, 2 pointwise chunked, 3 layered chunked
  uint16_t coder = 0;       // 0 arithmetic
  uint8_t version_major = 0, version_minor = 0;
  uint16_t version_revision = 0;
  uint32_t options = 0;
  uint32_t chunk_size = 0;  // points per chunk; 0xFFFFFFFF: variable (the chunk table holds the counts)
  std::vector<Item> items;  // in record order, their sizes summing to the record length
};
constexpr uint16_t kLazVlrRecordId = 22204;
constexpr uint32_t kVariableChunkSize = 0xFFFFFFFFu;

// Parses and validates the VLR's payload (the bytes after its 54-byte header). Throws InputError naming
// `file`, the payload byte and the field.
LazVlr ParseLazVlr(std::string_view payload, const std::string& file);

// The uncompressed point records (point_count x point_record_length bytes, as a LAS file holds them) of the
// LAZ file `file_bytes` whose points start at byte `offset_to_point_data`. `point_format` is the format
// without LASzip's bits 6-7. Throws InputError naming `file`, the chunk and point and what is wrong on
// corrupt or unsupported data.
std::string DecodeLazPoints(std::string_view laszip_vlr_payload, std::string_view file_bytes,
                            uint64_t offset_to_point_data, uint64_t point_count, int point_format,
                            int point_record_length, const std::string& file);

}  // namespace lidarshop::laz
