#include "lidarshop/inpaint/inpaint.h"

#include <fmt/format.h>

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
  return fmt::format("filled {} hole pixels in {} iterations, {} candidate patches evaluated, {:.3f} s",
                     hole_pixels, iterations, candidates_evaluated, seconds);
}

InpaintResult Inpaint(const cv::Mat& image, const cv::Mat& hole_mask, const InpaintOptions& options,
                      Progress* progress) {
  return Inpaint(image, hole_mask, options, InpaintStrategies{}, progress);
}

namespace {

// The fill front with cached priorities.
class Front {
 public:
  Front(const InpaintCanvas& canvas, PatchPriority& priority) : canvas_(canvas), priority_(priority) {
    flag_ = ComputeFillFront(canvas.known());
    value_ = cv::Mat::zeros(canvas.rows(), canvas.cols(), CV_64F);
    for (int r = 0; r < canvas.rows(); ++r) {
      for (int c = 0; c < canvas.cols(); ++c) {
        if (!flag_.at<uint8_t>(r, c)) continue;
        pixels_.push_back({r, c});
        value_.at<double>(r, c) = priority_.Priority(canvas, {r, c});
      }
    }
  }

  bool empty() const { return pixels_.empty(); }

  // Highest priority; ties: smallest (row, col).
  Pixel Best() const {
    Pixel best = pixels_.front();
    double best_value = value_.at<double>(best.row, best.col);
    for (const Pixel& p : pixels_) {
      const double v = value_.at<double>(p.row, p.col);
      if (v > best_value ||
          (v == best_value && canvas_.Index(p.row, p.col) < canvas_.Index(best.row, best.col))) {
        best = p;
        best_value = v;
      }
    }
    return best;
  }
  double Value(Pixel p) const { return value_.at<double>(p.row, p.col); }

  // After Ψtarget was filled: the front can change only within one pixel of the patch; priorities within the
  // priority's influence radius.
  void Update(Pixel target) {
    const int R = canvas_.patch_radius();
    const cv::Rect image_rect(0, 0, canvas_.cols(), canvas_.rows());
    const cv::Rect front_box =
        cv::Rect(target.col - R - 1, target.row - R - 1, 2 * R + 3, 2 * R + 3) & image_rect;
    for (int r = front_box.y; r < front_box.y + front_box.height; ++r) {
      for (int c = front_box.x; c < front_box.x + front_box.width; ++c) {
        const uint8_t now = IsFront(r, c) ? 1 : 0;
        uint8_t& flag = flag_.at<uint8_t>(r, c);
        if (now && !flag) pixels_.push_back({r, c});
        flag = now;
      }
    }
    pixels_.erase(std::remove_if(pixels_.begin(), pixels_.end(),
                                 [&](const Pixel& p) { return !flag_.at<uint8_t>(p.row, p.col); }),
                  pixels_.end());
    const int reach = R + std::max(1, priority_.InfluenceRadius(canvas_));
    const cv::Rect dirty =
        cv::Rect(target.col - reach, target.row - reach, 2 * reach + 1, 2 * reach + 1) & image_rect;
    for (const Pixel& p : pixels_) {
      if (dirty.contains(cv::Point(p.col, p.row)))
        value_.at<double>(p.row, p.col) = priority_.Priority(canvas_, p);
    }
  }

  // Compares with a recomputation from scratch; throws std::logic_error naming the first stranded pixel.
  void Check() const {
    const cv::Mat fresh = ComputeFillFront(canvas_.known());
    int listed = 0;
    for (int r = 0; r < canvas_.rows(); ++r) {
      for (int c = 0; c < canvas_.cols(); ++c) {
        if (fresh.at<uint8_t>(r, c) != flag_.at<uint8_t>(r, c)) {
          throw std::logic_error(
              fmt::format("fill front: pixel (row {}, col {}) is {} but should be {}", r, c,
                          flag_.at<uint8_t>(r, c) ? "on the front (stranded)" : "off the front",
                          fresh.at<uint8_t>(r, c) ? "on it" : "off it"));
        }
        listed += fresh.at<uint8_t>(r, c);
      }
    }
    if (listed != static_cast<int>(pixels_.size())) {
      throw std::logic_error(
          fmt::format("fill front: {} pixels listed, {} on the front", pixels_.size(), listed));
    }
    for (const Pixel& p : pixels_) {
      const double cached = Value(p), now = priority_.Priority(canvas_, p);
      if (std::abs(cached - now) > 1e-9 * std::max(1.0, std::abs(now))) {
        throw std::logic_error(fmt::format("fill front: priority of (row {}, col {}) is stale: {} vs {}",
                                           p.row, p.col, cached, now));
      }
    }
  }

