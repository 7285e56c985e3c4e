// LASzip's layered decompressors after POINT14, version 3 (LAZ specification): RGB14 (one layer), RGBNIR14
// (RGB and NIR layers) and BYTE14 (one layer per extra byte). Each keeps a prediction per scanner channel
// (the context POINT14 decoded); a channel's first point predicts from the previous point of the channel
// before it.
#include <array>
#include <optional>
#include <vector>

#include "lidarshop/io/laz_items.h"

namespace lidarshop::laz {

void DecodeRgbV2(ArithmeticDecoder& d, uint32_t sym, std::array<SymbolModel, 6>& diff, const uint16_t* last,
                 uint16_t* rgb);

namespace {

// Per channel state of RGB(NIR): the last colour (R, G, B, NIR) and the models.
struct ColourChannel {
  explicit ColourChannel(const uint16_t* from)
      : byte_used(128),
        diff{SymbolModel(256), SymbolModel(256), SymbolModel(256),
             SymbolModel(256), SymbolModel(256), SymbolModel(256)},
        nir_bytes_used(4),
        nir_diff{SymbolModel(256), SymbolModel(256)} {
    std::memcpy(last, from, sizeof(last));
  }
  SymbolModel byte_used;
  std::array<SymbolModel, 6> diff;
  SymbolModel nir_bytes_used;
  std::array<SymbolModel, 2> nir_diff;
  uint16_t last[4];
};

class ColourV3 final : public LayeredItemDecoder {
 public:
  explicit ColourV3(bool nir) : nir_(nir) {}
  int LayerCount() const override { return nir_ ? 2 : 1; }

  void Start(const uint8_t* first, std::span<const Layer> layers, uint32_t& context) override {
    for (int i = 0; i < LayerCount(); ++i) {
      changed_[i] = !layers[i].empty();
      if (changed_[i]) decoders_[i].Start(layers[i].data(), layers[i].data() + layers[i].size());
    }
    uint16_t colour[4] = {0, 0, 0, 0};
    for (int i = 0; i < LayerCount() + 2; ++i) colour[i] = LoadLe<uint16_t>(first + 2 * i);
    current_ = context;
    channels_[current_].emplace(colour);
  }

  void Decode(uint8_t* item, uint32_t& context) override {
    if (context != current_) {
      if (!channels_[context]) channels_[context].emplace(channels_[current_]->last);
      current_ = context;
    }
    ColourChannel& c = *channels_[current_];
    if (changed_[0]) {
      uint16_t rgb[3];
      ArithmeticDecoder& d = decoders_[0];
      DecodeRgbV2(d, d.DecodeSymbol(c.byte_used), c.diff, c.last, rgb);
      std::memcpy(c.last, rgb, sizeof(rgb));
    }
    if (nir_ && changed_[1]) {
      ArithmeticDecoder& d = decoders_[1];
      const uint32_t sym = d.DecodeSymbol(c.nir_bytes_used);
      const uint16_t last = c.last[3];
      uint16_t nir = (sym & 1) ? FoldByte(static_cast<int32_t>(d.DecodeSymbol(c.nir_diff[0])) + (last & 255))
                               : (last & 0xFF);
      nir |= (sym & 2) ? FoldByte(static_cast<int32_t>(d.DecodeSymbol(c.nir_diff[1])) + (last >> 8)) << 8
                       : (last & 0xFF00);
      c.last[3] = nir;
    }
    for (int i = 0; i < (nir_ ? 4 : 3); ++i) StoreLe<uint16_t>(item + 2 * i, c.last[i]);
  }

 private:
  bool nir_;
  std::array<ArithmeticDecoder, 2> decoders_;
  std::array<bool, 2> changed_{};
  std::array<std::optional<ColourChannel>, 4> channels_;
  uint32_t current_ = 0;
};

struct BytesChannel {
  explicit BytesChannel(const std::vector<uint8_t>& from)
      : models(from.size(), SymbolModel(256)), last(from) {}
  std::vector<SymbolModel> models;
  std::vector<uint8_t> last;
};

class BytesV3 final : public LayeredItemDecoder {
 public:
  explicit BytesV3(uint32_t size) : decoders_(size), changed_(size) {}
  int LayerCount() const override { return static_cast<int>(decoders_.size()); }

  void Start(const uint8_t* first, std::span<const Layer> layers, uint32_t& context) override {
    for (size_t i = 0; i < decoders_.size(); ++i) {
      changed_[i] = !layers[i].empty();
      if (changed_[i]) decoders_[i].Start(layers[i].data(), layers[i].data() + layers[i].size());
    }
    current_ = context;
    channels_[current_].emplace(std::vector<uint8_t>(first, first + decoders_.size()));
  }

  void Decode(uint8_t* item, uint32_t& context) override {
    if (context != current_) {
      if (!channels_[context]) channels_[context].emplace(channels_[current_]->last);
      current_ = context;
    }
    BytesChannel& c = *channels_[current_];
    for (size_t i = 0; i < decoders_.size(); ++i) {
      if (changed_[i]) {
        c.last[i] = FoldByte(static_cast<int32_t>(c.last[i] + decoders_[i].DecodeSymbol(c.models[i])));
      }
      item[i] = c.last[i];
    }
  }

 private:
  std::vector<ArithmeticDecoder> decoders_;
  std::vector<char> changed_;
  std::array<std::optional<BytesChannel>, 4> channels_;
  uint32_t current_ = 0;
};

}  // namespace

std::unique_ptr<LayeredItemDecoder> MakeLayeredItemDecoder(uint16_t type, uint16_t version, uint32_t size) {
  if (version != 3) return nullptr;
  switch (type) {
    case kPoint14:
      return MakePoint14Decoder();
    case kRgb14:
      return std::make_unique<ColourV3>(false);
    case kRgbNir14:
      return std::make_unique<ColourV3>(true);
    case kByte14:
      return std::make_unique<BytesV3>(size);
    default:
      return nullptr;
  }
}

}  // namespace lidarshop::laz
