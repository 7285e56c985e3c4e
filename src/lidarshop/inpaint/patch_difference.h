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
// per row.
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
