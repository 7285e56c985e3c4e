#include "lidarshop/inpaint/inpaint.h"

#include <fmt/format.h>

#include "lidarshop/inpaint/inpaint_session.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"

namespace lidarshop {

void InpaintOptions::Check() const { Validate(*this); }

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
