// LASzip's POINT10 decompressors, versions 1 and 2 (LAZ specification): the 20 bytes every point format
// 0-5 starts with.
//   0  X, Y, Z       int32 x 3
//   12 intensity     uint16
//   14 return bits   return number (3), number of returns (3), scan direction, edge of flight line
//   15 classification, 16 scan angle rank (int8), 17 user data, 18 point source ID (uint16)
#include <array>
#include <optional>

#include "lidarshop/io/laz_items.h"

namespace lidarshop::laz {

const uint8_t kNumberReturnMap[8][8] = {{15, 14, 13, 12, 11, 10, 9, 8},  {14, 0, 1, 3, 6, 10, 10, 9},
                                        {13, 1, 2, 4, 7, 11, 11, 10},    {12, 3, 4, 5, 8, 12, 12, 11},
                                        {11, 6, 7, 8, 9, 13, 13, 12},    {10, 10, 11, 12, 13, 14, 14, 13},
                                        {9, 10, 11, 12, 13, 14, 15, 14}, {8, 9, 10, 11, 12, 13, 14, 15}};
// |n - r|: how many returns of the pulse came before.
const uint8_t kNumberReturnLevel[8][8] = {
    {0, 1, 2, 3, 4, 5, 6, 7}, {1, 0, 1, 2, 3, 4, 5, 6}, {2, 1, 0, 1, 2, 3, 4, 5}, {3, 2, 1, 0, 1, 2, 3, 4},
    {4, 3, 2, 1, 0, 1, 2, 3}, {5, 4, 3, 2, 1, 0, 1, 2}, {6, 5, 4, 3, 2, 1, 0, 1}, {7, 6, 5, 4, 3, 2, 1, 0}};

namespace {

constexpr int kX = 0, kY = 4, kZ = 8, kIntensity = 12, kReturnBits = 14, kClassification = 15,
              kScanAngleRank = 16, kUserData = 17, kPointSourceId = 18;

int ReturnNumber(const uint8_t* p) { return p[kReturnBits] & 7; }
int NumberOfReturns(const uint8_t* p) { return (p[kReturnBits] >> 3) & 7; }
void AddToInt32(uint8_t* p, int32_t diff) {
  StoreLe<uint32_t>(p, LoadLe<uint32_t>(p) + static_cast<uint32_t>(diff));
}

// Version 2: the return counts pick the contexts of the coordinates and the intensity; x and y are predicted
// by the median of the last five differences of the same return kind.
// User data (bit 1 of `changed`) and point source ID (bit 0), decoded alike by POINT10 v1 and v2.
void DecodeUserDataAndSourceId(uint32_t changed, ArithmeticDecoder& d,
                               std::array<std::optional<SymbolModel>, 256>& user_data,
                               IntegerDecompressor& point_source_id, uint8_t* last) {
  if (changed & 2) {
    last[kUserData] = static_cast<uint8_t>(d.DecodeSymbol(Lazy(user_data[last[kUserData]], 256)));
  }
  if (changed & 1) {
    StoreLe<uint16_t>(
        last + kPointSourceId,
        static_cast<uint16_t>(point_source_id.Decompress(LoadLe<uint16_t>(last + kPointSourceId))));
  }
}

class Point10V2 final : public PointwiseItemDecoder {
 public:
  Point10V2(ArithmeticDecoder& decoder, const uint8_t* first)
      : d_(decoder),
        changed_values_(64),
        scan_angle_rank_{SymbolModel(256), SymbolModel(256)},
        intensity_(decoder, 16, 4),
        point_source_id_(decoder, 16),
        dx_(decoder, 32, 2),
        dy_(decoder, 32, 22),
        z_(decoder, 32, 20) {
    std::memcpy(last_, first, 20);
    StoreLe<uint16_t>(last_ + kIntensity, 0);  // LASzip starts the intensity prediction at 0
  }

  void Decode(uint8_t* item) override {
    const uint32_t changed = d_.DecodeSymbol(changed_values_);
    if (changed & 32) {
      last_[kReturnBits] = static_cast<uint8_t>(d_.DecodeSymbol(Lazy(bit_byte_[last_[kReturnBits]], 256)));
    }
    const int r = ReturnNumber(last_);
    const int n = NumberOfReturns(last_);
    const int m = kNumberReturnMap[n][r];
    const int l = kNumberReturnLevel[n][r];
    if (changed & 16) {
      const auto intensity = static_cast<uint16_t>(intensity_.Decompress(last_intensity_[m], m < 3 ? m : 3));
      StoreLe<uint16_t>(last_ + kIntensity, intensity);
      last_intensity_[m] = intensity;
    } else {
      StoreLe<uint16_t>(last_ + kIntensity, last_intensity_[m]);
    }
    if (changed & 8) {
      last_[kClassification] =
          static_cast<uint8_t>(d_.DecodeSymbol(Lazy(classification_[last_[kClassification]], 256)));
    }
    if (changed & 4) {
      const int scan_direction = (last_[kReturnBits] >> 6) & 1;
      const uint32_t diff = d_.DecodeSymbol(scan_angle_rank_[scan_direction]);
      last_[kScanAngleRank] = FoldByte(static_cast<int32_t>(diff + last_[kScanAngleRank]));
    }
    DecodeUserDataAndSourceId(changed, d_, user_data_, point_source_id_, last_);

    const int32_t dx = dx_.Decompress(x_median_[m].Get(), n == 1);
    AddToInt32(last_ + kX, dx);
    x_median_[m].Add(dx);
    uint32_t k_bits = dx_.k();
    const int32_t dy = dy_.Decompress(y_median_[m].Get(), (n == 1) + (k_bits < 20 ? (k_bits & ~1u) : 20));
    AddToInt32(last_ + kY, dy);
    y_median_[m].Add(dy);
    k_bits = (dx_.k() + dy_.k()) / 2;
    const int32_t z = z_.Decompress(last_height_[l], (n == 1) + (k_bits < 18 ? (k_bits & ~1u) : 18));
    StoreLe<int32_t>(last_ + kZ, z);
    last_height_[l] = z;
    std::memcpy(item, last_, 20);
  }

