// Patch differences: how unlike a source patch is to the known part of a target patch.
//
// The interface is split in two so that the per-target work (gathering the target's known pixels and weights)
// is done once per query and the per-candidate work is a tight loop: PatchDifference::ForTarget() prepares a
// TargetDifference, whose Evaluate() is called for each candidate source centre (from several threads at
// once).
#pragma once

#include <memory>
#include <vector>

#include "lidarshop/inpaint/canvas.h"

namespace lidarshop {

class TargetDifference {
 public:
  virtual ~TargetDifference() = default;
  // Difference to the source patch centred at `source` (a source centre of the canvas). Early termination:
  // once the difference is known to exceed `bound`, any value > bound may be returned. Thread-safe.
  virtual float Evaluate(Pixel source, float bound) const = 0;
  // The same for `count` source centres in a row: (source.row, source.col + i) for i in [0, count), all of
  // them source centres; out[i] gets what Evaluate() would return for each (bit-identical whenever it is <=
  // bound; any value > bound otherwise). Implementations may share the target's loads between neighbouring
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

// Weighted sum of squared differences over the target patch's known pixels inside the image:
//   SSD(p, q) = Σ_{d : p+d known} Σ_k w_k (I_k(p+d) − I_k(q+d))²       (Criminisi et al. 2004, §3 "d(Ψp,
//   Ψq)")
// channel_weights: one weight ≥ 0 per channel, or empty for all 1. Evaluated with AVX-512 or AVX2+FMA when
// the CPU has them (runtime dispatch), on (2R+1)·C contiguous floats per patch row, with early termination
// checked every few rows. With AVX-512 and (2R+1)·C ≤ 64 (e.g. radius ≤ 10 for RGB) the kernel is unrolled
// for the row's vector count: per target row the known pixels' values are stored with a lane mask (masked
// loads of the source, subtract, FMA; the common weight of equal-weight channels is applied once at the end),
// and EvaluateRun() evaluates four adjacent candidates per pass so they share the target's loads.
class WeightedSsd : public PatchDifference {
 public:
  explicit WeightedSsd(std::vector<float> channel_weights = {});
  std::unique_ptr<TargetDifference> ForTarget(const InpaintCanvas& canvas, Pixel target) const override;

  // The instruction set the evaluations use: "avx512", "avx2" or "scalar".
  static const char* KernelName();

 private:
  std::vector<float> channel_weights_;
};

}  // namespace lidarshop
