#include "lidarshop/inpaint/inpaint_session.h"

#include <limits>
#include <optional>

#include <fmt/format.h>

#include "lidarshop/inpaint/fill_front.h"
#include "lidarshop/inpaint/forward_looking.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/progress.h"
#include "lidarshop/util/timer.h"

namespace lidarshop {

struct InpaintSession::State {
  State(const cv::Mat& image, const cv::Mat& hole_mask, const InpaintOptions& o, InpaintStrategies s,
        Progress* p)
      : options(o), canvas(image, hole_mask, o.patch_radius), strategies(std::move(s)), progress(p) {}

  InpaintOptions options;
  InpaintCanvas canvas;
  InpaintStrategies strategies;
  Progress* progress;
  std::unique_ptr<Front> front;
  std::unique_ptr<TargetChooser> chooser;
  InpaintResult result;  // steps and counters so far
  std::vector<ReviewDecision> decisions;
  std::optional<TargetDecision> pending;  // the target of the pending review
  int review_points = 0;
  int remaining = 0;
  double seconds = 0.0;

  // Copies `chosen` into the decision's target and updates the bookkeeping.
  void Fill(const TargetDecision& decision, const SourceCandidate& chosen, int review_point) {
    const Pixel target = decision.target;
    FillStep step;
    step.target = target;
    step.priority = front->Value(target);
    step.rejected = decision.rejected;
    step.accepted = decision.passed();
    step.margin = strategies.acceptance ? decision.verdict.margin : 0.0;
    step.review_point = review_point;
    step.source = chosen.source;
    step.difference = chosen.difference;
    result.rejected += decision.rejected;
    const std::vector<Pixel> filled = canvas.CopyPatch(target, chosen.source, result.iterations);
    step.filled_pixels = static_cast<int>(filled.size());
    LIDARSHOP_CHECK(!filled.empty());
    strategies.priority->Update(canvas, target, filled);
    front->Update(target);
    chooser->Filled(target);
    if (options.check_bookkeeping) {
      front->Check();
      strategies.priority->CheckConsistency(canvas);
    }
    result.steps.push_back(step);
    ++result.iterations;
    remaining -= step.filled_pixels;
    Advance(progress, step.filled_pixels);
  }

  // When no candidate passes: the best candidate not rejected outright (AcceptanceVerdict::hard), among the
  // decision's and then among the search's best `review_candidates`; the best one when all are.
  SourceCandidate Fallback(const TargetDecision& decision) const {
    if (!strategies.acceptance) return decision.candidates.front();
    auto soft = [&](const SourceCandidate& c) {
      return !strategies.acceptance->Judge(canvas, decision.target, c).hard;
    };
    for (const SourceCandidate& c : decision.candidates)
      if (soft(c)) return c;
    const auto difference = strategies.difference->ForTarget(canvas, decision.target);
    for (const SourceCandidate& c :
         strategies.search->Find(canvas, *difference, decision.target, options.review_candidates))
      if (soft(c)) return c;
    return decision.candidates.front();
  }

