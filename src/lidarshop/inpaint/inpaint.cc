#include "lidarshop/inpaint/inpaint.h"

#include <fmt/format.h>

#include "lidarshop/inpaint/inpaint_session.h"
#include "lidarshop/util/error.h"

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
  if (image.depth() == CV_32F || image.depth() == CV_64F) {
    if (image.size() == hole_mask.size() && hole_mask.type() == CV_8U) {
      // Any known pixel may become a source or enter a patch distance: a NaN or inf there would spread into
      // the fill. Values inside the hole are replaced and do not matter.
      cv::Mat known = cv::Mat::zeros(image.size(), image.type());  // any channel count (setTo takes <= 4)
      image.copyTo(known, hole_mask == 0);
      cv::Point at;
      if (!cv::checkRange(known, /*quiet=*/true, &at)) {
        throw InputError(
            fmt::format("Inpaint: the image holds NaN or inf at pixel (x {}, y {}) outside the hole; add it "
                        "to the hole or fix it",
                        at.x, at.y));
      }
    }
  }
  InpaintSession session(image, hole_mask, options, std::move(strategies), progress);
  session.Run();
  return session.Result();
}

}  // namespace lidarshop
