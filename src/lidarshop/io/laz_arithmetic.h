// The entropy coder of LASzip (internal to the io module's LAZ reader): the arithmetic (range) decoder with
// its adaptive bit and symbol models, and the integer decompressor that codes a value as a prediction plus a
// corrector of k bits. Written from the LAZ specification (rapidlasso, "LASzip compression": the coder is
// Amir Said's FastAC with 32-bit intervals, 13-bit bit-model and 15-bit symbol-model probabilities).
//
// Corrupt input never reads out of the given bytes: running off their end, or a value the encoder cannot
// have written, throws LazCorrupt, which the LAZ reader turns into an InputError naming the file, the
// chunk and the point.
#pragma once

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <vector>

namespace lidarshop::laz {

// Corrupt compressed data; the message says what is wrong (the caller adds file, chunk and point).
class LazCorrupt : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// An adaptive model of one binary decision.
class BitModel {
 public:
  BitModel() = default;

 private:
  friend class ArithmeticDecoder;
  void Update();
  uint32_t bit_0_count_ = 1;
  uint32_t bit_count_ = 2;
  uint32_t bit_0_prob_ = 1u << 12;  // probability of a 0, in 1/8192
  uint32_t update_cycle_ = 4;
  uint32_t bits_until_update_ = 4;
};

// An adaptive model of a symbol in [0, symbols).
class SymbolModel {
 public:
  explicit SymbolModel(uint32_t symbols);

 private:
  friend class ArithmeticDecoder;
  void Update();
  uint32_t symbols_;
  uint32_t last_symbol_;
  uint32_t table_size_ = 0;  // 0: no decoder table (16 symbols or fewer)
  uint32_t table_shift_ = 0;
  uint32_t total_count_ = 0;
  uint32_t update_cycle_;
  uint32_t symbols_until_update_ = 0;
  // One allocation (models are made per chunk): the cumulative probabilities in 1/32768 (symbols_), the
  // counts (symbols_), then the decoder table (table_size_ + 2: the first symbol of each slice).
  std::vector<uint32_t> storage_;
  uint32_t* distribution() { return storage_.data(); }
  uint32_t* symbol_count() { return storage_.data() + symbols_; }
  uint32_t* decoder_table() { return storage_.data() + 2 * symbols_; }
};

class ArithmeticDecoder {
 public:
  // Decodes bytes [begin, end), reading the first four now. Throws LazCorrupt when fewer than four.
  void Start(const uint8_t* begin, const uint8_t* end);
  uint32_t DecodeBit(BitModel& model);
  uint32_t DecodeSymbol(SymbolModel& model);
  uint32_t ReadBits(uint32_t bits);  // 1 to 32 raw bits
  uint32_t ReadInt() { return ReadBits(32); }
  const uint8_t* position() const { return next_; }  // the next byte to read
  uint64_t ReadInt64() {
    const uint64_t lower = ReadInt();
    return (static_cast<uint64_t>(ReadInt()) << 32) | lower;
  }

 private:
  uint32_t ReadRaw(uint32_t bits);  // at most 16 bits
  void Renormalize() {
    do {
      value_ = (value_ << 8) | NextByte();
    } while ((length_ <<= 8) < kMinLength);
  }
  uint8_t NextByte() {
    if (next_ == end_) throw LazCorrupt("the compressed data ends before its last point");
    return *next_++;
  }
  static constexpr uint32_t kMinLength = 0x01000000u;
  const uint8_t* next_ = nullptr;
  const uint8_t* end_ = nullptr;
  uint32_t value_ = 0;
  uint32_t length_ = 0;
};

// Decompresses integers of `bits` bits (2 to 32) as a prediction plus a corrector; the corrector's bit count
// k is entropy coded in one of `contexts` models, its low bits beyond `bits_high` raw.
class IntegerDecompressor {
 public:
  IntegerDecompressor(ArithmeticDecoder& decoder, uint32_t bits = 16, uint32_t contexts = 1,
                      uint32_t bits_high = 8);
  // The value predicted by `prediction`, wrapped into the `bits`-bit range (32 bits: modulo 2^32).
  int32_t Decompress(int32_t prediction, uint32_t context = 0);
  uint32_t k() const { return k_; }  // the bit count of the last corrector (a context for later values)

 private:
  int32_t ReadCorrector(SymbolModel& k_model);
  ArithmeticDecoder* decoder_;
  uint32_t corr_bits_;
  uint32_t corr_range_;  // 0 for 32 bits
  int32_t corr_min_;
  uint32_t bits_high_;
  uint32_t k_ = 0;
  std::vector<SymbolModel> k_models_;  // one per context
  BitModel corrector_0_;               // k = 0: the corrector is 0 or 1
  // k = 1 .. corr_bits_ at index k - 1, made on first use (a fresh model is the same whenever it is made;
  // making all 32 of a 32-bit decompressor up front dominated chunks of a few points, as COPC has).
  std::vector<std::optional<SymbolModel>> correctors_;
};

// The median of the last five values, kept incrementally as LASzip does (its exact update order matters: the
// encoder predicted with it).
class StreamingMedian5 {
 public:
  void Add(int32_t v);
  int32_t Get() const { return values_[2]; }

 private:
  int32_t values_[5] = {0, 0, 0, 0, 0};
  bool high_ = true;
};

// A byte plus a difference, modulo 256 (LASzip's U8_FOLD), and a value clamped to a byte (U8_CLAMP).
inline uint8_t FoldByte(int32_t n) { return static_cast<uint8_t>(n); }
inline int32_t ClampByte(int32_t n) { return n < 0 ? 0 : (n > 255 ? 255 : n); }

}  // namespace lidarshop::laz
