#include "lidarshop/inpaint/patch_difference.h"

// GCC 12 warns falsely inside its own AVX-512 reduction intrinsics.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wpsabi"
#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <string_view>

#include "lidarshop/util/error.h"

namespace lidarshop {

namespace {

enum class Kernel { kScalar, kAvx2, kAvx512 };

// LIDARSHOP_SSD_KERNEL=scalar|avx2 forces a slower kernel (for benchmarks and tests of the fallbacks).
Kernel DetectKernel() {
  __builtin_cpu_init();
  const char* forced = std::getenv("LIDARSHOP_SSD_KERNEL");
  if (forced != nullptr && std::string_view(forced) == "scalar") return Kernel::kScalar;
  if (forced != nullptr && (std::string_view(forced) == "avx2" || std::string_view(forced) == "avx2rows") &&
      __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) {
    return Kernel::kAvx2;
  }
  if (__builtin_cpu_supports("avx512f")) return Kernel::kAvx512;
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return Kernel::kAvx2;
  return Kernel::kScalar;
}

const Kernel kKernel = DetectKernel();

// LIDARSHOP_SSD_KERNEL=avx512rows keeps the generic per-row AVX-512 kernel (no unrolled kernel, no runs of
// candidates), for before/after benchmarks.
bool DetectUnrolled() {
  const char* forced = std::getenv("LIDARSHOP_SSD_KERNEL");
  return kKernel == Kernel::kAvx512 && !(forced != nullptr && std::string_view(forced) == "avx512rows");
}

const bool kUnrolled = DetectUnrolled();

// LIDARSHOP_SSD_KERNEL=avx2rows keeps the AVX2 kernel one candidate at a time (no runs), for before/after
// benchmarks.
bool DetectAvx2Runs() {
  const char* forced = std::getenv("LIDARSHOP_SSD_KERNEL");
  return kKernel == Kernel::kAvx2 && !(forced != nullptr && std::string_view(forced) == "avx2rows");
}

const bool kAvx2Runs = DetectAvx2Runs();

// Per target row: sqrt(weight) and target·sqrt(weight), so that
//   Σ (s·√w − t·√w)²  =  Σ w (s − t)²
// Only the span of 8-float blocks that hold a non-zero weight is evaluated (at the hole's rim about half of a
// patch is unknown); the stored rows are zero-padded by 16 floats, so a kernel may read up to one AVX-512
// vector past a span and every lane beyond it contributes exactly 0 whatever the (finite) source floats there
// are.
struct RowSpan {
  int64_t source_offset = 0;  // floats from the source patch's top-left pixel to the span's first float
  int stored_offset = 0;      // floats into sqrt_weight / target_times_sqrt_weight
  int blocks8 = 0;            // 8-float blocks in the span
};

struct PreparedRows {
  std::vector<RowSpan> spans;
  std::vector<float> sqrt_weight, target_times_sqrt_weight;
};

float ScalarSsd(const PreparedRows& p, const float* source_top_left, float bound) {
  float lanes[8] = {};
  for (const RowSpan& span : p.spans) {
    const float* s = source_top_left + span.source_offset;
    const float* sw = p.sqrt_weight.data() + span.stored_offset;
    const float* tw = p.target_times_sqrt_weight.data() + span.stored_offset;
    for (int v = 0; v < 8 * span.blocks8; ++v) {
      const float d = s[v] * sw[v] - tw[v];
      lanes[v & 7] += d * d;
    }
    float partial = 0.0f;
    for (float lane : lanes) partial += lane;
    if (partial > bound) return partial;
  }
  float sum = 0.0f;
  for (float lane : lanes) sum += lane;
  return sum;
}

__attribute__((target("avx2,fma"), always_inline)) inline float Avx2Reduce(__m256 s) {
  __m128 x = _mm_add_ps(_mm256_castps256_ps128(s), _mm256_extractf128_ps(s, 1));
  x = _mm_add_ps(x, _mm_movehl_ps(x, x));
  x = _mm_add_ss(x, _mm_shuffle_ps(x, x, 1));
  return _mm_cvtss_f32(x);
}

// Four accumulators (block index mod 4) keep the FMA dependency chains short.
__attribute__((target("avx2,fma"))) float Avx2Ssd(const PreparedRows& p, const float* source_top_left,
                                                  float bound) {
  __m256 acc[4] = {_mm256_setzero_ps(), _mm256_setzero_ps(), _mm256_setzero_ps(), _mm256_setzero_ps()};
  const size_t n = p.spans.size();
  for (size_t i = 0; i < n; ++i) {
    const RowSpan& span = p.spans[i];
    const float* s = source_top_left + span.source_offset;
    const float* sw = p.sqrt_weight.data() + span.stored_offset;
    const float* tw = p.target_times_sqrt_weight.data() + span.stored_offset;
    for (int b = 0; b < span.blocks8; ++b) {
      const __m256 d = _mm256_fmsub_ps(_mm256_loadu_ps(s + 8 * b), _mm256_loadu_ps(sw + 8 * b),
                                       _mm256_loadu_ps(tw + 8 * b));
      acc[b & 3] = _mm256_fmadd_ps(d, d, acc[b & 3]);
    }
    // Lanes only grow, so a partial sum above the bound proves the full sum is above it too.
    if ((i & 1) && i + 1 < n) {
      const float partial =
          Avx2Reduce(_mm256_add_ps(_mm256_add_ps(acc[0], acc[1]), _mm256_add_ps(acc[2], acc[3])));
      if (partial > bound) return partial;
    }
  }
  return Avx2Reduce(_mm256_add_ps(_mm256_add_ps(acc[0], acc[1]), _mm256_add_ps(acc[2], acc[3])));
}

// The four accumulators' sum, in Avx2Ssd's order.
__attribute__((target("avx2,fma"), always_inline)) inline float Avx2Sum4(const __m256* acc) {
  return Avx2Reduce(_mm256_add_ps(_mm256_add_ps(acc[0], acc[1]), _mm256_add_ps(acc[2], acc[3])));
}

// N adjacent candidates of a row per pass (EvaluateRun): the target's weights and values are loaded once per
// block for all of them. Each candidate keeps its own four accumulators, filled in the same order as
// Avx2Ssd's, so every sum that is returned in full is bit-identical to Avx2Ssd's; the pass stops early only
// when every candidate's partial sum is above the bound (and then returns values above it).
template <int N>
__attribute__((target("avx2,fma"))) void Avx2SsdRun(const PreparedRows& p, const float* source_top_left,
                                                    int64_t candidate_step, float bound, float* out) {
  __m256 acc[N][4];
  for (int c = 0; c < N; ++c)
    for (int a = 0; a < 4; ++a) acc[c][a] = _mm256_setzero_ps();
  const size_t n = p.spans.size();
  for (size_t i = 0; i < n; ++i) {
    const RowSpan& span = p.spans[i];
    const float* s = source_top_left + span.source_offset;
    const float* sw = p.sqrt_weight.data() + span.stored_offset;
    const float* tw = p.target_times_sqrt_weight.data() + span.stored_offset;
    for (int b = 0; b < span.blocks8; ++b) {
      const __m256 w = _mm256_loadu_ps(sw + 8 * b), t = _mm256_loadu_ps(tw + 8 * b);
      for (int c = 0; c < N; ++c) {
        const __m256 d = _mm256_fmsub_ps(_mm256_loadu_ps(s + c * candidate_step + 8 * b), w, t);
        acc[c][b & 3] = _mm256_fmadd_ps(d, d, acc[c][b & 3]);
      }
    }
    if ((i & 1) && i + 1 < n) {
      bool all_out = true;
      for (int c = 0; c < N && all_out; ++c) all_out = Avx2Sum4(acc[c]) > bound;
      if (all_out) break;
    }
  }
  for (int c = 0; c < N; ++c) out[c] = Avx2Sum4(acc[c]);
}

__attribute__((target("avx512f"))) float Avx512Ssd(const PreparedRows& p, const float* source_top_left,
                                                   float bound) {
  __m512 acc0 = _mm512_setzero_ps(), acc1 = _mm512_setzero_ps(), acc2 = _mm512_setzero_ps();
  const size_t n = p.spans.size();
  for (size_t i = 0; i < n; ++i) {
    const RowSpan& span = p.spans[i];
    const float* s = source_top_left + span.source_offset;
    const float* sw = p.sqrt_weight.data() + span.stored_offset;
    const float* tw = p.target_times_sqrt_weight.data() + span.stored_offset;
    const int blocks16 = (span.blocks8 + 1) / 2;
    int b = 0;
    for (; b + 3 <= blocks16; b += 3) {
      const __m512 d0 = _mm512_fmsub_ps(_mm512_loadu_ps(s + 16 * b), _mm512_loadu_ps(sw + 16 * b),
                                        _mm512_loadu_ps(tw + 16 * b));
      const __m512 d1 = _mm512_fmsub_ps(_mm512_loadu_ps(s + 16 * b + 16), _mm512_loadu_ps(sw + 16 * b + 16),
                                        _mm512_loadu_ps(tw + 16 * b + 16));
      const __m512 d2 = _mm512_fmsub_ps(_mm512_loadu_ps(s + 16 * b + 32), _mm512_loadu_ps(sw + 16 * b + 32),
                                        _mm512_loadu_ps(tw + 16 * b + 32));
      acc0 = _mm512_fmadd_ps(d0, d0, acc0);
      acc1 = _mm512_fmadd_ps(d1, d1, acc1);
      acc2 = _mm512_fmadd_ps(d2, d2, acc2);
    }
    if (b < blocks16) {
      const __m512 d0 = _mm512_fmsub_ps(_mm512_loadu_ps(s + 16 * b), _mm512_loadu_ps(sw + 16 * b),
                                        _mm512_loadu_ps(tw + 16 * b));
      acc0 = _mm512_fmadd_ps(d0, d0, acc0);
      if (b + 1 < blocks16) {
        const __m512 d1 = _mm512_fmsub_ps(_mm512_loadu_ps(s + 16 * b + 16), _mm512_loadu_ps(sw + 16 * b + 16),
                                          _mm512_loadu_ps(tw + 16 * b + 16));
        acc1 = _mm512_fmadd_ps(d1, d1, acc1);
      }
    }
    if ((i & 1) && i + 1 < n) {
      const float partial = _mm512_reduce_add_ps(_mm512_add_ps(_mm512_add_ps(acc0, acc1), acc2));
      if (partial > bound) return partial;
    }
  }
  return _mm512_reduce_add_ps(_mm512_add_ps(_mm512_add_ps(acc0, acc1), acc2));
}

// The unrolled AVX-512 kernel (V = 16-float vectors per patch row, 1..4). Per target row that holds a known
// pixel: the target's floats (times √w when the channel weights differ, else as they are) with zeros where
// unknown, and one lane mask per vector (known pixel and weight > 0). The source is read with masked loads,
// so masked lanes read nothing and contribute exactly 0. Equal non-zero weights (the common case) are
// factored out: Σ w (s − t)² = w · Σ (s − t)², one subtraction and one FMA per vector.
struct FastRows {
  int vectors = 0;                     // V
  bool uniform = true;                 // all non-zero channel weights equal: scale · Σ (s − t)²
  float scale = 1.0f;                  // that common weight (uniform only)
  std::vector<int64_t> source_offset;  // per stored row: floats from the source patch's top-left float
  std::vector<float> target;           // per stored row, 16·V floats
  std::vector<float> sqrt_weight;      // per stored row, 16·V floats (not uniform only)
  std::vector<__mmask16> masks;        // per stored row, V masks
};

// Early termination is checked every kCheckRows rows (a horizontal reduction per candidate costs about as
// much as a row).
constexpr int kCheckRows = 2;

template <int V>
__attribute__((target("avx512f"), always_inline)) inline float SumOf(const __m512* acc, float scale) {
  __m512 sum = acc[0];
#pragma GCC unroll 16
  for (int v = 1; v < V; ++v) sum = _mm512_add_ps(sum, acc[v]);
  return _mm512_reduce_add_ps(sum) * scale;
}

template <int V, int N, bool kUniform>
__attribute__((target("avx512f"))) void FastSsd(const FastRows& p, const float* source_top_left,
                                                int64_t candidate_step, float bound, float* out) {
  __m512 acc[N][V];
#pragma GCC unroll 16
  for (int c = 0; c < N; ++c)
#pragma GCC unroll 16
    for (int v = 0; v < V; ++v) acc[c][v] = _mm512_setzero_ps();
  const int rows = static_cast<int>(p.source_offset.size());
  const float* target = p.target.data();
  const float* sqrt_weight = p.sqrt_weight.data();
  const __mmask16* masks = p.masks.data();
  const bool check = bound < std::numeric_limits<float>::infinity();
  for (int i = 0; i < rows; ++i) {
    const float* s = source_top_left + p.source_offset[i];
#pragma GCC unroll 16
    for (int v = 0; v < V; ++v) {
      const __m512 t = _mm512_loadu_ps(target + 16 * (V * i + v));
      const __mmask16 m = masks[V * i + v];
      // Vectors without a known pixel (at the hole's rim, about half of the target) are skipped; the branch
      // takes the same way for every candidate of a target, so it is predicted.
      if (m == 0) continue;
      if constexpr (kUniform) {
#pragma GCC unroll 16
        for (int c = 0; c < N; ++c) {
          const __m512 d = _mm512_maskz_sub_ps(m, _mm512_loadu_ps(s + c * candidate_step + 16 * v), t);
          acc[c][v] = _mm512_fmadd_ps(d, d, acc[c][v]);
        }
      } else {
        const __m512 w = _mm512_loadu_ps(sqrt_weight + 16 * (V * i + v));
#pragma GCC unroll 16
        for (int c = 0; c < N; ++c) {
          const __m512 d = _mm512_maskz_fmsub_ps(m, _mm512_loadu_ps(s + c * candidate_step + 16 * v), w, t);
          acc[c][v] = _mm512_fmadd_ps(d, d, acc[c][v]);
        }
      }
    }
    // Lanes only grow, so partial sums above the bound prove the full sums are above it too; stop when every
    // candidate of the pass is out.
    if (check && i % kCheckRows == kCheckRows - 1 && i + 1 < rows) {
      bool all_out = true;
#pragma GCC unroll 16
      for (int c = 0; c < N && all_out; ++c) all_out = SumOf<V>(acc[c], p.scale) > bound;
      if (all_out) {
#pragma GCC unroll 16
        for (int c = 0; c < N; ++c) out[c] = SumOf<V>(acc[c], p.scale);
        return;
      }
    }
  }
#pragma GCC unroll 16
  for (int c = 0; c < N; ++c) out[c] = SumOf<V>(acc[c], p.scale);
}

using FastKernel = void (*)(const FastRows&, const float*, int64_t, float, float*);

template <int N>
FastKernel PickFast(int vectors, bool uniform) {
  switch (vectors) {
    case 1:
      return uniform ? FastSsd<1, N, true> : FastSsd<1, N, false>;
    case 2:
      return uniform ? FastSsd<2, N, true> : FastSsd<2, N, false>;
    case 3:
      return uniform ? FastSsd<3, N, true> : FastSsd<3, N, false>;
    case 4:
      return uniform ? FastSsd<4, N, true> : FastSsd<4, N, false>;
    default:
      return nullptr;
  }
}

constexpr int kRun = 4;  // candidates per pass of EvaluateRun

class WeightedSsdTarget : public TargetDifference {
 public:
  WeightedSsdTarget(const InpaintCanvas& canvas, Pixel target, const std::vector<float>& channel_weights)
      : canvas_(canvas) {
    const int R = canvas.patch_radius(), C = canvas.channels(), side = 2 * R + 1;
    const int row_floats = side * C;
    if (kUnrolled && row_floats <= 64) {
      PrepareFast(target, channel_weights);
      return;
    }
    const int padded = (row_floats + 7) / 8 * 8;
    std::vector<float> sw(padded), tw(padded);
    for (int i = 0; i < side; ++i) {
      const int r = target.row - R + i;
      if (r < 0 || r >= canvas.rows()) continue;
      std::fill(sw.begin(), sw.end(), 0.0f);
      std::fill(tw.begin(), tw.end(), 0.0f);
      int first = padded, last = -1;
      for (int j = 0; j < side; ++j) {
        const int c = target.col - R + j;
        if (c < 0 || c >= canvas.cols() || !canvas.IsKnown(r, c)) continue;
        const float* t = canvas.PixelData(r, c);
        for (int k = 0; k < C; ++k) {
          const float w = channel_weights.empty() ? 1.0f : channel_weights[k];
          if (w == 0.0f) continue;
          const float root = std::sqrt(w);
          sw[j * C + k] = root;
          tw[j * C + k] = t[k] * root;
          first = std::min(first, j * C + k);
          last = std::max(last, j * C + k);
        }
      }
      if (last < 0) continue;
      RowSpan span;
      const int first_block = first / 8, end_block = last / 8 + 1;
      span.blocks8 = end_block - first_block;
      span.source_offset = int64_t{i} * canvas.row_stride() + 8 * first_block;
      span.stored_offset = static_cast<int>(prepared_.sqrt_weight.size());
      prepared_.sqrt_weight.insert(prepared_.sqrt_weight.end(), sw.begin() + 8 * first_block,
                                   sw.begin() + 8 * end_block);
      prepared_.target_times_sqrt_weight.insert(prepared_.target_times_sqrt_weight.end(),
                                                tw.begin() + 8 * first_block, tw.begin() + 8 * end_block);
      // Zero padding so that 16-float loads past the span read weights of 0.
      prepared_.sqrt_weight.insert(prepared_.sqrt_weight.end(), 16, 0.0f);
      prepared_.target_times_sqrt_weight.insert(prepared_.target_times_sqrt_weight.end(), 16, 0.0f);
      prepared_.spans.push_back(span);
    }
  }

