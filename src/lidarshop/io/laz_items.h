// LASzip's per-item decompressors (internal to the io module's LAZ reader): each turns the arithmetic-coded
// stream back into one item of a LAS point record (the 20-byte POINT10 core, the GPS time, RGB, extra bytes,
// ...), predicting from the chunk's previous point. The item layouts are the LAS ones, little-endian.
//
// Pointwise items (LAZ for point formats 0-5, item versions 1 and 2) share one decoder per chunk; layered
// items (point formats 6-10, version 3) own one decoder per layer. Every decompressor is made fresh for each
// chunk from the chunk's first point, which is stored raw.
#pragma once

#include <cstdint>
#include <cstring>
#include <memory>
#include <optional>
#include <span>

#include "lidarshop/io/laz_arithmetic.h"

namespace lidarshop::laz {

// LASzip item types (the "items" of the laszip VLR).
enum ItemType : uint16_t {
  kByte = 0,
  kPoint10 = 6,
  kGpsTime11 = 7,
  kRgb12 = 8,
  kWavePacket13 = 9,
  kPoint14 = 10,
  kRgb14 = 11,
  kRgbNir14 = 12,
  kWavePacket14 = 13,
  kByte14 = 14,
};

class PointwiseItemDecoder {
 public:
  virtual ~PointwiseItemDecoder() = default;
  // Fills `item` (the item's bytes in the output record) with the next point's item.
  virtual void Decode(uint8_t* item) = 0;
};

// A decompressor for `type` version `version` of `size` bytes, predicting from `first` (the chunk's raw
// first item) and reading from `decoder`. Null for an unsupported type / version.
std::unique_ptr<PointwiseItemDecoder> MakePointwiseItemDecoder(uint16_t type, uint16_t version, uint32_t size,
                                                               ArithmeticDecoder& decoder,
                                                               const uint8_t* first);

// The compressed bytes of one layer; empty when the layer's attribute does not change within the chunk.
using Layer = std::span<const uint8_t>;

class LayeredItemDecoder {
 public:
  virtual ~LayeredItemDecoder() = default;
  virtual int LayerCount() const = 0;
  // Starts the chunk: `first` is the raw first item, `layers` its LayerCount() layers. The POINT14 item sets
  // `context` (the scanner channel), which the later items use.
  virtual void Start(const uint8_t* first, std::span<const Layer> layers, uint32_t& context) = 0;
  virtual void Decode(uint8_t* item, uint32_t& context) = 0;
};

// Version 3 (layered) decompressors: kPoint14, kRgb14, kRgbNir14, kByte14 (`size` bytes). Null otherwise.
std::unique_ptr<LayeredItemDecoder> MakeLayeredItemDecoder(uint16_t type, uint16_t version, uint32_t size);
std::unique_ptr<LayeredItemDecoder> MakePoint14Decoder();

// The contexts LASzip derives from the return number r and the number of returns n (LAZ specification):
// point formats 0-5 (3-bit returns) and 6-10 (4-bit returns).
extern const uint8_t kNumberReturnMap[8][8];
extern const uint8_t kNumberReturnLevel[8][8];
extern const uint8_t kNumberReturnMap6Ctx[16][16];
extern const uint8_t kNumberReturnLevel8Ctx[16][16];

template <typename T>
inline T LoadLe(const uint8_t* p) {
  T value;
  std::memcpy(&value, p, sizeof(T));
  return value;
}
template <typename T>
inline void StoreLe(uint8_t* p, T value) {
  std::memcpy(p, &value, sizeof(T));
}

// A symbol model made on first use, as LASzip does for its 256 per-value contexts.
inline SymbolModel& Lazy(std::optional<SymbolModel>& model, uint32_t symbols) {
  if (!model) model.emplace(symbols);
  return *model;
}

// a * b with the 32-bit wrap-around LASzip's C++ relies on (signed overflow is undefined, unsigned wraps).
inline uint32_t Times(int32_t a, int32_t b) { return static_cast<uint32_t>(a) * static_cast<uint32_t>(b); }

}  // namespace lidarshop::laz
