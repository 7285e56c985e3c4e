// LASzip's pointwise decompressors after POINT10, versions 1 and 2 (LAZ specification): the GPS time
// (GPSTIME11, 8 bytes), the colour (RGB12, 3 x uint16) and the extra bytes (BYTE, one model per byte).
#include <array>
#include <vector>

#include "lidarshop/io/laz_items.h"

namespace lidarshop::laz {

std::unique_ptr<PointwiseItemDecoder> MakePoint10Decoder(uint16_t version, ArithmeticDecoder& decoder,
                                                         const uint8_t* first);

namespace {

// GPS times are coded as the 64-bit integers of their doubles. Version 2 keeps four sequences (flight lines
// merged finely interleave their times) with the last difference of each, and codes a time as a multiple of
// that difference plus a corrector.
class GpsTimeV2 final : public PointwiseItemDecoder {
 public:
  GpsTimeV2(ArithmeticDecoder& decoder, const uint8_t* first)
      : d_(decoder), multi_(kMultiTotal), zero_diff_(6), gpstime_(decoder, 32, 9) {
    last_gpstime_[0] = LoadLe<uint64_t>(first);
  }

  void Decode(uint8_t* item) override {
    // A switch to another sequence is followed by the time coded in it; a valid stream switches once.
    for (int switches = 0;; ++switches) {
      if (switches > 1) throw LazCorrupt("the GPS time switches sequence twice for one point");
      if (last_diff_[last_] == 0) {
        const uint32_t multi = d_.DecodeSymbol(zero_diff_);
        if (multi == 1) {  // a difference of 32 bits
          last_diff_[last_] = gpstime_.Decompress(0, 0);
          last_gpstime_[last_] += static_cast<int64_t>(last_diff_[last_]);
          extreme_counter_[last_] = 0;
        } else if (multi == 2) {  // a jump: a new sequence
          NewSequence();
        } else if (multi > 2) {
          last_ = (last_ + multi - 2) & 3;
          continue;
        }
      } else {
        const uint32_t multi = d_.DecodeSymbol(multi_);
        if (multi == 1) {
          last_gpstime_[last_] += static_cast<int64_t>(gpstime_.Decompress(last_diff_[last_], 1));
          extreme_counter_[last_] = 0;
        } else if (multi < kMultiUnchanged) {
          last_gpstime_[last_] += static_cast<int64_t>(DecodeMultiple(multi));
        } else if (multi == kMultiCodeFull) {
          NewSequence();
        } else if (multi > kMultiCodeFull) {
          last_ = (last_ + multi - kMultiCodeFull) & 3;
          continue;
        }
      }
      break;
    }
    StoreLe<uint64_t>(item, last_gpstime_[last_]);
  }

 private:
  static constexpr int32_t kMulti = 500;
  static constexpr int32_t kMultiMinus = -10;
  static constexpr uint32_t kMultiUnchanged = kMulti - kMultiMinus + 1;
  static constexpr uint32_t kMultiCodeFull = kMulti - kMultiMinus + 2;
  static constexpr uint32_t kMultiTotal = kMulti - kMultiMinus + 6;

  // The difference for symbol `multi` in [0, kMultiUnchanged): a multiple of the last difference.
  int32_t DecodeMultiple(uint32_t code) {
    const int32_t last_diff = last_diff_[last_];
    int32_t diff;
    auto count_extreme = [&] {
      if (++extreme_counter_[last_] > 3) {
        last_diff_[last_] = diff;
        extreme_counter_[last_] = 0;
      }
    };
    const auto multi = static_cast<int32_t>(code);
    if (multi == 0) {
      diff = gpstime_.Decompress(0, 7);
      count_extreme();
    } else if (multi < kMulti) {
      diff = gpstime_.Decompress(static_cast<int32_t>(Times(multi, last_diff)), multi < 10 ? 2 : 3);
    } else if (multi == kMulti) {
      diff = gpstime_.Decompress(static_cast<int32_t>(Times(kMulti, last_diff)), 4);
      count_extreme();
    } else {
      const int32_t negative = kMulti - multi;
      if (negative > kMultiMinus) {
        diff = gpstime_.Decompress(static_cast<int32_t>(Times(negative, last_diff)), 5);
      } else {
        diff = gpstime_.Decompress(static_cast<int32_t>(Times(kMultiMinus, last_diff)), 6);
        count_extreme();
      }
    }
    return diff;
  }

  void NewSequence() {
    next_ = (next_ + 1) & 3;
    const auto high = static_cast<uint32_t>(
        gpstime_.Decompress(static_cast<int32_t>(static_cast<uint32_t>(last_gpstime_[last_] >> 32)), 8));
    last_gpstime_[next_] = (static_cast<uint64_t>(high) << 32) | d_.ReadInt();
    last_ = next_;
    last_diff_[last_] = 0;
    extreme_counter_[last_] = 0;
  }

