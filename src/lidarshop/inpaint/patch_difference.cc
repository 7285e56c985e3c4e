#include "lidarshop/inpaint/patch_difference.h"

// GCC 12 warns falsely inside its own AVX-512 reduction intrinsics.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wpsabi"
#include <immintrin.h>

#include <cmath>
#include <limits>

#include "lidarshop/util/error.h"

namespace lidarshop {

namespace {

enum class Kernel { kScalar, kAvx2, kAvx512 };

Kernel DetectKernel() {
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f")) return Kernel::kAvx512;
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return Kernel::kAvx2;
  return Kernel::kScalar;
}

const Kernel kKernel = DetectKernel();

// Per target row: sqrt(weight) and target·sqrt(weight), padded with zeros to a multiple of 16 floats, so that
//   Σ (s·√w − t·√w)²  =  Σ w (s − t)²
// and every lane beyond the patch row contributes exactly 0 whatever the (finite) source floats there are.
struct PreparedRows {
  int row_floats = 0;     // (2R+1)·C
  int padded_floats = 0;  // rounded up to 16
  std::vector<int> rows;  // patch rows (0..2R) with at least one weighted float
  std::vector<float, std::allocator<float>> sqrt_weight, target_times_sqrt_weight;  // rows.size() x padded
};

float ScalarSsd(const PreparedRows& p, const float* source_top_left, int64_t stride, float bound) {
  float lanes[16] = {};
  for (size_t i = 0; i < p.rows.size(); ++i) {
    const float* s = source_top_left + p.rows[i] * stride;
    const float* sw = p.sqrt_weight.data() + i * p.padded_floats;
    const float* tw = p.target_times_sqrt_weight.data() + i * p.padded_floats;
    for (int v = 0; v < p.padded_floats; v += 16) {
      for (int l = 0; l < 16; ++l) {
        const float d = s[v + l] * sw[v + l] - tw[v + l];
        lanes[l] += d * d;
      }
    }
    float partial = 0.0f;
    for (float lane : lanes) partial += lane;
    if (partial > bound) return partial;
  }
  float sum = 0.0f;
  for (float lane : lanes) sum += lane;
  return sum;
}

__attribute__((target("avx2,fma"), always_inline)) inline float Avx2Reduce(__m256 a, __m256 b) {
  const __m256 s = _mm256_add_ps(a, b);
  __m128 x = _mm_add_ps(_mm256_castps256_ps128(s), _mm256_extractf128_ps(s, 1));
  x = _mm_add_ps(x, _mm_movehl_ps(x, x));
  x = _mm_add_ss(x, _mm_shuffle_ps(x, x, 1));
  return _mm_cvtss_f32(x);
}

__attribute__((target("avx2,fma"))) float Avx2Ssd(const PreparedRows& p, const float* source_top_left,
                                                  int64_t stride, float bound) {
  __m256 acc0 = _mm256_setzero_ps(), acc1 = _mm256_setzero_ps();
  for (size_t i = 0; i < p.rows.size(); ++i) {
    const float* s = source_top_left + p.rows[i] * stride;
    const float* sw = p.sqrt_weight.data() + i * p.padded_floats;
    const float* tw = p.target_times_sqrt_weight.data() + i * p.padded_floats;
    for (int v = 0; v < p.padded_floats; v += 16) {
      const __m256 d0 =
          _mm256_fmsub_ps(_mm256_loadu_ps(s + v), _mm256_load_ps(sw + v), _mm256_load_ps(tw + v));
      const __m256 d1 =
          _mm256_fmsub_ps(_mm256_loadu_ps(s + v + 8), _mm256_load_ps(sw + v + 8), _mm256_load_ps(tw + v + 8));
      acc0 = _mm256_fmadd_ps(d0, d0, acc0);
      acc1 = _mm256_fmadd_ps(d1, d1, acc1);
    }
    if (Avx2Reduce(acc0, acc1) > bound) return Avx2Reduce(acc0, acc1);
  }
  return Avx2Reduce(acc0, acc1);
}

__attribute__((target("avx512f"))) float Avx512Ssd(const PreparedRows& p, const float* source_top_left,
                                                   int64_t stride, float bound) {
  __m512 acc = _mm512_setzero_ps();
  const size_t n = p.rows.size();
  for (size_t i = 0; i < n; ++i) {
    const float* s = source_top_left + p.rows[i] * stride;
    const float* sw = p.sqrt_weight.data() + i * p.padded_floats;
    const float* tw = p.target_times_sqrt_weight.data() + i * p.padded_floats;
    for (int v = 0; v < p.padded_floats; v += 16) {
      const __m512 d =
          _mm512_fmsub_ps(_mm512_loadu_ps(s + v), _mm512_loadu_ps(sw + v), _mm512_loadu_ps(tw + v));
      acc = _mm512_fmadd_ps(d, d, acc);
    }
    // Lanes only grow, so a partial sum above the bound proves the full sum is above it too.
    if ((i & 1) && i + 1 < n) {
      const float partial = _mm512_reduce_add_ps(acc);
      if (partial > bound) return partial;
    }
  }
  return _mm512_reduce_add_ps(acc);
}

class WeightedSsdTarget : public TargetDifference {
 public:
  WeightedSsdTarget(const InpaintCanvas& canvas, Pixel target, const std::vector<float>& channel_weights)
      : canvas_(canvas) {
    const int R = canvas.patch_radius(), C = canvas.channels(), side = 2 * R + 1;
    prepared_.row_floats = side * C;
    prepared_.padded_floats = (prepared_.row_floats + 15) / 16 * 16;
    std::vector<float> sw(prepared_.padded_floats), tw(prepared_.padded_floats);
    for (int i = 0; i < side; ++i) {
      const int r = target.row - R + i;
      std::fill(sw.begin(), sw.end(), 0.0f);
      std::fill(tw.begin(), tw.end(), 0.0f);
      bool any = false;
      if (r >= 0 && r < canvas.rows()) {
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
            any = true;
          }
        }
      }
      if (!any) continue;
      prepared_.rows.push_back(i);
      prepared_.sqrt_weight.insert(prepared_.sqrt_weight.end(), sw.begin(), sw.end());
      prepared_.target_times_sqrt_weight.insert(prepared_.target_times_sqrt_weight.end(), tw.begin(),
                                                tw.end());
    }
  }

  float Evaluate(Pixel source, float bound) const override {
    const int R = canvas_.patch_radius();
    const float* top_left = canvas_.PixelData(source.row - R, source.col - R);
    switch (kKernel) {
      case Kernel::kAvx512:
        return Avx512Ssd(prepared_, top_left, canvas_.row_stride(), bound);
      case Kernel::kAvx2:
        return Avx2Ssd(prepared_, top_left, canvas_.row_stride(), bound);
      default:
        return ScalarSsd(prepared_, top_left, canvas_.row_stride(), bound);
    }
  }

 private:
  const InpaintCanvas& canvas_;
  PreparedRows prepared_;
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
      return "avx512";
    case Kernel::kAvx2:
      return "avx2";
    default:
      return "scalar";
  }
}

}  // namespace lidarshop