 private:
  bool IsFront(int r, int c) const {
    if (canvas_.IsKnown(r, c)) return false;
    return (r > 0 && canvas_.IsKnown(r - 1, c)) || (r + 1 < canvas_.rows() && canvas_.IsKnown(r + 1, c)) ||
           (c > 0 && canvas_.IsKnown(r, c - 1)) || (c + 1 < canvas_.cols() && canvas_.IsKnown(r, c + 1));
  }

  const InpaintCanvas& canvas_;
  PatchPriority& priority_;
  cv::Mat flag_, value_;
  std::vector<Pixel> pixels_;
};

}  // namespace

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
  InpaintCanvas canvas(image, hole_mask, options.patch_radius);  // validates the mask against the image
  if (image.depth() == CV_32F || image.depth() == CV_64F) {
    // Any known pixel may become a source or enter a patch distance: a NaN or inf there would spread into
    // the fill. Values inside the hole are replaced and do not matter.
    cv::Mat known = cv::Mat::zeros(image.size(), image.type());  // any channel count (setTo takes <= 4)
    image.copyTo(known, hole_mask == 0);
    cv::Point at;
    if (!cv::checkRange(known, /*quiet=*/true, &at)) {
      throw InputError(fmt::format("Inpaint: the image holds NaN or inf at pixel (x {}, y {}) outside the hole; "
                                   "add it to the hole or fix it",
                                   at.x, at.y));
    }
  }
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
  if (!strategies.search) strategies.search = MakeSearch(options);
  PatchPriority& priority = *strategies.priority;
  PatchSearch& search = *strategies.search;

  priority.Initialize(canvas);
  Front front(canvas, priority);
  const int count = strategies.acceptance ? options.acceptance_candidates : 1;
  int remaining = result.hole_pixels;
  if (progress) progress->Restart("inpaint", remaining);
  while (!front.empty()) {
    const Pixel target = front.Best();
    FillStep step;
    step.target = target;
    step.priority = front.Value(target);
    const std::unique_ptr<TargetDifference> difference = strategies.difference->ForTarget(canvas, target);
    const std::vector<SourceCandidate> candidates = search.Find(canvas, *difference, target, count);
    LIDARSHOP_CHECK(!candidates.empty());
    const SourceCandidate* chosen = &candidates.front();
    if (strategies.acceptance) {
      chosen = nullptr;
      for (const SourceCandidate& c : candidates) {
        if (strategies.acceptance->Accept(canvas, target, c)) {
          chosen = &c;
          break;
        }
        ++step.rejected;
      }
      if (chosen == nullptr) {
        chosen = &candidates.front();
        ++result.acceptance_fallbacks;
      }
    }
    step.source = chosen->source;
    step.difference = chosen->difference;
    const std::vector<Pixel> filled = canvas.CopyPatch(target, chosen->source, result.iterations);
    step.filled_pixels = static_cast<int>(filled.size());
    LIDARSHOP_CHECK(!filled.empty());
    priority.Update(canvas, target, filled);
    front.Update(target);
    if (options.check_bookkeeping) {
      front.Check();
      priority.CheckConsistency(canvas);
    }
    result.steps.push_back(step);
    ++result.iterations;
    remaining -= step.filled_pixels;
    Advance(progress, step.filled_pixels);
  }
  LIDARSHOP_CHECK(remaining == 0);
  if (progress) progress->Finish();
  result.image = canvas.Image();
  result.fill_iteration = canvas.fill_iteration().clone();
  result.source_pixel = canvas.source_pixel().clone();
  result.candidates_evaluated = search.evaluations();
  result.seconds = timer.Seconds();
  return result;
}

}  // namespace lidarshop