  SourceCandidate Checked(const ReviewDecision& made, Pixel target) const {
    if (!(made.target == target) || !canvas.Inside(made.source.row, made.source.col) ||
        !canvas.IsSource(made.source.row, made.source.col) || !canvas.SourceFits(target, made.source)) {
      ThrowInputError("", "", fmt::format("review decision {}", review_points),
                      fmt::format("decision for target ({}, {}) with source ({}, {}) does not fit this fill "
                                  "(target ({}, {}); the source must be a source centre)",
                                  made.target.row, made.target.col, made.source.row, made.source.col,
                                  target.row, target.col));
    }
    return {made.source, strategies.difference->ForTarget(canvas, target)
                             ->Evaluate(made.source, std::numeric_limits<float>::infinity())};
  }
};

InpaintSession::InpaintSession(const cv::Mat& image, const cv::Mat& hole_mask, const InpaintOptions& options,
                               InpaintStrategies strategies, Progress* progress) {
  options.Check();
  const Timer timer;
  if (!options.channel_weights.empty() &&
      static_cast<int>(options.channel_weights.size()) != image.channels()) {
    throw OptionsError(
        fmt::format("InpaintOptions.channel_weights has {} weights for an image of {} channels",
                    options.channel_weights.size(), image.channels()));
  }
  state_ = std::make_unique<State>(image, hole_mask, options, std::move(strategies), progress);
  State& s = *state_;
  s.result.hole_pixels = static_cast<int>(cv::countNonZero(hole_mask));
  if (s.result.hole_pixels > 0 && s.canvas.source_centers().empty()) {
    ThrowInputError(
        "", "", "mask",
        fmt::format("no fully known {0}x{0} source patch: the hole leaves no patch of the image whole",
                    2 * options.patch_radius + 1));
  }
  InpaintStrategies& st = s.strategies;
  if (!st.priority) st.priority = MakePriority(options);
  if (!st.difference) st.difference = std::make_unique<WeightedSsd>(options.channel_weights);
  const bool search_is_exhaustive = !st.search && options.search == InpaintSearchKind::kExhaustive;
  if (!st.search) st.search = MakeSearch(options);
  if (!st.acceptance) st.acceptance = MakeAcceptance(options.acceptance, options.channel_weights);
  if (st.acceptance) st.acceptance->Initialize(s.canvas);
  st.priority->Initialize(s.canvas);
  s.front = std::make_unique<Front>(s.canvas, *st.priority);
  s.chooser = std::make_unique<TargetChooser>(s.canvas, s.options, *st.difference, *st.search,
                                              st.acceptance.get(), search_is_exhaustive);
  s.remaining = s.result.hole_pixels;
  if (progress) progress->Restart("inpaint", s.remaining);
  s.seconds += timer.Seconds();
}

InpaintSession::~InpaintSession() = default;

bool InpaintSession::Run() {
  State& s = *state_;
  if (s.pending) return false;
  const Timer timer;
  const InpaintOptions& options = s.options;
  while (!s.front->empty()) {
    const TargetDecision decision = s.chooser->Choose(*s.front);
    if (decision.passed()) {
      s.Fill(decision, decision.candidates[decision.chosen], -1);
      continue;
    }
    if (s.review_points < static_cast<int>(options.review_decisions.size())) {
      const ReviewDecision& made = options.review_decisions[s.review_points];
      s.Fill(decision, s.Checked(made, decision.target), s.review_points);
      s.decisions.push_back(made);
    } else if (options.stop_for_review) {
      const Pixel target = decision.target;
      const auto difference = s.strategies.difference->ForTarget(s.canvas, target);
      InpaintReview review =
          MakeReview(s.canvas, target,
                     s.strategies.search->Find(s.canvas, *difference, target, options.review_candidates),
                     s.strategies.acceptance.get(), options.review_cluster_rms, options.channel_weights);
      review.review_point = s.review_points;
      review.iteration = s.result.iterations;
      s.result.review_stop = StopOf(review);
      s.result.review = std::move(review);
      s.pending = decision;
      s.seconds += timer.Seconds();
      return false;
    } else {
      ++s.result.acceptance_fallbacks;
      s.Fill(decision, s.Fallback(decision), -1);
    }
    ++s.review_points;
  }
  LIDARSHOP_CHECK(s.remaining == 0);
  if (s.progress) s.progress->Finish();
  s.seconds += timer.Seconds();
  return true;
}

const InpaintReview* InpaintSession::pending_review() const {
  return state_->pending ? &*state_->result.review : nullptr;
}

void InpaintSession::Decide(Pixel source) {
  State& s = *state_;
  if (!s.pending) ThrowInputError("", "", "decision", "no review is pending");
  const ReviewDecision made{s.pending->target, source};
  const SourceCandidate chosen = s.Checked(made, made.target);
  const TargetDecision decision = *s.pending;
  s.pending.reset();
  s.result.review.reset();
  s.result.review_stop.reset();
  s.Fill(decision, chosen, s.review_points);
  s.decisions.push_back(made);
  ++s.review_points;
}

void InpaintSession::SetProgress(Progress* progress) {
  state_->progress = progress;
  if (progress) progress->Restart("inpaint", state_->remaining);
}

const std::vector<ReviewDecision>& InpaintSession::decisions() const { return state_->decisions; }

InpaintResult InpaintSession::Result() const {
  InpaintResult result = ResultWithoutImage();
  result.image = state_->canvas.Image();
  return result;
}

InpaintResult InpaintSession::ResultWithoutImage() const {
  const State& s = *state_;
  InpaintResult result = s.result;
  result.complete = !s.pending;
  result.fill_iteration = s.canvas.fill_iteration().clone();
  result.source_pixel = s.canvas.source_pixel().clone();
  result.candidates_evaluated = s.chooser->evaluations();
  result.global_searches = s.chooser->global_searches();
  result.seconds = s.seconds;
  return result;
}

}  // namespace lidarshop
