#include "lidarshop/inpaint/patch_difference.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "lidarshop/util/error.h"

namespace lidarshop {

namespace {

// Per target row: sqrt(weight) and target·sqrt(weight), so that
//   Σ (s·√w − t·√w)²  =  Σ w (s − t)²
// Only the span of 8-float blocks that hold a non-zero weight is evaluated (at the hole's rim about half of a
// patch is unknown); the stored rows are zero-padded by 16 floats, so a kernel may read past a span and every
// lane beyond it contributes exactly 0 whatever the (finite) source floats there are.
struct RowSpan {
  int64_t source_offset = 0;  // floats from the source patch's top-left pixel to the span's first float
  int stored_offset = 0;      // floats into sqrt_weight / target_times_sqrt_weight
  int blocks8 = 0;            // 8-float blocks in the span
};

struct PreparedRows {
  std::vector<RowSpan> spans;
  std::vector<float> sqrt_weight, target_times_sqrt_weight;
};

// The sum's one order, on every SIMD path (lanes code, util/simd.h; no FMA: the file is compiled with
// -ffp-contract=off and the AVX2 functions are target("avx2") only). Per candidate, four 8-lane accumulators
// (block index mod 4, which keeps the dependency chains short) get d² with d = s·√w − t·√w (a product, then
// a difference); the total is ((a0 + a1) + (a2 + a3)) per lane, then lanes j + (j + 4), then
// (0 + 2) + (1 + 3).
LIDARSHOP_LANES_INLINE float Sum4(const lanes::F8* acc) {
  using F4 = float __attribute__((vector_size(16)));
  const lanes::F8 v = (acc[0] + acc[1]) + (acc[2] + acc[3]);
  const F4 x = __builtin_shufflevector(v, v, 0, 1, 2, 3) + __builtin_shufflevector(v, v, 4, 5, 6, 7);
  return (x[0] + x[2]) + (x[1] + x[3]);
}

// N adjacent candidates of a row per pass (source patches candidate_step floats apart): the target's
// weights and values are loaded once per block for all of them; each candidate's sum is in the order
// above, so it does not depend on N. Early termination every second row: lanes only grow, so partial
// sums above the bound prove the full sums are above it too; the pass stops when every candidate is
// out and returns the partial sums.
template <int N>
LIDARSHOP_LANES_INLINE void SsdBody(const PreparedRows& p, const float* source_top_left,
                                    int64_t candidate_step, float bound, float* out) {
  using lanes::F8;
  F8 acc[N][4];
  for (int c = 0; c < N; ++c)
    for (int a = 0; a < 4; ++a) acc[c][a] = lanes::Splat(0.0f);
  const size_t n = p.spans.size();
  for (size_t i = 0; i < n; ++i) {
    const RowSpan& span = p.spans[i];
    const float* s = source_top_left + span.source_offset;
    const float* sw = p.sqrt_weight.data() + span.stored_offset;
    const float* tw = p.target_times_sqrt_weight.data() + span.stored_offset;
    for (int b = 0; b < span.blocks8; ++b) {
      const F8 w = lanes::Load<F8>(sw + 8 * b), t = lanes::Load<F8>(tw + 8 * b);
      for (int c = 0; c < N; ++c) {
        const F8 d = lanes::Load<F8>(s + c * candidate_step + 8 * b) * w - t;
        acc[c][b & 3] += d * d;
      }
    }
    if ((i & 1) && i + 1 < n) {
      bool all_out = true;
      for (int c = 0; c < N && all_out; ++c) all_out = Sum4(acc[c]) > bound;
      if (all_out) break;
    }
  }
  for (int c = 0; c < N; ++c) out[c] = Sum4(acc[c]);
}

template <int N>
__attribute__((target("avx2"), flatten)) void SsdAvx2(const PreparedRows& p, const float* source_top_left,
                                                      int64_t candidate_step, float bound, float* out) {
  SsdBody<N>(p, source_top_left, candidate_step, bound, out);
}
// The same sums with 16-lane vectors: one 16-float load covers blocks 2m and 2m + 1, whose lanes go to the
// 8-lane accumulators 2m mod 4 and (2m + 1) mod 4, so pair[m & 1] holds accumulators (0, 1) or (2, 3) in its
// low and high halves and every lane adds the same terms in the same order as SsdBody. A span with an odd
// number of blocks reads one block past it: its weights and targets are the stored zero padding, so those
// lanes add d² = (s·0 − 0)² = +0, which leaves a sum of squares unchanged. The canvas's padding covers the
// source floats read past the last patch row.
using F16 = float __attribute__((vector_size(64)));

LIDARSHOP_LANES_INLINE float Sum16(const F16* pair) {
  const lanes::F8 acc[4] = {__builtin_shufflevector(pair[0], pair[0], 0, 1, 2, 3, 4, 5, 6, 7),
                            __builtin_shufflevector(pair[0], pair[0], 8, 9, 10, 11, 12, 13, 14, 15),
                            __builtin_shufflevector(pair[1], pair[1], 0, 1, 2, 3, 4, 5, 6, 7),
                            __builtin_shufflevector(pair[1], pair[1], 8, 9, 10, 11, 12, 13, 14, 15)};
  return Sum4(acc);
}

template <int N>
__attribute__((target("avx512f"), flatten)) void SsdAvx512(const PreparedRows& p,
                                                           const float* source_top_left,
                                                           int64_t candidate_step, float bound, float* out) {
  F16 acc[N][2];
  for (int c = 0; c < N; ++c)
    for (int a = 0; a < 2; ++a) acc[c][a] = F16{} * 0.0f;
  const size_t n = p.spans.size();
  for (size_t i = 0; i < n; ++i) {
    const RowSpan& span = p.spans[i];
    const float* s = source_top_left + span.source_offset;
    const float* sw = p.sqrt_weight.data() + span.stored_offset;
    const float* tw = p.target_times_sqrt_weight.data() + span.stored_offset;
    const int pairs = (span.blocks8 + 1) / 2;
    for (int m = 0; m < pairs; ++m) {
      // Loads written out here, not lanes::Load: clang refuses a 64-byte vector returned from a function not
      // compiled for AVX-512 (an ABI change) even when it is inlined, e.g. in the -mavx2 fuzz build.
      F16 w, t;
      __builtin_memcpy(&w, sw + 16 * m, sizeof(F16));
      __builtin_memcpy(&t, tw + 16 * m, sizeof(F16));
      for (int c = 0; c < N; ++c) {
        F16 d;
        __builtin_memcpy(&d, s + c * candidate_step + 16 * m, sizeof(F16));
        d = d * w - t;
        acc[c][m & 1] += d * d;
      }
    }
    if ((i & 1) && i + 1 < n) {
      bool all_out = true;
      for (int c = 0; c < N && all_out; ++c) all_out = Sum16(acc[c]) > bound;
      if (all_out) break;
    }
  }
  for (int c = 0; c < N; ++c) out[c] = Sum16(acc[c]);
}

template <int N>
void SsdBaseline(const PreparedRows& p, const float* source_top_left, int64_t candidate_step, float bound,
                 float* out) {
  SsdBody<N>(p, source_top_left, candidate_step, bound, out);
}

class WeightedSsdTarget : public TargetDifference {
 public:
  WeightedSsdTarget(const InpaintCanvas& canvas, Pixel target, const std::vector<float>& channel_weights,
                    SsdKernel kernel)
      : canvas_(canvas), kernel_(kernel) {
    const int R = canvas.patch_radius(), C = canvas.channels(), side = 2 * R + 1;
    const int row_floats = side * C;
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
    float out;
    switch (kernel_) {
      case SsdKernel::kAvx512:
        SsdAvx512<1>(prepared_, top_left, 0, bound, &out);
        break;
      case SsdKernel::kAvx2:
        SsdAvx2<1>(prepared_, top_left, 0, bound, &out);
        break;
      case SsdKernel::kBaseline:
        SsdBaseline<1>(prepared_, top_left, 0, bound, &out);
        break;
    }
    return out;
  }

