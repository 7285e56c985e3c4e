// LASzip's POINT14 decompressor, version 3 (LAZ specification, "LASzip for LAS 1.4"): the 30 bytes point
// formats 6-10 start with, coded in nine layers, with the previous point of the same scanner channel as the
// prediction (four contexts).
//   0  X, Y, Z         int32 x 3         14 return number (4 bits), number of returns (4 bits)
//   12 intensity       uint16            15 classification flags (4), scanner channel (2), scan direction, edge
//   16 classification  17 user data      18 scan angle (int16)   20 point source ID (uint16)   22 GPS time
#include <array>
#include <optional>

#include "lidarshop/io/laz_items.h"

namespace lidarshop::laz {

const uint8_t kNumberReturnMap6Ctx[16][16] = {
    {0, 1, 2, 3, 4, 5, 3, 4, 4, 5, 5, 5, 5, 5, 5, 5}, {1, 0, 1, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3},
    {2, 1, 2, 4, 4, 4, 4, 4, 4, 4, 4, 3, 3, 3, 3, 3}, {3, 3, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
    {4, 3, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4}, {5, 3, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
    {3, 3, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4}, {4, 3, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4},
    {4, 3, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4}, {5, 3, 4, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4},
    {5, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4}, {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 4, 4, 4},
    {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5, 4, 4}, {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5, 4},
    {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5}, {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5}};

namespace {

// The specification's number_return_level_8ctx: |n - r| capped at 7.
int ReturnLevel8(int n, int r) { return std::min(n > r ? n - r : r - n, 7); }

struct Point14 {
  int32_t x, y, z;
  uint16_t intensity;
  uint8_t return_number, number_of_returns;
  uint8_t classification_flags, scanner_channel, scan_direction, edge;
  uint8_t classification, user_data;
  int16_t scan_angle;
  uint16_t point_source_id;
  uint64_t gps_time;
  bool gps_time_change = false;  // whether this point's GPS time differed from its predecessor's

  static Point14 Load(const uint8_t* p) {
    Point14 q;
    q.x = LoadLe<int32_t>(p);
    q.y = LoadLe<int32_t>(p + 4);
    q.z = LoadLe<int32_t>(p + 8);
    q.intensity = LoadLe<uint16_t>(p + 12);
    q.return_number = p[14] & 15;
    q.number_of_returns = p[14] >> 4;
    q.classification_flags = p[15] & 15;
    q.scanner_channel = (p[15] >> 4) & 3;
    q.scan_direction = (p[15] >> 6) & 1;
    q.edge = p[15] >> 7;
    q.classification = p[16];
    q.user_data = p[17];
    q.scan_angle = LoadLe<int16_t>(p + 18);
    q.point_source_id = LoadLe<uint16_t>(p + 20);
    q.gps_time = LoadLe<uint64_t>(p + 22);
    return q;
  }
  void Store(uint8_t* p) const {
    StoreLe(p, x);
    StoreLe(p + 4, y);
    StoreLe(p + 8, z);
    StoreLe(p + 12, intensity);
    p[14] = static_cast<uint8_t>(return_number | (number_of_returns << 4));
    p[15] = static_cast<uint8_t>(classification_flags | (scanner_channel << 4) | (scan_direction << 6) |
                                 (edge << 7));
    p[16] = classification;
    p[17] = user_data;
    StoreLe(p + 18, scan_angle);
    StoreLe(p + 20, point_source_id);
    StoreLe(p + 22, gps_time);
  }
};

enum LayerIndex {
  kLayerXy,
  kLayerZ,
  kLayerClassification,
  kLayerFlags,
  kLayerIntensity,
  kLayerScanAngle,
  kLayerUserData,
  kLayerPointSource,
  kLayerGpsTime,
  kLayers
};

// The models and predictions of one scanner channel.
struct Channel {
  Channel(std::array<ArithmeticDecoder, kLayers>& d, const Point14& from)
      : changed_values{SymbolModel(128), SymbolModel(128), SymbolModel(128), SymbolModel(128),
                       SymbolModel(128), SymbolModel(128), SymbolModel(128), SymbolModel(128)},
        scanner_channel(3),
        return_number_gps_same(13),
        dx(d[kLayerXy], 32, 2),
        dy(d[kLayerXy], 32, 22),
        z(d[kLayerZ], 32, 20),
        intensity(d[kLayerIntensity], 16, 4),
        scan_angle(d[kLayerScanAngle], 16, 2),
        point_source_id(d[kLayerPointSource], 16),
        gpstime_multi(kMultiTotal),
        gpstime_0diff(5),
        gpstime(d[kLayerGpsTime], 32, 9),
        last(from) {
    last_z.fill(from.z);
    last_intensity.fill(from.intensity);
    last_gpstime[0] = from.gps_time;
    last.gps_time_change = false;
  }

  static constexpr int32_t kMulti = 500;
  static constexpr int32_t kMultiMinus = -10;
  static constexpr uint32_t kMultiCodeFull = kMulti - kMultiMinus + 1;
  static constexpr uint32_t kMultiTotal = kMulti - kMultiMinus + 5;

  std::array<SymbolModel, 8> changed_values;
  SymbolModel scanner_channel;
  std::array<std::optional<SymbolModel>, 16> number_of_returns, return_number;
  SymbolModel return_number_gps_same;
  IntegerDecompressor dx, dy, z;
  std::array<std::optional<SymbolModel>, 64> classification, flags, user_data;
  IntegerDecompressor intensity, scan_angle, point_source_id;
  SymbolModel gpstime_multi, gpstime_0diff;
  IntegerDecompressor gpstime;

  std::array<StreamingMedian5, 12> x_median, y_median;
  std::array<int32_t, 8> last_z;
  std::array<uint16_t, 8> last_intensity;
  uint32_t last_seq = 0, next_seq = 0;
  std::array<uint64_t, 4> last_gpstime{};
  std::array<int32_t, 4> last_diff{};
  std::array<int32_t, 4> extreme_counter{};
  Point14 last;
};

class Point14V3 final : public LayeredItemDecoder {
 public:
  int LayerCount() const override { return kLayers; }

  void Start(const uint8_t* first, std::span<const Layer> layers, uint32_t& context) override {
    for (int i = 0; i < kLayers; ++i) {
      changed_[i] = !layers[i].empty();
      if (changed_[i]) decoders_[i].Start(layers[i].data(), layers[i].data() + layers[i].size());
    }
    const Point14 point = Point14::Load(first);
    current_ = point.scanner_channel;
    channels_[current_].emplace(decoders_, point);
    context = current_;
  }

  void Decode(uint8_t* item, uint32_t& context) override {
    ArithmeticDecoder& xy = decoders_[kLayerXy];
    Channel* c = &*channels_[current_];
    // Context of the previous point (of any channel): first / last return, and whether its time changed.
    uint32_t lpr = (c->last.return_number == 1 ? 1 : 0) +
                   (c->last.return_number >= c->last.number_of_returns ? 2 : 0) +
                   (c->last.gps_time_change ? 4 : 0);
    const uint32_t changed_values = xy.DecodeSymbol(c->changed_values[lpr]);
    if (changed_values & (1 << 6)) {
      const uint32_t diff = xy.DecodeSymbol(c->scanner_channel);
      const uint32_t channel = (current_ + diff + 1) % 4;
      // A channel's first point predicts from the previous point of whichever channel.
      if (!channels_[channel]) channels_[channel].emplace(decoders_, c->last);
      current_ = channel;
      c = &*channels_[current_];
      c->last.scanner_channel = static_cast<uint8_t>(channel);
    }
    context = current_;
    Point14& last = c->last;
    const bool point_source_change = changed_values & (1 << 5);
    const bool gps_time_change = changed_values & (1 << 4);
    const bool scan_angle_change = changed_values & (1 << 3);

    const uint32_t last_n = last.number_of_returns;
    const uint32_t last_r = last.return_number;
    uint32_t n = last_n;
    if (changed_values & (1 << 2)) {
      n = xy.DecodeSymbol(Lazy(c->number_of_returns[last_n], 16));
      last.number_of_returns = static_cast<uint8_t>(n);
    }
    uint32_t r = last_r;
    switch (changed_values & 3) {
      case 1:
        r = (last_r + 1) % 16;
        break;
      case 2:
        r = (last_r + 15) % 16;
        break;
      case 3:
        if (gps_time_change) {
          r = xy.DecodeSymbol(Lazy(c->return_number[last_r], 16));
        } else {
          r = (last_r + xy.DecodeSymbol(c->return_number_gps_same) + 2) % 16;
        }
        break;
      default:
        break;
    }
    last.return_number = static_cast<uint8_t>(r);

    const uint32_t m = kNumberReturnMap6Ctx[n][r];
    const uint32_t l = ReturnLevel8(static_cast<int>(n), static_cast<int>(r));
    const uint32_t cpr = (r == 1 ? 2 : 0) + (r >= n ? 1 : 0);  // single 3, first 2, last 1, middle 0

    const uint32_t mc = (m << 1) | (gps_time_change ? 1 : 0);
    const int32_t dx = c->dx.Decompress(c->x_median[mc].Get(), n == 1);
    last.x = static_cast<int32_t>(static_cast<uint32_t>(last.x) + static_cast<uint32_t>(dx));
    c->x_median[mc].Add(dx);
    uint32_t k_bits = c->dx.k();
    const int32_t dy =
        c->dy.Decompress(c->y_median[mc].Get(), (n == 1) + (k_bits < 20 ? (k_bits & ~1u) : 20));
    last.y = static_cast<int32_t>(static_cast<uint32_t>(last.y) + static_cast<uint32_t>(dy));
    c->y_median[mc].Add(dy);

    if (changed_[kLayerZ]) {
      k_bits = (c->dx.k() + c->dy.k()) / 2;
      last.z = c->z.Decompress(c->last_z[l], (n == 1) + (k_bits < 18 ? (k_bits & ~1u) : 18));
      c->last_z[l] = last.z;
    }
    if (changed_[kLayerClassification]) {
      const uint32_t ccc = ((last.classification & 0x1F) << 1) + (cpr == 3 ? 1 : 0);
      last.classification = static_cast<uint8_t>(
          decoders_[kLayerClassification].DecodeSymbol(Lazy(c->classification[ccc], 256)));
    }
    if (changed_[kLayerFlags]) {
      const uint32_t last_flags = (last.edge << 5) | (last.scan_direction << 4) | last.classification_flags;
      const uint32_t flags = decoders_[kLayerFlags].DecodeSymbol(Lazy(c->flags[last_flags], 64));
      last.edge = (flags >> 5) & 1;
      last.scan_direction = (flags >> 4) & 1;
      last.classification_flags = flags & 15;
    }
    if (changed_[kLayerIntensity]) {
      const uint32_t ic = (cpr << 1) | (gps_time_change ? 1 : 0);
      last.intensity = static_cast<uint16_t>(c->intensity.Decompress(c->last_intensity[ic], cpr));
      c->last_intensity[ic] = last.intensity;
    }
    if (changed_[kLayerScanAngle] && scan_angle_change) {
      last.scan_angle = static_cast<int16_t>(c->scan_angle.Decompress(last.scan_angle, gps_time_change));
    }
    if (changed_[kLayerUserData]) {
      last.user_data = static_cast<uint8_t>(
          decoders_[kLayerUserData].DecodeSymbol(Lazy(c->user_data[last.user_data / 4], 256)));
    }
    if (changed_[kLayerPointSource] && point_source_change) {
      last.point_source_id = static_cast<uint16_t>(c->point_source_id.Decompress(last.point_source_id));
    }
    if (changed_[kLayerGpsTime] && gps_time_change) {
      DecodeGpsTime(*c);
      last.gps_time = c->last_gpstime[c->last_seq];
    }
    last.Store(item);
    last.gps_time_change = gps_time_change;
  }

 private:
  // As GPSTIME11 version 2, without the "unchanged" case (the XY layer says whether the time changed).
  void DecodeGpsTime(Channel& c) {
    ArithmeticDecoder& d = decoders_[kLayerGpsTime];
    for (int switches = 0;; ++switches) {
      if (switches > 1) throw LazCorrupt("the GPS time switches sequence twice for one point");
      uint32_t& last = c.last_seq;
      if (c.last_diff[last] == 0) {
        const uint32_t multi = d.DecodeSymbol(c.gpstime_0diff);
        if (multi == 0) {
          c.last_diff[last] = c.gpstime.Decompress(0, 0);
          c.last_gpstime[last] += static_cast<int64_t>(c.last_diff[last]);
          c.extreme_counter[last] = 0;
        } else if (multi == 1) {
          NewSequence(c, d);
        } else {
          last = (last + multi - 1) & 3;
          continue;
        }
      } else {
        const uint32_t multi = d.DecodeSymbol(c.gpstime_multi);
        if (multi == 1) {
          c.last_gpstime[last] += static_cast<int64_t>(c.gpstime.Decompress(c.last_diff[last], 1));
          c.extreme_counter[last] = 0;
        } else if (multi < Channel::kMultiCodeFull) {
          c.last_gpstime[last] += static_cast<int64_t>(DecodeMultiple(c, static_cast<int32_t>(multi)));
        } else if (multi == Channel::kMultiCodeFull) {
          NewSequence(c, d);
        } else {
          last = (last + multi - Channel::kMultiCodeFull) & 3;
          continue;
        }
      }
      return;
    }
  }

  static int32_t DecodeMultiple(Channel& c, int32_t multi) {
    const uint32_t last = c.last_seq;
    const int32_t last_diff = c.last_diff[last];
    int32_t diff;
    auto count_extreme = [&] {
      if (++c.extreme_counter[last] > 3) {
        c.last_diff[last] = diff;
        c.extreme_counter[last] = 0;
      }
    };
    if (multi == 0) {
      diff = c.gpstime.Decompress(0, 7);
      count_extreme();
    } else if (multi < Channel::kMulti) {
      diff = c.gpstime.Decompress(static_cast<int32_t>(Times(multi, last_diff)), multi < 10 ? 2 : 3);
    } else if (multi == Channel::kMulti) {
      diff = c.gpstime.Decompress(static_cast<int32_t>(Times(Channel::kMulti, last_diff)), 4);
      count_extreme();
    } else {
      const int32_t negative = Channel::kMulti - multi;
      if (negative > Channel::kMultiMinus) {
        diff = c.gpstime.Decompress(static_cast<int32_t>(Times(negative, last_diff)), 5);
      } else {
        diff = c.gpstime.Decompress(static_cast<int32_t>(Times(Channel::kMultiMinus, last_diff)), 6);
        count_extreme();
      }
    }
    return diff;
  }

  static void NewSequence(Channel& c, ArithmeticDecoder& d) {
    c.next_seq = (c.next_seq + 1) & 3;
    const auto high = static_cast<uint32_t>(c.gpstime.Decompress(
        static_cast<int32_t>(static_cast<uint32_t>(c.last_gpstime[c.last_seq] >> 32)), 8));
    c.last_gpstime[c.next_seq] = (static_cast<uint64_t>(high) << 32) | d.ReadInt();
    c.last_seq = c.next_seq;
    c.last_diff[c.last_seq] = 0;
    c.extreme_counter[c.last_seq] = 0;
  }

  std::array<ArithmeticDecoder, kLayers> decoders_;
  std::array<bool, kLayers> changed_{};
  std::array<std::optional<Channel>, 4> channels_;
  uint32_t current_ = 0;
};

}  // namespace

std::unique_ptr<LayeredItemDecoder> MakePoint14Decoder() { return std::make_unique<Point14V3>(); }

}  // namespace lidarshop::laz
