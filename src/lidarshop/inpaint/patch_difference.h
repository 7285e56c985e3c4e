// Patch differences: how unlike a source patch is to the known part of a target patch.
//
// The interface is split in two so that the per-target work (gathering the target's known pixels and
// weights) is done once per query and the per-candidate work is a tight loop:
// PatchDifference::ForTarget() prepares a TargetDifference, whose Evaluate() is called for each candidate
// source centre (from several threads at once).
#pragma once

#include <memory>
#include <vector>

#include "lidarshop/inpaint/canvas.h"
#include "lidarshop/util/simd.h"

namespace lidarshop {

class TargetDifference {
 public:
  virtual ~TargetDifference() = default;
  // Difference to the source patch centred at `source` (a source centre of the canvas). Early termination:
  // once the difference is known to exceed `bound`, any value > bound may be returned. Thread-safe.
  virtual float Evaluate(Pixel source, float bound) const = 0;
  // The same for `count` source centres in a row: (source.row, source.col + i) for i in [0, count), all of
  // them source centres; out[i] gets what Evaluate() would return for each (bit-identical whenever it is
  // <= bound; any value > bound otherwise). Implementations may share the target's loads between neighbouring
  // candidates. The default calls Evaluate() per candidate.
  virtual void EvaluateRun(Pixel source, int count, float bound, float* out) const {
    for (int i = 0; i < count; ++i) out[i] = Evaluate({source.row, source.col + i}, bound);
  }
};

class PatchDifference {
 public:
  virtual ~PatchDifference() = default;
  virtual std::unique_ptr<TargetDifference> ForTarget(const InpaintCanvas& canvas, Pixel target) const = 0;
};

// The kernels of WeightedSsd, narrowest first. All of them give bit-identical results.
enum class SsdKernel { kBaseline, kAvx2, kAvx512 };
// The widest kernel this CPU runs (checked once).
SsdKernel BestSsdKernel();

// Weighted sum of squared differences over the target patch's known pixels inside the image:
//   SSD(p, q) = Σ_{d : p+d known} Σ_k w_k (I_k(p+d) − I_k(q+d))²   (d(Ψp, Ψq) of Criminisi et al. 2004, §3)
// channel_weights: one weight ≥ 0 per channel, or empty for all 1. Evaluated on (2R+1)·C contiguous floats
// per patch row in 8-lane vectors (util/simd.h), with early termination checked every second row;
// EvaluateRun() evaluates four adjacent candidates per pass so that they share the target's loads. The kernel
// is the baseline (x86-64), AVX2 or AVX-512 one; the AVX-512 kernel loads 16 floats (two 8-lane blocks) at a
// time into the same per-lane accumulators, so all of them sum in one order without FMA, and every
// evaluation, and so every fill, is bit-identical on any kernel and any CPU.
class WeightedSsd : public PatchDifference {
 public:
  // path kAvx2: the widest kernel the CPU runs (AVX-512 or AVX2); kScalar: the baseline one.
  explicit WeightedSsd(std::vector<float> channel_weights = {}, SimdPath path = BestSimdPath());
  // `kernel`, or the widest narrower one the CPU runs (for tests and benchmarks).
  WeightedSsd(std::vector<float> channel_weights, SsdKernel kernel);
  std::unique_ptr<TargetDifference> ForTarget(const InpaintCanvas& canvas, Pixel target) const override;

  // The kernel the evaluations take: "avx512", "avx2" or "baseline".
  const char* KernelName() const;

 private:
  std::vector<float> channel_weights_;
  SsdKernel kernel_;
};

}  // namespace lidarshop
