// A patch must not bring "no return" into a place where everything around it returned.
//
// The acceptance tests of inpaint/acceptance.h compare the value distributions of a patch's known and copied
// parts, on a thin band along the hole's boundary; a few sky cells deep inside an otherwise well-matching source
// patch pass them. In a scan that leaves a gap in a wall: the exact search found, for the foot of a brick wall
// behind a car, the patch at the wall's top whose upper rows are sky (brick_over_grass: 228 cells left without a
// return). Sky and beyond-range regions do not appear out of nothing inside a surface, so a source whose copied
// cells include one without a return is refused for a target whose known cells all have one. The converse
// (returns brought next to sky only) stays allowed: the hole may hide the top of a building. Likewise a source
// that would copy a cell of an object standing in front of the background (a person beside the removed one)
// is refused: the hole shows what continues behind the object, never another object's front.
#pragma once

#include <memory>
#include <utility>

#include <opencv2/core.hpp>

#include "lidarshop/inpaint/acceptance.h"

namespace lidarshop::fill_internal {

// Wraps `inner` (may be null: accept everything else). `return_channel` is the canvas channel holding
// "has a return" (0 = none, > 0 = a return).
class ReturnConsistentAcceptance : public PatchAcceptance {
 public:
  // `front` (CV_8U over the canvas, may be empty): cells standing in front of the hole's background
  // (fill/foreground.h); a source that would copy one of them is refused too.
  ReturnConsistentAcceptance(std::unique_ptr<PatchAcceptance> inner, int return_channel, cv::Mat front = {})
      : inner_(std::move(inner)), return_channel_(return_channel), front_(std::move(front)) {}
  void Initialize(const InpaintCanvas& canvas) override;
  bool Accept(const InpaintCanvas& canvas, Pixel target, const SourceCandidate& candidate) const override {
    return Judge(canvas, target, candidate).accepted;
  }
  AcceptanceVerdict Judge(const InpaintCanvas& canvas, Pixel target,
                          const SourceCandidate& candidate) const override;

 private:
  std::unique_ptr<PatchAcceptance> inner_;
  int return_channel_;
  cv::Mat front_;
};

}  // namespace lidarshop::fill_internal