  float Evaluate(Pixel source, float bound) const override {
    const int R = canvas_.patch_radius();
    const float* top_left = canvas_.PixelData(source.row - R, source.col - R);
    if (fast_single_ != nullptr) {
      float out;
      fast_single_(fast_, top_left, 0, bound, &out);
      return out;
    }
    switch (kKernel) {
      case Kernel::kAvx512:
        return Avx512Ssd(prepared_, top_left, bound);
      case Kernel::kAvx2:
        return Avx2Ssd(prepared_, top_left, bound);
      default:
        return ScalarSsd(prepared_, top_left, bound);
    }
  }

  void EvaluateRun(Pixel source, int count, float bound, float* out) const override {
    const int R = canvas_.patch_radius(), C = canvas_.channels();
    int i = 0;
    if (fast_run_ != nullptr) {
      for (; i + kRun <= count; i += kRun)
        fast_run_(fast_, canvas_.PixelData(source.row - R, source.col + i - R), C, bound, out + i);
    }
    if (fast_run_ == nullptr && kAvx2Runs) {
      // Fours, then pairs (measured on fill_bench: fours save more target loads than the register spills of
      // their 16 accumulators cost).
      for (; i + 4 <= count; i += 4)
        Avx2SsdRun<4>(prepared_, canvas_.PixelData(source.row - R, source.col + i - R), C, bound, out + i);
      for (; i + 2 <= count; i += 2)
        Avx2SsdRun<2>(prepared_, canvas_.PixelData(source.row - R, source.col + i - R), C, bound, out + i);
    }
    for (; i < count; ++i) out[i] = Evaluate({source.row, source.col + i}, bound);
  }

