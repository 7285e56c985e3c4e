// The E57 bit-pack codec (see e57_format.h).
#include <algorithm>
#include <bit>

#include "lidarshop/io/e57_format.h"
#include "lidarshop/util/error.h"

namespace lidarshop::e57 {
namespace {

// Reads `bits` (1..64) bits at bit position `pos`; the caller has checked that they lie inside the stream.
inline uint64_t ReadBitsSlow(const uint8_t* stream, uint64_t pos, int bits) {
  uint64_t value = 0;
  int got = 0;
  while (got < bits) {
    const uint64_t byte = pos >> 3;
    const int shift = static_cast<int>(pos & 7);
    const int take = std::min(8 - shift, bits - got);
    const uint64_t chunk = (uint64_t{stream[byte]} >> shift) & ((uint64_t{1} << take) - 1);
    value |= chunk << got;
    got += take;
    pos += take;
  }
  return value;
}

}  // namespace

int BitsForRange(int64_t minimum, int64_t maximum) {
  if (maximum <= minimum) return 0;
  const uint64_t span = static_cast<uint64_t>(maximum) - static_cast<uint64_t>(minimum);
  return 64 - std::countl_zero(span);  // bits to hold values 0..span
}

void CheckStreamHolds(const Field& field, uint64_t stream_size, int64_t count, const std::string& where) {
  if (count <= 0) return;
  const uint64_t available_bits = stream_size * 8;
  const uint64_t needed_bits = static_cast<uint64_t>(count) * static_cast<uint64_t>(field.bits);
  if (field.bits > 0 && (needed_bits / static_cast<uint64_t>(field.bits) != static_cast<uint64_t>(count) ||
                         needed_bits > available_bits)) {
    ThrowInputError(where, "", field.name,
                    fmt::format("bytestream holds {} values of {} bits, the record count needs {}",
                                available_bits / field.bits, field.bits, count));
  }
}

void DecodeField(const Field& field, const uint8_t* stream, size_t stream_size, int64_t count, double* out,
                 const std::string& where) {
  if (count <= 0) return;
  CheckStreamHolds(field, stream_size, count, where);
  switch (field.type) {
    case Field::Type::kFloat:
      for (int64_t i = 0; i < count; ++i) out[i] = LoadLe<float>(stream + 4 * i);
      return;
    case Field::Type::kDouble:
      for (int64_t i = 0; i < count; ++i) out[i] = LoadLe<double>(stream + 8 * i);
      return;
    default:
      break;
  }
  const bool scaled = field.type == Field::Type::kScaledInteger;
  const int bits = field.bits;
  const uint64_t minimum = static_cast<uint64_t>(field.minimum);
  auto emit = [&](int64_t i, uint64_t raw) {
    const int64_t v = static_cast<int64_t>(raw + minimum);  // wraps like the two's-complement writer
    out[i] = scaled ? static_cast<double>(v) * field.scale + field.offset : static_cast<double>(v);
  };
  if (bits == 0) {
    for (int64_t i = 0; i < count; ++i) emit(i, 0);
    return;
  }
  const uint64_t mask = bits == 64 ? ~uint64_t{0} : (uint64_t{1} << bits) - 1;
  int64_t i = 0;
  if (bits <= 56) {
    // Fast path: one unaligned 64-bit load per value while 8 bytes remain.
    for (; i < count; ++i) {
      const uint64_t pos = static_cast<uint64_t>(i) * bits;
      const uint64_t byte = pos >> 3;
      if (byte + 8 > stream_size) break;
      emit(i, (LoadLe<uint64_t>(stream + byte) >> (pos & 7)) & mask);
    }
  }
  for (; i < count; ++i) emit(i, ReadBitsSlow(stream, static_cast<uint64_t>(i) * bits, bits));
}

void BitWriter::PutInteger(int64_t value, int64_t minimum) {
  PutRaw(static_cast<uint64_t>(value) - static_cast<uint64_t>(minimum), bits_);
}

void BitWriter::PutRaw(uint64_t value, int bits) {
  if (bits == 0) return;
  if (bits < 64) value &= (uint64_t{1} << bits) - 1;
  if (bits <= 56) {
    // Fast path (every field but doubles): pending_ < 8 after each call, so the value fits the accumulator
    // whole; flush its whole bytes at once.
    accumulator_ |= value << pending_;
    pending_ += bits;
    const int whole = pending_ >> 3;
    uint8_t out[8];
    for (int k = 0; k < whole; ++k) out[k] = static_cast<uint8_t>(accumulator_ >> (8 * k));
    bytes_.insert(bytes_.end(), out, out + whole);
    accumulator_ = whole == 8 ? 0 : accumulator_ >> (8 * whole);
    pending_ -= 8 * whole;
    return;
  }
  // accumulator_ holds pending_ (< 8 after each flush) bits; add the low part that fits, flush whole bytes.
  int done = 0;
  while (done < bits) {
    const int take = std::min(bits - done, 64 - pending_ > 56 ? 56 : 64 - pending_);
    const uint64_t part = take == 64 ? value : (value >> done) & ((uint64_t{1} << take) - 1);
    accumulator_ |= part << pending_;
    pending_ += take;
    done += take;
    while (pending_ >= 8) {
      bytes_.push_back(static_cast<uint8_t>(accumulator_ & 0xFF));
      accumulator_ >>= 8;
      pending_ -= 8;
    }
  }
}

void BitWriter::FlushPartialByte() {
  if (pending_ > 0) bytes_.push_back(static_cast<uint8_t>(accumulator_ & 0xFF));
  accumulator_ = 0;
  pending_ = 0;
}

void BitWriter::TakeFront(size_t n, uint8_t* out) {
  LIDARSHOP_CHECK(n <= bytes_.size());
  std::memcpy(out, bytes_.data(), n);
  bytes_.erase(bytes_.begin(), bytes_.begin() + static_cast<std::ptrdiff_t>(n));
}

std::vector<uint8_t> BitWriter::Finish() {
  if (pending_ > 0) bytes_.push_back(static_cast<uint8_t>(accumulator_ & 0xFF));
  accumulator_ = 0;
  pending_ = 0;
  return std::move(bytes_);
}

}  // namespace lidarshop::e57
