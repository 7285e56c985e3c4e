// A fill that can stop and be resumed in process (thesis ch. 7.1 "User action"): the state the browser editor
// keeps between the user's decisions. Inpaint() is a session run to the end.
//
//   InpaintOptions options;
//   options.acceptance = AcceptanceOptions::Combined();
//   options.stop_for_review = true;
//   InpaintSession session(image, hole, options);
//   while (!session.Run()) {                       // stopped: no candidate passed at a target
//     const InpaintReview& review = *session.pending_review();
//     session.Decide(review.candidates[k].source);  // a listed candidate, or any source centre by hand
//   }
//   InpaintResult result = session.Result();
//
// The result equals Inpaint() with options.review_decisions = session.decisions() (tested), so a session can
// also be rebuilt later by replay (what `lidarshop inpaint --resume` does).
#pragma once

#include <memory>
#include <vector>

#include <opencv2/core.hpp>

#include "lidarshop/inpaint/inpaint.h"

namespace lidarshop {

class InpaintSession {
 public:
  // Checks the options and inputs as Inpaint() does (throws OptionsError / InputError).
  InpaintSession(const cv::Mat& image, const cv::Mat& hole_mask, const InpaintOptions& options,
                 InpaintStrategies strategies = {}, Progress* progress = nullptr);
  ~InpaintSession();
  InpaintSession(const InpaintSession&) = delete;
  InpaintSession& operator=(const InpaintSession&) = delete;

  // Fills until the hole is empty (returns true) or until a target where no candidate passes and no decision
  // is left while options.stop_for_review is set (returns false; see pending_review()).
  bool Run();
  // The review the fill stopped at, or null.
  const InpaintReview* pending_review() const;
  // Copies the source patch centred at `source` (a source centre) into the pending review's target; Run()
  // then continues. Throws InputError when nothing is pending or `source` is not a source centre.
  void Decide(Pixel source);
  // Reports the next Run() and Decide() to `progress` (nullptr = silent) instead of the one given at
  // construction, restarted at the hole pixels still to fill: a caller that runs each stretch between two
  // review points as its own operation (the editor's jobs) gives each its own progress and cancel.
  void SetProgress(Progress* progress);
  // Every decision applied so far, review point by review point.
  const std::vector<ReviewDecision>& decisions() const;
  // The fill as it stands (partial when stopped: complete = false and review set).
  InpaintResult Result() const;
  // Result() with `image` left empty: for a caller that needs only where each pixel came from (the scan fill
  // copies its channels from the sources), one copy of the image less while the session's own is held.
  InpaintResult ResultWithoutImage() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace lidarshop