 private:
  ArithmeticDecoder& d_;
  uint8_t last_[20];
  SymbolModel changed_values_;
  std::array<SymbolModel, 2> scan_angle_rank_;
  std::array<std::optional<SymbolModel>, 256> bit_byte_, classification_, user_data_;
  IntegerDecompressor intensity_, point_source_id_, dx_, dy_, z_;
  std::array<uint16_t, 16> last_intensity_{};
  std::array<StreamingMedian5, 16> x_median_, y_median_;
  std::array<int32_t, 8> last_height_{};
};

// Version 1 (LASzip 1.0-1.3 files): x and y predicted by the median of the last three differences, the
// attributes after the coordinates.
class Point10V1 final : public PointwiseItemDecoder {
 public:
  Point10V1(ArithmeticDecoder& decoder, const uint8_t* first)
      : d_(decoder),
        dx_(decoder, 32),
        dy_(decoder, 32, 20),
        z_(decoder, 32, 20),
        intensity_(decoder, 16),
        scan_angle_rank_(decoder, 8, 2),
        point_source_id_(decoder, 16),
        changed_values_(64) {
    std::memcpy(last_, first, 20);
  }

  void Decode(uint8_t* item) override {
    const int32_t median_x = Median3(last_x_diff_);
    const int32_t median_y = Median3(last_y_diff_);
    const int32_t x_diff = dx_.Decompress(median_x);
    AddToInt32(last_ + kX, x_diff);
    uint32_t k_bits = dx_.k();
    const int32_t y_diff = dy_.Decompress(median_y, k_bits < 19 ? k_bits : 19);
    AddToInt32(last_ + kY, y_diff);
    k_bits = (k_bits + dy_.k()) / 2;
    StoreLe<int32_t>(last_ + kZ, z_.Decompress(LoadLe<int32_t>(last_ + kZ), k_bits < 19 ? k_bits : 19));

    const uint32_t changed = d_.DecodeSymbol(changed_values_);
    if (changed & 32) {
      StoreLe<uint16_t>(last_ + kIntensity,
                        static_cast<uint16_t>(intensity_.Decompress(LoadLe<uint16_t>(last_ + kIntensity))));
    }
    if (changed & 16) {
      last_[kReturnBits] = static_cast<uint8_t>(d_.DecodeSymbol(Lazy(bit_byte_[last_[kReturnBits]], 256)));
    }
    if (changed & 8) {
      last_[kClassification] =
          static_cast<uint8_t>(d_.DecodeSymbol(Lazy(classification_[last_[kClassification]], 256)));
    }
    if (changed & 4) {
      last_[kScanAngleRank] =
          static_cast<uint8_t>(scan_angle_rank_.Decompress(last_[kScanAngleRank], k_bits < 3));
    }
    DecodeUserDataAndSourceId(changed, d_, user_data_, point_source_id_, last_);
    last_x_diff_[last_incr_] = x_diff;
    last_y_diff_[last_incr_] = y_diff;
    last_incr_ = (last_incr_ + 1) % 3;
    std::memcpy(item, last_, 20);
  }

 private:
  static int32_t Median3(const std::array<int32_t, 3>& d) {
    if (d[0] < d[1]) {
      if (d[1] < d[2]) return d[1];
      if (d[0] < d[2]) return d[2];
      return d[0];
    }
    if (d[0] < d[2]) return d[0];
    if (d[1] < d[2]) return d[2];
    return d[1];
  }

  ArithmeticDecoder& d_;
  uint8_t last_[20];
  IntegerDecompressor dx_, dy_, z_, intensity_, scan_angle_rank_, point_source_id_;
  SymbolModel changed_values_;
  std::array<std::optional<SymbolModel>, 256> bit_byte_, classification_, user_data_;
  std::array<int32_t, 3> last_x_diff_{}, last_y_diff_{};
  int last_incr_ = 0;
};

}  // namespace

std::unique_ptr<PointwiseItemDecoder> MakePoint10Decoder(uint16_t version, ArithmeticDecoder& decoder,
                                                         const uint8_t* first) {
  if (version == 1) return std::make_unique<Point10V1>(decoder, first);
  if (version == 2) return std::make_unique<Point10V2>(decoder, first);
  return nullptr;
}

}  // namespace lidarshop::laz