  // Fours, then pairs, then singles (measured on fill_bench: fours save more target loads than the register
  // spills of their 16 accumulators cost). Every path splits a run the same way, so results that exceed the
  // bound agree between paths too.
  void EvaluateRun(Pixel source, int count, float bound, float* out) const override {
    const int R = canvas_.patch_radius(), C = canvas_.channels();
    auto top_left = [&](int i) { return canvas_.PixelData(source.row - R, source.col + i - R); };
    int i = 0;
    if (kernel_ == SsdKernel::kAvx512) {
      for (; i + 4 <= count; i += 4) SsdAvx512<4>(prepared_, top_left(i), C, bound, out + i);
      for (; i + 2 <= count; i += 2) SsdAvx512<2>(prepared_, top_left(i), C, bound, out + i);
      for (; i < count; ++i) SsdAvx512<1>(prepared_, top_left(i), C, bound, out + i);
    } else if (kernel_ == SsdKernel::kAvx2) {
      for (; i + 4 <= count; i += 4) SsdAvx2<4>(prepared_, top_left(i), C, bound, out + i);
      for (; i + 2 <= count; i += 2) SsdAvx2<2>(prepared_, top_left(i), C, bound, out + i);
      for (; i < count; ++i) SsdAvx2<1>(prepared_, top_left(i), C, bound, out + i);
    } else {
      for (; i + 4 <= count; i += 4) SsdBaseline<4>(prepared_, top_left(i), C, bound, out + i);
      for (; i + 2 <= count; i += 2) SsdBaseline<2>(prepared_, top_left(i), C, bound, out + i);
      for (; i < count; ++i) SsdBaseline<1>(prepared_, top_left(i), C, bound, out + i);
    }
  }