  ArithmeticDecoder& d_;
  SymbolModel multi_, zero_diff_;
  IntegerDecompressor gpstime_;
  uint32_t last_ = 0, next_ = 0;
  std::array<uint64_t, 4> last_gpstime_{};
  std::array<int32_t, 4> last_diff_{};
  std::array<int32_t, 4> extreme_counter_{};
};

// Version 1: one sequence.
class GpsTimeV1 final : public PointwiseItemDecoder {
 public:
  GpsTimeV1(ArithmeticDecoder& decoder, const uint8_t* first)
      : d_(decoder), multi_(kMultiMax), zero_diff_(3), gpstime_(decoder, 32, 6) {
    last_gpstime_ = LoadLe<uint64_t>(first);
  }

  void Decode(uint8_t* item) override {
    if (last_diff_ == 0) {
      const uint32_t multi = d_.DecodeSymbol(zero_diff_);
      if (multi == 1) {
        last_diff_ = gpstime_.Decompress(0, 0);
        last_gpstime_ += static_cast<int64_t>(last_diff_);
      } else if (multi == 2) {
        last_gpstime_ = d_.ReadInt64();
      }
    } else {
      const auto multi = static_cast<int32_t>(d_.DecodeSymbol(multi_));
      if (multi < kMultiMax - 2) {
        int32_t diff;
        if (multi == 1) {
          diff = gpstime_.Decompress(last_diff_, 1);
          last_diff_ = diff;
          extreme_counter_ = 0;
        } else if (multi == 0) {
          diff = gpstime_.Decompress(last_diff_ / 4, 2);
          if (++extreme_counter_ > 3) {
            last_diff_ = diff;
            extreme_counter_ = 0;
          }
        } else {
          diff = gpstime_.Decompress(static_cast<int32_t>(Times(multi, last_diff_)),
                                     multi < 10 ? 3 : (multi < 50 ? 4 : 5));
          if (multi == kMultiMax - 3 && ++extreme_counter_ > 3) {
            last_diff_ = diff;
            extreme_counter_ = 0;
          }
        }
        last_gpstime_ += static_cast<int64_t>(diff);
      } else if (multi < kMultiMax - 1) {
        last_gpstime_ = d_.ReadInt64();
      }
    }
    StoreLe<uint64_t>(item, last_gpstime_);
  }

 private:
  static constexpr int32_t kMultiMax = 512;
  ArithmeticDecoder& d_;
  SymbolModel multi_, zero_diff_;
  IntegerDecompressor gpstime_;
  uint64_t last_gpstime_;
  int32_t last_diff_ = 0;
  int32_t extreme_counter_ = 0;
};

}  // namespace

// Shared with RGB14 (laz_items14.cc): the colour of version 2, each byte of R, G, B as a difference to the
// previous point's, G and B predicted from R's change; `sym` says which bytes changed (bit 6: not grey).
void DecodeRgbV2(ArithmeticDecoder& d, uint32_t sym, std::array<SymbolModel, 6>& diff, const uint16_t* last,
                 uint16_t* rgb) {
  auto corr = [&](int i) { return static_cast<int32_t>(d.DecodeSymbol(diff[i])); };
  rgb[0] = (sym & 1) ? FoldByte(corr(0) + (last[0] & 255)) : (last[0] & 0xFF);
  rgb[0] |= (sym & 2) ? FoldByte(corr(1) + (last[0] >> 8)) << 8 : (last[0] & 0xFF00);
  if (sym & (1 << 6)) {
    int32_t delta = (rgb[0] & 0xFF) - (last[0] & 0xFF);
    rgb[1] = (sym & 4) ? FoldByte(corr(2) + ClampByte(delta + (last[1] & 255))) : (last[1] & 0xFF);
    if (sym & 16) {
      delta = (delta + ((rgb[1] & 0xFF) - (last[1] & 0xFF))) / 2;
      rgb[2] = FoldByte(corr(4) + ClampByte(delta + (last[2] & 255)));
    } else {
      rgb[2] = last[2] & 0xFF;
    }
    delta = (rgb[0] >> 8) - (last[0] >> 8);
    rgb[1] |= (sym & 8) ? FoldByte(corr(3) + ClampByte(delta + (last[1] >> 8))) << 8 : (last[1] & 0xFF00);
    if (sym & 32) {
      delta = (delta + ((rgb[1] >> 8) - (last[1] >> 8))) / 2;
      rgb[2] |= FoldByte(corr(5) + ClampByte(delta + (last[2] >> 8))) << 8;
    } else {
      rgb[2] |= last[2] & 0xFF00;
    }
  } else {
    rgb[1] = rgb[0];
    rgb[2] = rgb[0];
  }
}

namespace {

void LoadRgb(const uint8_t* p, uint16_t* rgb) {
  for (int i = 0; i < 3; ++i) rgb[i] = LoadLe<uint16_t>(p + 2 * i);
}
void StoreRgb(uint8_t* p, const uint16_t* rgb) {
  for (int i = 0; i < 3; ++i) StoreLe<uint16_t>(p + 2 * i, rgb[i]);
}

class RgbV2 final : public PointwiseItemDecoder {
 public:
  RgbV2(ArithmeticDecoder& decoder, const uint8_t* first)
      : d_(decoder), byte_used_(128), diff_{SymbolModel(256), SymbolModel(256), SymbolModel(256),
                                            SymbolModel(256), SymbolModel(256), SymbolModel(256)} {
    LoadRgb(first, last_);
  }
  void Decode(uint8_t* item) override {
    uint16_t rgb[3];
    DecodeRgbV2(d_, d_.DecodeSymbol(byte_used_), diff_, last_, rgb);
    std::memcpy(last_, rgb, sizeof(rgb));
    StoreRgb(item, rgb);
  }

