#include "lidarshop/io/laz_arithmetic.h"

#include <algorithm>

namespace lidarshop::laz {
namespace {

constexpr uint32_t kBitLengthShift = 13;  // bit-model probabilities in 1/8192
constexpr uint32_t kBitMaxCount = 1u << kBitLengthShift;
constexpr uint32_t kSymbolLengthShift = 15;  // symbol-model probabilities in 1/32768
constexpr uint32_t kSymbolMaxCount = 1u << kSymbolLengthShift;

}  // namespace

void BitModel::Update() {
  // Halve the counts when they grow too large, so that the model keeps adapting.
  if ((bit_count_ += update_cycle_) > kBitMaxCount) {
    bit_count_ = (bit_count_ + 1) >> 1;
    bit_0_count_ = (bit_0_count_ + 1) >> 1;
    if (bit_0_count_ == bit_count_) ++bit_count_;
  }
  const uint32_t scale = 0x80000000u / bit_count_;
  bit_0_prob_ = (bit_0_count_ * scale) >> (31 - kBitLengthShift);
  update_cycle_ = std::min<uint32_t>((5 * update_cycle_) >> 2, 64);
  bits_until_update_ = update_cycle_;
}

SymbolModel::SymbolModel(uint32_t symbols) : symbols_(symbols), last_symbol_(symbols - 1) {
  if (symbols > 16) {
    uint32_t table_bits = 3;
    while (symbols > (1u << (table_bits + 2))) ++table_bits;
    table_size_ = 1u << table_bits;
    table_shift_ = kSymbolLengthShift - table_bits;
  }
  storage_.assign(2 * symbols + (table_size_ != 0 ? table_size_ + 2 : 0), 0);
  std::fill_n(symbol_count(), symbols, 1u);
  update_cycle_ = symbols;
  Update();
  symbols_until_update_ = update_cycle_ = (symbols + 6) >> 1;
}

void SymbolModel::Update() {
  uint32_t* const dist = distribution();
  uint32_t* const counts = symbol_count();
  uint32_t* const table = decoder_table();
  if ((total_count_ += update_cycle_) > kSymbolMaxCount) {
    total_count_ = 0;
    for (uint32_t k = 0; k < symbols_; ++k) total_count_ += (counts[k] = (counts[k] + 1) >> 1);
  }
  const uint32_t scale = 0x80000000u / total_count_;
  uint32_t sum = 0;
  if (table_size_ == 0) {
    for (uint32_t k = 0; k < symbols_; ++k) {
      dist[k] = (scale * sum) >> (31 - kSymbolLengthShift);
      sum += counts[k];
    }
  } else {
    uint32_t s = 0;
    for (uint32_t k = 0; k < symbols_; ++k) {
      dist[k] = (scale * sum) >> (31 - kSymbolLengthShift);
      sum += counts[k];
      const uint32_t w = dist[k] >> table_shift_;
      while (s < w) table[++s] = k - 1;
    }
    table[0] = 0;
    while (s <= table_size_) table[++s] = symbols_ - 1;
  }
  update_cycle_ = std::min((5 * update_cycle_) >> 2, (symbols_ + 6) << 3);
  symbols_until_update_ = update_cycle_;
}

void ArithmeticDecoder::Start(const uint8_t* begin, const uint8_t* end) {
  next_ = begin;
  end_ = end;
  length_ = 0xFFFFFFFFu;
  value_ = 0;
  for (int i = 0; i < 4; ++i) value_ = (value_ << 8) | NextByte();
  // The decoder keeps value_ < length_; an encoder never starts at the very top.
  if (value_ >= length_) throw LazCorrupt("the arithmetic coder's first value is out of range");
}

uint32_t ArithmeticDecoder::DecodeBit(BitModel& model) {
  const uint32_t x = model.bit_0_prob_ * (length_ >> kBitLengthShift);
  const uint32_t bit = value_ >= x;
  if (bit == 0) {
    length_ = x;
    ++model.bit_0_count_;
  } else {
    value_ -= x;
    length_ -= x;
  }
  if (length_ < kMinLength) Renormalize();
  if (--model.bits_until_update_ == 0) model.Update();
  return bit;
}

uint32_t ArithmeticDecoder::DecodeSymbol(SymbolModel& model) {
  uint32_t symbol;
  uint32_t x;
  uint32_t y = length_;
  if (model.table_size_ != 0) {
    // The decoder table narrows the search to the symbols of the value's slice.
    const uint32_t dv = value_ / (length_ >>= kSymbolLengthShift);
    const uint32_t t = std::min(dv >> model.table_shift_, model.table_size_);
    symbol = model.decoder_table()[t];
    uint32_t n = model.decoder_table()[t + 1] + 1;
    while (n > symbol + 1) {
      const uint32_t k = (symbol + n) >> 1;
      if (model.distribution()[k] > dv) {
        n = k;
      } else {
        symbol = k;
      }
    }
    x = model.distribution()[symbol] * length_;
    if (symbol != model.last_symbol_) y = model.distribution()[symbol + 1] * length_;
  } else {
    x = symbol = 0;
    length_ >>= kSymbolLengthShift;
    uint32_t n = model.symbols_;
    uint32_t k = n >> 1;
    do {
      const uint32_t z = length_ * model.distribution()[k];
      if (z > value_) {
        n = k;
        y = z;
      } else {
        symbol = k;
        x = z;
      }
    } while ((k = (symbol + n) >> 1) != symbol);
  }
  if (x > value_ || y <= x) throw LazCorrupt("an arithmetic-coded symbol is out of range");
  value_ -= x;
  length_ = y - x;
  if (length_ < kMinLength) Renormalize();
  ++model.symbol_count()[symbol];
  if (--model.symbols_until_update_ == 0) model.Update();
  return symbol;
}

uint32_t ArithmeticDecoder::ReadRaw(uint32_t bits) {
  const uint32_t symbol = value_ / (length_ >>= bits);
  if (symbol >> bits) throw LazCorrupt("raw bits in the arithmetic-coded data are out of range");
  value_ -= length_ * symbol;
  if (length_ < kMinLength) Renormalize();
  return symbol;
}

uint32_t ArithmeticDecoder::ReadBits(uint32_t bits) {
  // LASzip reads more than 19 bits as 16 low bits, then the rest.
  if (bits > 19) {
    const uint32_t lower = ReadRaw(16);
    return (ReadBits(bits - 16) << 16) | lower;
  }
  return ReadRaw(bits);
}

IntegerDecompressor::IntegerDecompressor(ArithmeticDecoder& decoder, uint32_t bits, uint32_t contexts,
                                         uint32_t bits_high)
    : decoder_(&decoder), bits_high_(bits_high) {
  if (bits != 0 && bits < 32) {
    corr_bits_ = bits;
    corr_range_ = 1u << bits;
    corr_min_ = -static_cast<int32_t>(corr_range_ / 2);
  } else {
    corr_bits_ = 32;
    corr_range_ = 0;
    corr_min_ = INT32_MIN;
  }
  k_models_.assign(contexts, SymbolModel(corr_bits_ + 1));
  correctors_.resize(corr_bits_);
}

int32_t IntegerDecompressor::ReadCorrector(SymbolModel& k_model) {
  k_ = decoder_->DecodeSymbol(k_model);
  if (k_ == 0) return static_cast<int32_t>(decoder_->DecodeBit(corrector_0_));
  if (k_ >= 32) return corr_min_;
  std::optional<SymbolModel>& model = correctors_[k_ - 1];
  if (!model) model.emplace(1u << std::min(k_, bits_high_));
  int64_t c = decoder_->DecodeSymbol(*model);
  if (k_ > bits_high_) {
    const uint32_t low_bits = k_ - bits_high_;
    c = (c << low_bits) | decoder_->ReadBits(low_bits);
  }
  // c codes the corrector's magnitude class: [1, 2^(k-1)] and [-(2^k - 1), -2^(k-1)].
  if (c >= (int64_t{1} << (k_ - 1))) {
    c += 1;
  } else {
    c -= (int64_t{1} << k_) - 1;
  }
  return static_cast<int32_t>(static_cast<uint32_t>(c));
}

int32_t IntegerDecompressor::Decompress(int32_t prediction, uint32_t context) {
  const int32_t corrector = ReadCorrector(k_models_[context]);
  if (corr_range_ == 0) {
    return static_cast<int32_t>(static_cast<uint32_t>(prediction) + static_cast<uint32_t>(corrector));
  }
  int64_t real = int64_t{prediction} + corrector;
  if (real < 0) {
    real += corr_range_;
  } else if (real >= corr_range_) {
    real -= corr_range_;
  }
  return static_cast<int32_t>(real);
}

void StreamingMedian5::Add(int32_t v) {
  int32_t* s = values_;
  if (high_) {
    if (v < s[2]) {
      s[4] = s[3];
      s[3] = s[2];
      if (v < s[0]) {
        s[2] = s[1];
        s[1] = s[0];
        s[0] = v;
      } else if (v < s[1]) {
        s[2] = s[1];
        s[1] = v;
      } else {
        s[2] = v;
      }
    } else {
      if (v < s[3]) {
        s[4] = s[3];
        s[3] = v;
      } else {
        s[4] = v;
      }
      high_ = false;
    }
  } else {
    if (s[2] < v) {
      s[0] = s[1];
      s[1] = s[2];
      if (s[4] < v) {
        s[2] = s[3];
        s[3] = s[4];
        s[4] = v;
      } else if (s[3] < v) {
        s[2] = s[3];
        s[3] = v;
      } else {
        s[2] = v;
      }
    } else {
      if (s[1] < v) {
        s[0] = s[1];
        s[1] = v;
      } else {
        s[0] = v;
      }
      high_ = true;
    }
  }
}

}  // namespace lidarshop::laz