 private:
  void PrepareFast(Pixel target, const std::vector<float>& channel_weights) {
    const InpaintCanvas& canvas = canvas_;
    const int R = canvas.patch_radius(), C = canvas.channels(), side = 2 * R + 1;
    const int V = (side * C + 15) / 16;
    fast_.vectors = V;
    float common = -1.0f;
    for (int k = 0; k < C; ++k) {
      const float w = channel_weights.empty() ? 1.0f : channel_weights[k];
      if (w == 0.0f) continue;
      if (common < 0.0f) common = w;
      if (w != common) fast_.uniform = false;
    }
    fast_.scale = fast_.uniform && common > 0.0f ? common : 1.0f;
    std::vector<float> t(16 * V), sw(16 * V);
    std::vector<__mmask16> m(V);
    struct StoredRow {
      int lanes, index;
      std::vector<float> target, sqrt_weight;
      std::vector<__mmask16> masks;
    };
    std::vector<StoredRow> rows;
    for (int i = 0; i < side; ++i) {
      const int r = target.row - R + i;
      if (r < 0 || r >= canvas.rows()) continue;
      std::fill(t.begin(), t.end(), 0.0f);
      std::fill(sw.begin(), sw.end(), 0.0f);
      std::fill(m.begin(), m.end(), __mmask16{0});
      bool any = false;
      for (int j = 0; j < side; ++j) {
        const int c = target.col - R + j;
        if (c < 0 || c >= canvas.cols() || !canvas.IsKnown(r, c)) continue;
        const float* value = canvas.PixelData(r, c);
        for (int k = 0; k < C; ++k) {
          const float w = channel_weights.empty() ? 1.0f : channel_weights[k];
          if (w == 0.0f) continue;
          const int lane = j * C + k;
          const float root = fast_.uniform ? 1.0f : std::sqrt(w);
          t[lane] = value[k] * root;
          sw[lane] = root;
          m[lane / 16] = static_cast<__mmask16>(m[lane / 16] | (1u << (lane % 16)));
          any = true;
        }
      }
      if (!any) continue;
      int lanes = 0;
      for (__mmask16 mask : m) lanes += __builtin_popcount(mask);
      rows.push_back({lanes, i, t, sw, m});
    }
    // Rows with the most known floats first: the partial sums grow fastest, so early termination comes
    // sooner (the sum's order is fixed per target, so Evaluate and EvaluateRun still agree bit for bit).
    std::stable_sort(rows.begin(), rows.end(),
                     [](const StoredRow& a, const StoredRow& b) { return a.lanes > b.lanes; });
    for (const StoredRow& row : rows) {
      fast_.source_offset.push_back(int64_t{row.index} * canvas.row_stride());
      fast_.target.insert(fast_.target.end(), row.target.begin(), row.target.end());
      if (!fast_.uniform)
        fast_.sqrt_weight.insert(fast_.sqrt_weight.end(), row.sqrt_weight.begin(), row.sqrt_weight.end());
      fast_.masks.insert(fast_.masks.end(), row.masks.begin(), row.masks.end());
    }
    fast_single_ = PickFast<1>(V, fast_.uniform);
    fast_run_ = PickFast<kRun>(V, fast_.uniform);
  }

