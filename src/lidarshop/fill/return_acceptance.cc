#include "lidarshop/fill/return_acceptance.h"

namespace lidarshop::fill_internal {

void ReturnConsistentAcceptance::Initialize(const InpaintCanvas& canvas) {
  if (inner_) inner_->Initialize(canvas);
}

AcceptanceVerdict ReturnConsistentAcceptance::Judge(const InpaintCanvas& canvas, Pixel target,
                                                    const SourceCandidate& candidate) const {
  const int radius = canvas.patch_radius();
  bool known_without_return = false, copies_without_return = false, copies_front = false;
  for (int dr = -radius; dr <= radius; ++dr) {
    for (int dc = -radius; dc <= radius; ++dc) {
      const int row = target.row + dr, col = target.col + dc;
      if (!canvas.Inside(row, col)) continue;
      if (canvas.IsKnown(row, col)) {
        known_without_return |= canvas.PixelData(row, col)[return_channel_] <= 0.0f;
      } else {
        const float* copied = canvas.PixelData(candidate.source.row + dr, candidate.source.col + dc);
        copies_without_return |= copied[return_channel_] <= 0.0f;
        const int from_row = candidate.source.row + dr, from_col = candidate.source.col + dc;
        copies_front |= !front_.empty() && canvas.Inside(from_row, from_col) &&
                        front_.at<uint8_t>(from_row, from_col) != 0;
      }
    }
  }
  if (copies_front || (copies_without_return && !known_without_return)) {
    AcceptanceVerdict verdict;
    verdict.accepted = false;
    verdict.margin = -1.0;
    verdict.test = copies_front ? "background" : "returns";
    verdict.value = 1.0;
    verdict.threshold = 0.0;
    verdict.hard = true;
    return verdict;
  }
  if (inner_) return inner_->Judge(canvas, target, candidate);
  return AcceptanceVerdict{};
}

}  // namespace lidarshop::fill_internal
