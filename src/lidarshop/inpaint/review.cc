#include "lidarshop/inpaint/review.h"

#include <cmath>

namespace lidarshop {

std::vector<int> ClusterCandidates(const InpaintCanvas& canvas,
                                   const std::vector<SourceCandidate>& candidates, double max_rms,
                                   const std::vector<float>& channel_weights) {
  const int R = canvas.patch_radius(), C = canvas.channels();
  std::vector<float> low, range;
  ChannelRanges(canvas, &low, &range);
  std::vector<double> w(C, 1.0);
  double weight_sum = C;
  if (!channel_weights.empty()) {
    weight_sum = 0.0;
    for (int k = 0; k < C; ++k) weight_sum += w[k] = channel_weights[k];
  }
  const double pixels = (2.0 * R + 1) * (2.0 * R + 1);
  auto rms = [&](Pixel a, Pixel b) {
    double sum = 0.0;
    for (int dr = -R; dr <= R; ++dr)
      for (int dc = -R; dc <= R; ++dc) {
        const float* pa = canvas.PixelData(a.row + dr, a.col + dc);
        const float* pb = canvas.PixelData(b.row + dr, b.col + dc);
        for (int k = 0; k < C; ++k) {
          const double d = (pa[k] - pb[k]) / range[k];
          sum += w[k] * d * d;
        }
      }
    return std::sqrt(sum / (pixels * std::max(weight_sum, 1e-12)));
  };
  std::vector<int> cluster(candidates.size(), -1), representatives;
  for (size_t i = 0; i < candidates.size(); ++i) {
    for (size_t c = 0; c < representatives.size(); ++c) {
      if (rms(candidates[representatives[c]].source, candidates[i].source) <= max_rms) {
        cluster[i] = static_cast<int>(c);
        break;
      }
    }
    if (cluster[i] < 0) {
      cluster[i] = static_cast<int>(representatives.size());
      representatives.push_back(static_cast<int>(i));
    }
  }
  return cluster;
}

InpaintReview MakeReview(const InpaintCanvas& canvas, Pixel target, std::vector<SourceCandidate> candidates,
                         const PatchAcceptance* acceptance, double cluster_max_rms,
                         const std::vector<float>& channel_weights) {
  InpaintReview review;
  review.target = target;
  review.candidates = std::move(candidates);
  for (const SourceCandidate& c : review.candidates)
    review.verdicts.push_back(acceptance ? acceptance->Judge(canvas, target, c) : AcceptanceVerdict{});
  review.cluster = ClusterCandidates(canvas, review.candidates, cluster_max_rms, channel_weights);
  for (size_t i = 0; i < review.cluster.size(); ++i)
    if (review.cluster[i] == static_cast<int>(review.cluster_representative.size()))
      review.cluster_representative.push_back(static_cast<int>(i));
  review.known = canvas.known().clone();
  review.tentative_image = canvas.Image();
  if (!review.candidates.empty()) {
    const int R = canvas.patch_radius(), C = canvas.channels();
    const Pixel source = review.candidates.front().source;
    for (int dr = -R; dr <= R; ++dr)
      for (int dc = -R; dc <= R; ++dc) {
        const int r = target.row + dr, c = target.col + dc;
        if (!canvas.Inside(r, c) || canvas.IsKnown(r, c)) continue;
        const float* from = canvas.PixelData(source.row + dr, source.col + dc);
        float* to = review.tentative_image.ptr<float>(r) + c * C;
        std::copy(from, from + C, to);
      }
  }
  return review;
}

}  // namespace lidarshop
