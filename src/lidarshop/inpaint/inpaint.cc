#include "lidarshop/inpaint/inpaint.h"

#include <fmt/format.h>

#include "lidarshop/inpaint/fill_front.h"
#include "lidarshop/inpaint/forward_looking.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/progress.h"
#include "lidarshop/util/timer.h"

namespace lidarshop {

void InpaintOptions::Check() const {
  CheckOption(patch_radius >= 1 && patch_radius <= 64,
              fmt::format("InpaintOptions.patch_radius must be in [1, 64], got {}", patch_radius));
  for (float w : channel_weights) {
    CheckOption(std::isfinite(w) && w >= 0.0f,
                fmt::format("InpaintOptions.channel_weights must be >= 0, got {}", w));
  }
  CheckOption(normal_sigma > 0.0 && normal_sigma <= 50.0,
              fmt::format("InpaintOptions.normal_sigma must be in (0, 50], got {}", normal_sigma));
  CheckOption(alpha > 0.0, fmt::format("InpaintOptions.alpha must be > 0, got {}", alpha));
  CheckOption(data_floor >= 0.0, fmt::format("InpaintOptions.data_floor must be >= 0, got {}", data_floor));
  CheckOption(local_window_radius >= 1,
              fmt::format("InpaintOptions.local_window_radius must be >= 1, got {}", local_window_radius));
  CheckOption(global_gain >= 1.0,
              fmt::format("InpaintOptions.global_gain must be >= 1, got {}", global_gain));
  CheckOption(patchmatch_random_samples >= 1,
              fmt::format("InpaintOptions.patchmatch_random_samples must be >= 1, got {}",
                          patchmatch_random_samples));
  CheckOption(
      patchmatch_iterations >= 0,
      fmt::format("InpaintOptions.patchmatch_iterations must be >= 0, got {}", patchmatch_iterations));
  CheckOption(
      acceptance_candidates >= 1,
      fmt::format("InpaintOptions.acceptance_candidates must be >= 1, got {}", acceptance_candidates));
  acceptance.Check();
  CheckOption(lookahead >= 1, fmt::format("InpaintOptions.lookahead must be >= 1, got {}", lookahead));
  CheckOption(review_candidates >= 1,
              fmt::format("InpaintOptions.review_candidates must be >= 1, got {}", review_candidates));
  CheckOption(review_cluster_rms >= 0.0,
              fmt::format("InpaintOptions.review_cluster_rms must be >= 0, got {}", review_cluster_rms));
}

std::unique_ptr<PatchPriority> MakePriority(const InpaintOptions& options) {
  switch (options.priority) {
    case InpaintPriorityKind::kRandom:
      return std::make_unique<RandomPriority>(options.seed);
    case InpaintPriorityKind::kOnionPeel:
      return std::make_unique<OnionPeelPriority>();
    case InpaintPriorityKind::kCriminisi:
      break;
  }
  return std::make_unique<CriminisiPriority>(CriminisiPriorityOptions{
      options.normal_sigma, options.alpha, options.data_floor, options.channel_weights});
}

std::unique_ptr<PatchSearch> MakeSearch(const InpaintOptions& options) {
  switch (options.search) {
    case InpaintSearchKind::kLocal:
      return std::make_unique<LocalSearch>(options.local_window_radius);
    case InpaintSearchKind::kTwoStep:
      return std::make_unique<TwoStepSearch>(options.local_window_radius, options.global_gain);
    case InpaintSearchKind::kPatchMatch:
      return std::make_unique<PatchMatchSearch>(
          PatchMatchOptions{.random_samples = options.patchmatch_random_samples,
                            .local_samples = options.patchmatch_local_samples,
                            .local_radius = options.local_window_radius,
                            .iterations = options.patchmatch_iterations,
                            .seed = options.seed});
    case InpaintSearchKind::kExhaustive:
      break;
  }
  return std::make_unique<ExhaustiveSearch>();
}

std::string InpaintResult::Summary() const {
  std::string s = fmt::format("filled {} hole pixels in {} iterations, {} candidate patches evaluated",
                              hole_pixels, iterations, candidates_evaluated);
  if (rejected > 0 || global_searches > 0) {
    s += fmt::format(", {} rejected, {} targets searched the whole image, {} fallbacks", rejected,
                     global_searches, acceptance_fallbacks);
  }
  return s + fmt::format(", {:.3f} s", seconds);
}

InpaintResult Inpaint(const cv::Mat& image, const cv::Mat& hole_mask, const InpaintOptions& options,
                      Progress* progress) {
  return Inpaint(image, hole_mask, options, InpaintStrategies{}, progress);
}

InpaintResult Inpaint(const cv::Mat& image, const cv::Mat& hole_mask, const InpaintOptions& options,
                      InpaintStrategies strategies, Progress* progress) {
  options.Check();
  const Timer timer;
  if (!options.channel_weights.empty() &&
      static_cast<int>(options.channel_weights.size()) != image.channels()) {
    throw OptionsError(
        fmt::format("InpaintOptions.channel_weights has {} weights for an image of {} channels",
                    options.channel_weights.size(), image.channels()));
  }
  InpaintCanvas canvas(image, hole_mask, options.patch_radius);
  InpaintResult result;
  result.hole_pixels = static_cast<int>(cv::countNonZero(hole_mask));
  if (result.hole_pixels > 0 && canvas.source_centers().empty()) {
    ThrowInputError(
        "", "", "mask",
        fmt::format("no fully known {0}x{0} source patch: the hole leaves no patch of the image whole",
                    2 * options.patch_radius + 1));
  }
  if (!strategies.priority) strategies.priority = MakePriority(options);
  if (!strategies.difference) strategies.difference = std::make_unique<WeightedSsd>(options.channel_weights);
  const bool search_is_exhaustive = !strategies.search && options.search == InpaintSearchKind::kExhaustive;
  if (!strategies.search) strategies.search = MakeSearch(options);
  PatchPriority& priority = *strategies.priority;
  PatchSearch& search = *strategies.search;

  if (!strategies.acceptance)
    strategies.acceptance = MakeAcceptance(options.acceptance, options.channel_weights);
  if (strategies.acceptance) strategies.acceptance->Initialize(canvas);

  priority.Initialize(canvas);
  Front front(canvas, priority);
  TargetChooser chooser(canvas, options, *strategies.difference, search, strategies.acceptance.get(),
                        search_is_exhaustive);
  int remaining = result.hole_pixels;
  int review_points = 0;
  if (progress) progress->Restart("inpaint", remaining);
  while (!front.empty()) {
    const TargetDecision decision = chooser.Choose(front);
    const Pixel target = decision.target;
    FillStep step;
    step.target = target;
    step.priority = front.Value(target);
    step.rejected = decision.rejected;
    step.accepted = decision.passed();
    step.margin = strategies.acceptance ? decision.verdict.margin : 0.0;
    result.rejected += decision.rejected;
    SourceCandidate chosen = decision.candidates[std::max(decision.chosen, 0)];
    if (!decision.passed()) {
      if (review_points < static_cast<int>(options.review_decisions.size())) {
        const ReviewDecision& made = options.review_decisions[review_points];
        if (!(made.target == target) || !canvas.Inside(made.source.row, made.source.col) ||
            !canvas.IsSource(made.source.row, made.source.col)) {
          ThrowInputError(
              "", "", fmt::format("review decision {}", review_points),
              fmt::format("decision for target ({}, {}) with source ({}, {}) does not fit this fill "
                          "(target ({}, {}); the source must be a source centre)",
                          made.target.row, made.target.col, made.source.row, made.source.col, target.row,
                          target.col));
        }
        step.review_point = review_points;
        chosen = {made.source, strategies.difference->ForTarget(canvas, target)
                                   ->Evaluate(made.source, std::numeric_limits<float>::infinity())};
      } else if (options.stop_for_review) {
        const std::unique_ptr<TargetDifference> difference = strategies.difference->ForTarget(canvas, target);
        InpaintReview review =
            MakeReview(canvas, target, search.Find(canvas, *difference, target, options.review_candidates),
                       strategies.acceptance.get(), options.review_cluster_rms, options.channel_weights);
        review.review_point = review_points;
        review.iteration = result.iterations;
        result.review = std::move(review);
        result.complete = false;
        break;
      } else {
        ++result.acceptance_fallbacks;
      }
      ++review_points;
    }
    step.source = chosen.source;
    step.difference = chosen.difference;
    const std::vector<Pixel> filled = canvas.CopyPatch(target, chosen.source, result.iterations);
    step.filled_pixels = static_cast<int>(filled.size());
    LIDARSHOP_CHECK(!filled.empty());
    priority.Update(canvas, target, filled);
    front.Update(target);
    chooser.Filled(target);
    if (options.check_bookkeeping) {
      front.Check();
      priority.CheckConsistency(canvas);
    }
    result.steps.push_back(step);
    ++result.iterations;
    remaining -= step.filled_pixels;
    Advance(progress, step.filled_pixels);
  }
  LIDARSHOP_CHECK(remaining == 0 || !result.complete);
  if (progress) progress->Finish();
  result.image = canvas.Image();
  result.fill_iteration = canvas.fill_iteration().clone();
  result.source_pixel = canvas.source_pixel().clone();
  result.candidates_evaluated = chooser.evaluations();
  result.global_searches = chooser.global_searches();
  result.seconds = timer.Seconds();
  return result;
}

}  // namespace lidarshop
