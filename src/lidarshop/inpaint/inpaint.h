// Greedy patch-based inpainting (exemplar-based, Criminisi, Pérez, Toyama 2004, "Region filling and object
// removal by exemplar-based image inpainting", IEEE TIP 13(9)) as a framework of pluggable parts:
//
//   repeat until the hole is empty:
//     p  = the fill-front pixel with the highest PatchPriority (ties: smallest row, then column)
//     q* = PatchSearch over source centres for the least PatchDifference to Ψp's known pixels; with an
//          acceptance (acceptance.h), the first of the best `acceptance_candidates` that it accepts, searched
//          in the local window first, then in the whole image (forward_looking.h); if none passes, the best
//          (or a review stop, review.h). With lookahead M > 1 the M best targets are decided and the one
//          accepted with the largest margin is filled (thesis ch. 7.2).
//     copy Ψq*'s pixels into the unknown pixels of Ψp; update the front and the priorities near Ψp
//
// Criminisi inpainting is {CriminisiPriority, WeightedSsd, ExhaustiveSearch}. Images are plain
// multi-channel float images (H x W CV_32FC(C)) with a hole mask (H x W CV_8U, non-zero = hole); the
// hole may touch the image border. Source patches are (2R+1)² patches entirely inside the image and
// entirely outside the original hole.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "lidarshop/inpaint/acceptance.h"
#include "lidarshop/inpaint/canvas.h"
#include "lidarshop/inpaint/patch_difference.h"
#include "lidarshop/inpaint/priority.h"
#include "lidarshop/inpaint/review.h"
#include "lidarshop/inpaint/search.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

class Progress;

enum class InpaintPriorityKind { kCriminisi, kOnionPeel, kRandom };
enum class InpaintSearchKind { kExhaustive, kLocal, kTwoStep, kPatchMatch };

struct InpaintOptions {
  int patch_radius = 5;  // pixels; patches are (2·patch_radius+1)² (default 11 x 11)
  InpaintPriorityKind priority = InpaintPriorityKind::kCriminisi;
  InpaintSearchKind search = InpaintSearchKind::kExhaustive;
  std::vector<float> channel_weights;  // per channel, >= 0, for the SSD and the gradients; empty = all 1
  uint64_t seed = 0;                   // random priority and PatchMatch
  // Criminisi priority.
  double normal_sigma = 1.5;  // pixels; blur of the hole mask for front normals
  double alpha = 255.0;       // image units; data-term normalisation (255 for 8-bit intensities)
  double data_floor = 1e-3;   // added to the data term
  // Local and two-step searches.
  int local_window_radius = 40;  // pixels; half-width of the search window around the target
  double global_gain = 1.0;  // two-step: a global source must be this many times better than the local one
  // PatchMatch.
  int patchmatch_random_samples = 48;  // uniform draws per query
  int patchmatch_local_samples = 32;   // draws within local_window_radius of the target per query
  int patchmatch_iterations = 4;       // propagation + random-search rounds per query
  // Acceptance (thesis ch. 7.1). Used when InpaintStrategies::acceptance is null and acceptance.enabled;
  // AcceptanceOptions::Combined() is the recommended set.
  AcceptanceOptions acceptance;
  int acceptance_candidates = 8;       // K: ranked candidates offered to the acceptance per search step
  bool acceptance_local_first = true;  // search the local window (local_window_radius) before the image
  // Forward-looking filling (thesis ch. 7.2): the M highest-priority targets that have not failed are
  // decided at once and the one accepted with the largest margin is filled; 1 = plain greedy order.
  int lookahead = 1;
  // Which of the passing lookahead targets is filled: the one with the largest acceptance margin (thesis
  // 7.2), or the highest-priority one (failing targets are still deferred).
  bool lookahead_by_margin = true;
  // Review (thesis "User action"): at a target where no candidate passes, take the next entry of
  // review_decisions; when there is none, stop and return InpaintResult::review if stop_for_review, else
  // copy the best candidate (an acceptance fallback).
  bool stop_for_review = false;
  std::vector<ReviewDecision> review_decisions;
  int review_candidates = 200;       // N: candidates listed in a review
  double review_cluster_rms = 0.04;  // value-range units: candidates closer than this share a cluster
  // Verify after every fill that the incremental front and priorities equal a recomputation from scratch
  // (slow; for tests). Throws std::logic_error on a mismatch.
  bool check_bookkeeping = false;
  void Check() const;  // throws OptionsError
};

template <>
const EnumInfo& EnumInfoOf<InpaintPriorityKind>();
template <>
const EnumInfo& EnumInfoOf<InpaintSearchKind>();
template <>
const StructInfo& InfoOf<InpaintOptions>();

// The pluggable parts; any left null is made from InpaintOptions.
struct InpaintStrategies {
  std::unique_ptr<PatchPriority> priority;
  std::unique_ptr<PatchDifference> difference;
  std::unique_ptr<PatchSearch> search;
  std::unique_ptr<PatchAcceptance>
      acceptance;  // null = MakeAcceptance(options.acceptance): none unless enabled
};

std::unique_ptr<PatchPriority> MakePriority(const InpaintOptions& options);
std::unique_ptr<PatchSearch> MakeSearch(const InpaintOptions& options);

struct FillStep {
  Pixel target;             // centre of the filled patch
  Pixel source;             // centre of the source patch copied from
  float difference = 0.0f;  // PatchDifference of the chosen source
  double priority = 0.0;    // priority of the target when chosen
  int filled_pixels = 0;    // hole pixels filled by this step
  int rejected = 0;         // candidates the acceptance hook rejected before this one
  bool accepted = true;     // false: no candidate passed (fallback or a review decision)
  int review_point = -1;    // index into review_decisions when a decision was applied
  double margin = 0.0;      // acceptance margin of the chosen candidate (0 without acceptance)
};

// Described (its counts, then review_stop as "review": the keys of `lidarshop inpaint --json`); the images,
// steps and the review itself are not JSON.
struct InpaintResult {
  cv::Mat image;           // H x W CV_32FC(C), hole filled
  cv::Mat fill_iteration;  // H x W CV_32S: iteration that filled each pixel, -1 = known from the start
  cv::Mat source_pixel;    // H x W CV_32SC2: (row, col) each filled pixel was copied from, (-1, -1) = known
  std::vector<FillStep> steps;  // fill order
  int iterations = 0;
  int hole_pixels = 0;
  int64_t candidates_evaluated = 0;  // patch differences evaluated (including early-terminated ones)
  int acceptance_fallbacks = 0;      // steps where no offered candidate was accepted (the best was used)
  int rejected = 0;                  // candidates rejected by the acceptance over the whole fill
  int global_searches = 0;  // targets whose local window held no accepted candidate (acceptance only)
  bool complete = true;     // false: stopped for a review; image holds the partial fill
  std::optional<InpaintReview> review;    // set when stopped for a review
  std::optional<ReviewStop> review_stop;  // set with review: where it stopped, in brief
  double seconds = 0.0;                   // wall-clock time of the fill
  std::string Summary() const;            // one line
};

template <>
const StructInfo& InfoOf<InpaintResult>();

// Fills the hole. Throws InputError on mismatched or invalid inputs, when no source patch exists and when a
// review decision does not fit the fill (another target, or a source that is not a source centre).
InpaintResult Inpaint(const cv::Mat& image, const cv::Mat& hole_mask, const InpaintOptions& options,
                      Progress* progress = nullptr);
InpaintResult Inpaint(const cv::Mat& image, const cv::Mat& hole_mask, const InpaintOptions& options,
                      InpaintStrategies strategies, Progress* progress = nullptr);

}  // namespace lidarshop