  const InpaintCanvas& canvas_;
  PreparedRows prepared_;
  FastRows fast_;
  FastKernel fast_single_ = nullptr, fast_run_ = nullptr;
};

}  // namespace

WeightedSsd::WeightedSsd(std::vector<float> channel_weights) : channel_weights_(std::move(channel_weights)) {
  for (float w : channel_weights_)
    CheckOption(std::isfinite(w) && w >= 0.0f, "WeightedSsd: channel weights must be >= 0");
}

std::unique_ptr<TargetDifference> WeightedSsd::ForTarget(const InpaintCanvas& canvas, Pixel target) const {
  if (!channel_weights_.empty() && static_cast<int>(channel_weights_.size()) != canvas.channels()) {
    throw OptionsError(fmt::format("WeightedSsd: {} channel weights for an image of {} channels",
                                   channel_weights_.size(), canvas.channels()));
  }
  return std::make_unique<WeightedSsdTarget>(canvas, target, channel_weights_);
}

const char* WeightedSsd::KernelName() {
  switch (kKernel) {
    case Kernel::kAvx512:
      return kUnrolled ? "avx512 unrolled" : "avx512 rows";
    case Kernel::kAvx2:
      return "avx2";
    default:
      return "scalar";
  }
}

}  // namespace lidarshop
