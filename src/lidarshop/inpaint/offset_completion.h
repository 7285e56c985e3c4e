// Image completion by the statistics of patch offsets (He & Sun, "Statistics of Patch Offsets for Image
// Completion", ECCV 2012).
//
// Built surroundings repeat: a facade's windows stand a fixed pitch apart, a kerb runs on along the rows. The
// offsets between similar patches of the known image therefore cluster at a few dominant shifts (one window
// pitch, one storey). The hole is filled by stacking shifted copies of the image: every hole pixel takes one of
// the K dominant offsets as its label and copies the pixel that far away; the labels minimise, by
// alpha-expansion graph cuts (Boykov–Kolmogorov max-flow), the disagreement between neighbouring copies and
// with the known pixels around the hole. Where a greedy patch fill (Criminisi) continues what the rim shows one
// patch at a time — and puts a wall in the middle of a window whose lower half it never sees — a shifted copy
// brings a whole window, its sill at the height of the others.
//
//   1. offsets: known patches on a grid are described by the first principal components of their (weighted)
//      values; each one's nearest neighbour in that space, at least `min_offset` pixels away, votes for the
//      offset between them; the vote histogram is smoothed and its K highest local maxima kept, each refined to
//      the pixel shift with the least mean squared difference between the image and its shifted copy;
//   2. labels: a label is valid at a hole pixel when the pixel it copies lies inside the image and outside the
//      hole. Data cost: for every known 4-neighbour q of the hole pixel, |I(q + o) − I(q)|² (the seam with the
//      rim); pairwise cost between hole neighbours p, q with offsets a ≠ b: |I(p + a) − I(p + b)|² +
//      |I(q + a) − I(q + b)|² (zero where the two copies agree); weighted by channel;
//   3. expansion: sweeps over the labels (most frequent first); each move is solved exactly for its submodular
//      part (Kolmogorov & Zabih; the rare non-submodular pair is truncated, as in Rother et al. 2005) and kept
//      only when it lowers the true energy.
// Hole pixels where no offset is valid stay unfilled (label −1) for another method to fill.
// Deterministic: no random choice; the same input gives the same labels on any CPU and thread count.
#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

struct OffsetCompletionOptions {
  int patch_radius = 4;                // patches described for the offset statistics, (2r+1)² pixels (>= 1)
  int sample_step = 2;                 // known patches on a grid of this step, pixels; raised so that at most
                                       // `max_samples` are described (>= 1)
  int max_samples = 20000;             // described patches at most (>= 100)
  int descriptor_dims = 12;            // principal components of a patch's values (>= 2)
  int min_offset = 8;                  // offsets shorter than this (Chebyshev) are not counted, pixels (>= 1)
  int labels = 60;                     // dominant offsets kept, K (>= 1)
  int sweeps = 2;                      // expansion sweeps over all labels (>= 1)
  std::vector<float> channel_weights;  // one weight >= 0 per channel, or empty for all 1
  void Check() const;                  // throws OptionsFieldError naming the field
};
template <>
const StructInfo& InfoOf<OffsetCompletionOptions>();

struct OffsetCompletionResult {
  std::vector<cv::Point> offsets;  // the K dominant offsets (dx = cols, dy = rows), most votes first
  std::vector<float> votes;        // their smoothed vote counts
  cv::Mat label;  // CV_32S rows x cols: index into `offsets` of each hole pixel, −1 elsewhere and unfilled
  cv::Mat source_pixel;  // CV_32SC2 rows x cols: (row, col) each filled hole pixel copies, (−1, −1) elsewhere
  int64_t unfilled = 0;  // hole pixels where no offset was valid
  double energy = 0;     // of the final labelling
  int moves = 0;         // expansion moves that lowered the energy
  double seconds = 0;
};

// image: H x W CV_32FC(C) (1..16 channels), finite outside the hole; hole: H x W CV_8U, non-zero = fill.
// Throws InputError on mismatched or invalid inputs and OptionsError on invalid options.
OffsetCompletionResult CompleteByOffsets(const cv::Mat& image, const cv::Mat& hole,
                                         const OffsetCompletionOptions& options = {});

}  // namespace lidarshop
