// Review of a failing patch (thesis ch. 7.1 "User action"): when no candidate passes the acceptance tests,
// the fill can stop and hand the decision to the user: the tentative result (the best candidate pasted), the
// top-N candidates grouped into clusters of near-identical patches (hundreds of similar bad patches show as
// one), and the choice to accept one of them or to place a source patch by hand.
//
// The fill state is resumable in process (InpaintSession, inpaint_session.h: Run() stops, Decide() continues)
// and by replay: a fill is a deterministic function of (inputs, options, decisions), so resuming later is
// Inpaint() again with the user's decision appended to InpaintOptions::review_decisions; both equal an
// uninterrupted fill given the same decisions up front (tested). The command line keeps the decisions in
// review.json (`inpaint --review DIR`, `inpaint --resume DIR --choose N`).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "lidarshop/inpaint/acceptance.h"
#include "lidarshop/inpaint/canvas.h"
#include "lidarshop/inpaint/search.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

// What the user decided at one review point: copy the source patch centred at `source` into Ψtarget.
struct ReviewDecision {
  Pixel target;  // the target the review was about (checked on replay)
  Pixel source;  // any source centre: a listed candidate or one placed by hand
};

struct InpaintReview {
  int review_point = 0;  // how many review points came before this one (index into review_decisions)
  int iteration = 0;     // fill iteration at which the fill stopped
  Pixel target;          // the failing target patch's centre
  std::vector<SourceCandidate> candidates;  // top-N sources, best first
  std::vector<AcceptanceVerdict> verdicts;  // per candidate: why it was rejected (or accepted)
  std::vector<int> cluster;                 // per candidate: its cluster's index
  std::vector<int> cluster_representative;  // per cluster: its best candidate's index
  cv::Mat tentative_image;  // H x W CV_32FC(C): the fill so far with candidates[0] pasted into Ψtarget
  cv::Mat known;            // H x W CV_8U, 1 = known before the paste
};

// Where a fill stopped for a review, in brief: InpaintResult::review_stop, the "review" of `lidarshop inpaint
// --json` (the review itself, with its candidates and images, is InpaintResult::review and review.json).
// Described.
struct ReviewStop {
  int iteration = 0;        // fill iteration at which the fill stopped
  std::vector<int> target;  // [row, col] of the failing target patch's centre
  int candidates = 0;       // candidates ranked for it
};
ReviewStop StopOf(const InpaintReview& review);

template <>
const StructInfo& InfoOf<ReviewStop>();

// Groups ranked candidates: each joins the first cluster whose representative's descriptor differs from its
// own by at most max_rms, or starts a new one. The descriptor of a source patch is, per channel, the mean of
// each of its four quadrants and its standard deviation (in units of the channel's value range over the
// known pixels, see ChannelRanges; weighted RMS over channels): patches of one texture at other phases or
// with other noise group together, which a pixel-wise distance would keep apart. Returns per candidate its
// cluster index; representatives are the first member of each cluster.
std::vector<int> ClusterCandidates(const InpaintCanvas& canvas,
                                   const std::vector<SourceCandidate>& candidates, double max_rms,
                                   const std::vector<float>& channel_weights);

// The review of `target` with `candidates` (ranked): verdicts, clusters and the tentative image.
InpaintReview MakeReview(const InpaintCanvas& canvas, Pixel target, std::vector<SourceCandidate> candidates,
                         const PatchAcceptance* acceptance, double cluster_max_rms,
                         const std::vector<float>& channel_weights);

// A review's candidate as JSON lists it (ReviewSummary::candidates). Described.
struct ReviewCandidateSummary {
  int64_t index = 0;        // rank, 0 = best
  std::vector<int> source;  // [row, col] of the source patch's centre
  double difference = 0;    // SourceCandidate::difference
  int cluster = 0;          // its cluster's index
  // Its AcceptanceVerdict: accepted, the test that decided, its value, threshold and margin.
  bool accepted = true;
  std::string test;
  double value = 0, threshold = 0, margin = 0;
};
template <>
const StructInfo& InfoOf<ReviewCandidateSummary>();

// A cluster of a review's candidates. Described.
struct ReviewClusterSummary {
  int64_t index = 0;
  int representative = 0;        // its best candidate's index
  std::vector<int64_t> members;  // its candidates' indices
};
template <>
const StructInfo& InfoOf<ReviewClusterSummary>();

// The JSON form of a review, shared by `inpaint --review` (review.json) and the editor's API (docs/api.md).
// Described.
struct ReviewSummary {
  int review_point = 0, iteration = 0;             // InpaintReview's
  std::vector<int> target;                         // [row, col] of the failing target patch's centre
  int patch_radius = 0;                            // the fill's, cells
  std::vector<ReviewCandidateSummary> candidates;  // best first
  std::vector<ReviewClusterSummary> clusters;
};
ReviewSummary SummarizeReview(const InpaintReview& review, int patch_radius);
template <>
const StructInfo& InfoOf<ReviewSummary>();

// A review decision as JSON: {"target": [r, c], "source": [r, c]}. Described.
struct ReviewDecisionSummary {
  std::vector<int> target, source;  // [row, col]
};
template <>
const StructInfo& InfoOf<ReviewDecisionSummary>();

// review.json of `inpaint --review`'s folder: the decisions so far and the pending review. Described.
struct ReviewFolderSummary {
  std::vector<ReviewDecisionSummary> decisions;
  ReviewSummary review;
};
template <>
const StructInfo& InfoOf<ReviewFolderSummary>();

std::vector<ReviewDecisionSummary> SummarizeDecisions(const std::vector<ReviewDecision>& decisions);

// ToJson(SummarizeReview(review, patch_radius)).
nlohmann::ordered_json ReviewToJson(const InpaintReview& review, int patch_radius);
// [{"target": [r, c], "source": [r, c]}, ...]: SummarizeDecisions as a JSON array.
nlohmann::ordered_json DecisionsToJson(const std::vector<ReviewDecision>& decisions);

}  // namespace lidarshop
