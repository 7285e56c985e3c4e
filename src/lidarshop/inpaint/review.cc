#include "lidarshop/inpaint/review.h"

#include <cmath>

#include "lidarshop/util/options.h"

namespace lidarshop {

std::vector<int> ClusterCandidates(const InpaintCanvas& canvas,
                                   const std::vector<SourceCandidate>& candidates, double max_rms,
                                   const std::vector<float>& channel_weights) {
  const int R = canvas.patch_radius(), C = canvas.channels();
  std::vector<float> low, range;
  ChannelRanges(canvas, &low, &range);
  std::vector<double> w(C, 1.0);
  if (!channel_weights.empty()) std::copy(channel_weights.begin(), channel_weights.end(), w.begin());
  // Descriptor: per channel, the mean of each quadrant and the standard deviation of the whole patch (5 C
  // values, range units, scaled by √w).
  auto describe = [&](Pixel s) {
    std::vector<double> sum(5 * C, 0.0), count(4, 0.0), square(C, 0.0), all(C, 0.0);
    for (int dr = -R; dr <= R; ++dr)
      for (int dc = -R; dc <= R; ++dc) {
        if (!canvas.Inside(s.row + dr, s.col + dc)) continue;  // a source at the border (canvas.h)
        const int q = (dr > 0 ? 2 : 0) + (dc > 0 ? 1 : 0);
        const float* p = canvas.PixelData(s.row + dr, s.col + dc);
        count[q] += 1.0;
        for (int k = 0; k < C; ++k) {
          const double v = (p[k] - low[k]) / range[k];
          sum[q * C + k] += v;
          all[k] += v;
          square[k] += v * v;
        }
      }
    const double n = count[0] + count[1] + count[2] + count[3];
    for (int q = 0; q < 4; ++q)
      for (int k = 0; k < C; ++k) sum[q * C + k] = std::sqrt(w[k]) * sum[q * C + k] / std::max(count[q], 1.0);
    for (int k = 0; k < C; ++k) {
      const double mean = all[k] / n;
      sum[4 * C + k] = std::sqrt(w[k] * std::max(0.0, square[k] / n - mean * mean));
    }
    return sum;
  };
  double weight_sum = 0.0;
  for (double x : w) weight_sum += x;
  std::vector<std::vector<double>> descriptors;
  for (const SourceCandidate& c : candidates) descriptors.push_back(describe(c.source));
  auto rms = [&](const std::vector<double>& a, const std::vector<double>& b) {
    double s = 0.0;
    for (size_t i = 0; i < a.size(); ++i) s += (a[i] - b[i]) * (a[i] - b[i]);
    return std::sqrt(s / (5.0 * std::max(weight_sum, 1e-12)));
  };
  std::vector<int> cluster(candidates.size(), -1), representatives;
  for (size_t i = 0; i < candidates.size(); ++i) {
    for (size_t c = 0; c < representatives.size(); ++c) {
      if (rms(descriptors[representatives[c]], descriptors[i]) <= max_rms) {
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

ReviewStop StopOf(const InpaintReview& review) {
  return {
      review.iteration, {review.target.row, review.target.col}, static_cast<int>(review.candidates.size())};
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

namespace {

std::vector<int> PixelList(Pixel p) { return {p.row, p.col}; }

}  // namespace

ReviewSummary SummarizeReview(const InpaintReview& review, int patch_radius) {
  ReviewSummary summary;
  summary.review_point = review.review_point;
  summary.iteration = review.iteration;
  summary.target = PixelList(review.target);
  summary.patch_radius = patch_radius;
  for (size_t i = 0; i < review.candidates.size(); ++i) {
    const AcceptanceVerdict verdict = i < review.verdicts.size() ? review.verdicts[i] : AcceptanceVerdict{};
    summary.candidates.push_back({.index = static_cast<int64_t>(i),
                                  .source = PixelList(review.candidates[i].source),
                                  .difference = review.candidates[i].difference,
                                  .cluster = review.cluster[i],
                                  .accepted = verdict.accepted,
                                  .test = verdict.test,
                                  .value = verdict.value,
                                  .threshold = verdict.threshold,
                                  .margin = verdict.margin});
  }
  for (size_t c = 0; c < review.cluster_representative.size(); ++c) {
    ReviewClusterSummary cluster{
        .index = static_cast<int64_t>(c), .representative = review.cluster_representative[c], .members = {}};
    for (size_t i = 0; i < review.cluster.size(); ++i)
      if (review.cluster[i] == static_cast<int>(c)) cluster.members.push_back(static_cast<int64_t>(i));
    summary.clusters.push_back(std::move(cluster));
  }
  return summary;
}

std::vector<ReviewDecisionSummary> SummarizeDecisions(const std::vector<ReviewDecision>& decisions) {
  std::vector<ReviewDecisionSummary> list;
  for (const ReviewDecision& d : decisions) list.push_back({PixelList(d.target), PixelList(d.source)});
  return list;
}

nlohmann::ordered_json ReviewToJson(const InpaintReview& review, int patch_radius) {
  return ToJson(SummarizeReview(review, patch_radius));
}

nlohmann::ordered_json DecisionsToJson(const std::vector<ReviewDecision>& decisions) {
  nlohmann::ordered_json json = nlohmann::ordered_json::array();
  for (const ReviewDecisionSummary& decision : SummarizeDecisions(decisions))
    json.push_back(ToJson(decision));
  return json;
}

}  // namespace lidarshop