 private:
  const InpaintCanvas& canvas_;
  const SsdKernel kernel_;
  PreparedRows prepared_;
};

}  // namespace

SsdKernel BestSsdKernel() {
  static const SsdKernel best = [] {
    if (BestSimdPath() != SimdPath::kAvx2) return SsdKernel::kBaseline;
    return CpuMayUse("avx512f") ? SsdKernel::kAvx512 : SsdKernel::kAvx2;
  }();
  return best;
}

WeightedSsd::WeightedSsd(std::vector<float> channel_weights, SimdPath path)
    : WeightedSsd(std::move(channel_weights),
                  path == SimdPath::kAvx2 ? SsdKernel::kAvx512 : SsdKernel::kBaseline) {}

WeightedSsd::WeightedSsd(std::vector<float> channel_weights, SsdKernel kernel)
    : channel_weights_(std::move(channel_weights)), kernel_(std::min(kernel, BestSsdKernel())) {
  for (float w : channel_weights_)
    CheckOption(std::isfinite(w) && w >= 0.0f, "WeightedSsd: channel weights must be >= 0");
}

std::unique_ptr<TargetDifference> WeightedSsd::ForTarget(const InpaintCanvas& canvas, Pixel target) const {
  if (!channel_weights_.empty() && static_cast<int>(channel_weights_.size()) != canvas.channels()) {
    throw OptionsError(fmt::format("WeightedSsd: {} channel weights for an image of {} channels",
                                   channel_weights_.size(), canvas.channels()));
  }
  return std::make_unique<WeightedSsdTarget>(canvas, target, channel_weights_, kernel_);
}

const char* WeightedSsd::KernelName() const {
  switch (kernel_) {
    case SsdKernel::kAvx512:
      return "avx512";
    case SsdKernel::kAvx2:
      return "avx2";
    case SsdKernel::kBaseline:
      break;
  }
  return "baseline";
}

}  // namespace lidarshop