 private:
  ArithmeticDecoder& d_;
  SymbolModel byte_used_;
  std::array<SymbolModel, 6> diff_;
  uint16_t last_[3];
};

// Version 1: each changed byte of R, G, B difference-coded on its own.
class RgbV1 final : public PointwiseItemDecoder {
 public:
  RgbV1(ArithmeticDecoder& decoder, const uint8_t* first) : d_(decoder), byte_used_(64), rgb_(decoder, 8, 6) {
    LoadRgb(first, last_);
  }
  void Decode(uint8_t* item) override {
    const uint32_t sym = d_.DecodeSymbol(byte_used_);
    uint16_t rgb[3];
    for (int c = 0; c < 3; ++c) {
      const uint32_t low_context = 2 * c, high_context = 2 * c + 1;
      rgb[c] = (sym & (1u << low_context))
                   ? static_cast<uint16_t>(rgb_.Decompress(last_[c] & 255, low_context) & 0xFF)
                   : (last_[c] & 0xFF);
      rgb[c] |= (sym & (1u << high_context))
                    ? static_cast<uint16_t>((rgb_.Decompress(last_[c] >> 8, high_context) & 0xFF) << 8)
                    : (last_[c] & 0xFF00);
    }
    std::memcpy(last_, rgb, sizeof(rgb));
    StoreRgb(item, rgb);
  }

 private:
  ArithmeticDecoder& d_;
  SymbolModel byte_used_;
  IntegerDecompressor rgb_;
  uint16_t last_[3];
};

class BytesV2 final : public PointwiseItemDecoder {
 public:
  BytesV2(ArithmeticDecoder& decoder, const uint8_t* first, uint32_t size)
      : d_(decoder), models_(size, SymbolModel(256)), last_(first, first + size) {}
  void Decode(uint8_t* item) override {
    for (size_t i = 0; i < last_.size(); ++i) {
      last_[i] = FoldByte(static_cast<int32_t>(last_[i] + d_.DecodeSymbol(models_[i])));
    }
    std::memcpy(item, last_.data(), last_.size());
  }

 private:
  ArithmeticDecoder& d_;
  std::vector<SymbolModel> models_;
  std::vector<uint8_t> last_;
};

class BytesV1 final : public PointwiseItemDecoder {
 public:
  BytesV1(ArithmeticDecoder& decoder, const uint8_t* first, uint32_t size)
      : bytes_(decoder, 8, size), last_(first, first + size) {}
  void Decode(uint8_t* item) override {
    for (size_t i = 0; i < last_.size(); ++i) {
      last_[i] = static_cast<uint8_t>(bytes_.Decompress(last_[i], static_cast<uint32_t>(i)));
    }
    std::memcpy(item, last_.data(), last_.size());
  }

 private:
  IntegerDecompressor bytes_;
  std::vector<uint8_t> last_;
};

}  // namespace

std::unique_ptr<PointwiseItemDecoder> MakePointwiseItemDecoder(uint16_t type, uint16_t version, uint32_t size,
                                                               ArithmeticDecoder& decoder,
                                                               const uint8_t* first) {
  if (version != 1 && version != 2) return nullptr;
  const bool v2 = version == 2;
  switch (type) {
    case kPoint10:
      return MakePoint10Decoder(version, decoder, first);
    case kGpsTime11:
      if (v2) return std::make_unique<GpsTimeV2>(decoder, first);
      return std::make_unique<GpsTimeV1>(decoder, first);
    case kRgb12:
      if (v2) return std::make_unique<RgbV2>(decoder, first);
      return std::make_unique<RgbV1>(decoder, first);
    case kByte:
      if (v2) return std::make_unique<BytesV2>(decoder, first, size);
      return std::make_unique<BytesV1>(decoder, first, size);
    default:
      return nullptr;
  }
}

}  // namespace lidarshop::laz
