// Inpainting with the patch review (inpaint/inpaint_session.h, thesis ch. 7.1 "User action"; docs/api.md):
// the scan's colour (or intensity) ray image is inpainted in the painted hole; where no candidate passes the
// acceptance tests the fill stops and the editor shows the top candidates grouped in clusters; the user
// accepts one or places a source patch by hand, and the fill goes on to the next review point or the end.
// The finished fill is one undoable edit of that channel (the points and ranges do not change).
//
// What is reviewed is the ray image of one channel, not FillScan's joint image: the fill module runs its
// patch search to the end in one call and exposes no session to stop in.
#include <fmt/format.h>

#include "http.h"
#include "lidarshop/fill/fill.h"
#include "lidarshop/inpaint/inpaint_session.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "replies.h"

namespace lidarshop::server {

namespace {

// The defaults of the editor's review: the combined acceptance tests (without them nothing is ever
// reviewed) and the CLI's two-step search.
InpaintOptions ReviewDefaults() {
  InpaintOptions options;
  options.patch_radius = 4;
  options.search = InpaintSearchKind::kTwoStep;
  options.global_gain = 1.5;
  options.acceptance = AcceptanceOptions::Combined();
  options.review_candidates = 100;
  return options;
}

// The channel's ray image as the inpainting's float image (grey levels 0..255).
cv::Mat ChannelImage(const Scan& scan, const std::string& channel) {
  cv::Mat image;
  if (channel == "color") {
    scan.color.convertTo(image, CV_32FC3);
  } else {
    scan.intensity.convertTo(image, CV_32F, 255.0);
  }
  return image;
}

// `scan` with the inpainted values written into its hole cells of `channel` (a new buffer; every other cell
// and channel is the scan's own).
Scan WithChannel(const Scan& scan, const std::string& channel, const cv::Mat& image, const cv::Mat& hole) {
  Scan next = scan;
  if (channel == "color") {
    cv::Mat color;
    image.convertTo(color, CV_8UC3);  // rounds and saturates
    next.color = scan.color.clone();
    color.copyTo(next.color, hole);
  } else {
    cv::Mat intensity;
    image.convertTo(intensity, CV_32F, 1.0 / 255.0);
    next.intensity = scan.intensity.clone();
    intensity.copyTo(next.intensity, hole);
  }
  return next;
}

std::vector<int> PixelList(Pixel pixel) { return {pixel.row, pixel.col}; }

// The decisions made so far (as inpaint/review.h DecisionsToJson writes them for `lidarshop inpaint --review`).
std::vector<ReviewDecisionEntry> DecisionEntries(const std::vector<ReviewDecision>& decisions) {
  std::vector<ReviewDecisionEntry> list;
  for (const ReviewDecision& decision : decisions)
    list.push_back({PixelList(decision.target), PixelList(decision.source)});
  return list;
}

// A review point with its candidates' verdicts and their clusters (as inpaint/review.h ReviewToJson).
ReviewDetail ReviewDetailOf(const InpaintReview& review, int patch_radius) {
  ReviewDetail detail{review.review_point, review.iteration, PixelList(review.target), patch_radius, {}, {}};
  for (size_t i = 0; i < review.candidates.size(); ++i) {
    const AcceptanceVerdict verdict = i < review.verdicts.size() ? review.verdicts[i] : AcceptanceVerdict{};
    detail.candidates.push_back({i, PixelList(review.candidates[i].source), review.candidates[i].difference,
                                 review.cluster[i], verdict.accepted, verdict.test, verdict.value,
                                 verdict.threshold, verdict.margin});
  }
  for (size_t c = 0; c < review.cluster_representative.size(); ++c) {
    ReviewClusterEntry cluster{c, review.cluster_representative[c], {}};
    for (size_t i = 0; i < review.cluster.size(); ++i)
      if (review.cluster[i] == static_cast<int>(c)) cluster.members.push_back(i);
    detail.clusters.push_back(std::move(cluster));
  }
  return detail;
}

// The review's display image as 8-bit RGB or grey.
cv::Mat Display(const cv::Mat& image) {
  cv::Mat display;
  image.convertTo(display, image.channels() == 3 ? CV_8UC3 : CV_8U);
  return display;
}

// A job that runs the session to its next review point or its end; at the end the fill becomes an edit.
// Not yet submitted: the caller makes it the review's job while it holds the document's lock.
std::shared_ptr<Job> FillingJob(State& state, const std::shared_ptr<Document>& document,
                                const std::shared_ptr<ReviewSession>& review, Snapshot start) {
  const int undo_depth = state.options.undo_depth;
  auto job = std::make_shared<Job>();
  job->id = state.runner->NextId();
  job->document = document->id;
  job->kind = "review";
  job->run = [document, review, start, undo_depth](Progress& progress) {
    // Whatever ends the job (a review point, the end, an error, a cancel), the session is idle after it;
    // an error or a cancel closes the review.
    auto finish = [&](bool keep) {
      std::lock_guard lock(document->mutex);
      review->job = nullptr;
      if (!keep && document->review == review) document->review = nullptr;
    };
    bool complete = false;
    try {
      progress.Restart("inpaint", 1);
      if (!review->session) {
        review->session = std::make_unique<InpaintSession>(ChannelImage(start.scan, review->channel),
                                                           review->hole, review->options);
      }
      review->session->SetProgress(&progress);
      complete = review->session->Run();
      review->session->SetProgress(nullptr);
    } catch (...) {
      if (review->session) review->session->SetProgress(nullptr);
      finish(false);
      throw;
    }
    if (!complete) {
      const InpaintReview& pending = *review->session->pending_review();
      const ReviewPointReply reply{"review",
                                   pending.review_point,
                                   {pending.target.row, pending.target.col},
                                   pending.candidates.size(),
                                   pending.cluster_representative.size()};
      finish(true);
      return ToJson(reply);
    }
    const InpaintResult result = review->session->Result();
    std::lock_guard lock(document->mutex);
    review->job = nullptr;
    if (document->review != review) return ToJson(ReviewStoppedReply{});  // dropped meanwhile
    document->review = nullptr;
    Snapshot next = document->now;
    next.scan = WithChannel(document->now.scan, review->channel, result.image, review->hole);
    if (review->painted) next.hole = cv::Mat();
    Commit(*document, std::move(next), undo_depth);
    return ToJson(ReviewDoneReply{"done", review->channel, DecisionEntries(review->session->decisions()),
                                  result.Summary(), document->version});
  };
  return job;
}

// Submits the review's job (answers 202), or closes the review and answers 503.
// `job` by value: callers pass review->job, which the worker clears when the job ends — possibly before
// this thread has answered with the job's JSON.
void Submit(State& state, const std::shared_ptr<Document>& document,
            const std::shared_ptr<ReviewSession>& review, std::shared_ptr<Job> job,
            httplib::Response& response) {
  if (state.runner->Submit(job)) return SendJson(response, JobJson(*job), 202);
  std::lock_guard lock(document->mutex);
  review->job = nullptr;
  if (document->review == review) document->review = nullptr;
  SendError(response, 503, "too many operations queued; try again");
}

// Whether a job is filling the review (queued or running). A job cancelled before it ran never cleared its
// mark: that review is over.
bool Filling(const ReviewSession& review) {
  if (!review.job) return false;
  const JobState job = review.job->state;
  return job == JobState::kQueued || job == JobState::kRunning || job == JobState::kDone;
}

// The document's review when it is idle; nullptr after answering 404 (none) or 409 (a job is filling).
std::shared_ptr<ReviewSession> IdleReview(Document& document, httplib::Response& response) {
  if (document.review && !Filling(*document.review)) {
    if (document.review->job) document.review = nullptr;  // its job was cancelled or failed before running
  }
  if (!document.review) {
    SendError(response, 404, "no review in progress: start one (POST .../inpaint/review)");
    return nullptr;
  }
  if (Filling(*document.review)) {
    SendError(response, 409,
              fmt::format("the review is filling (job {}); wait for it to stop", document.review->job->id));
    return nullptr;
  }
  return document.review;
}

void Start(State& state, const std::shared_ptr<Document>& document, const nlohmann::json& body,
           httplib::Response& response) {
  auto review = std::make_shared<ReviewSession>();
  InpaintOptions base = ReviewDefaults();
  review->options = body.contains("options") ? FromJson<InpaintOptions>(body.at("options"), base) : base;
  if (!review->options.review_decisions.empty())
    throw OptionsFieldError("options.review_decisions", "decisions are made here, one review at a time");
  review->options.stop_for_review = true;
  const std::string which = body.value("hole", std::string("painted"));
  if (which != "object" && which != "painted")
    throw OptionsFieldError("hole", "expected \"painted\" or \"object\"");
  const int margin = body.value("margin_cells", 2);
  if (margin < 0 || margin > 100) throw OptionsFieldError("margin_cells", "out of range [0, 100]");
  Snapshot start;
  {
    std::lock_guard lock(document->mutex);
    if (document->review && Filling(*document->review))
      return SendError(response, 409, "a review is filling on this scan; cancel it or wait");
    start = document->now;
    const cv::Mat& mask = which == "painted" ? start.hole : start.object_mask;
    if (mask.empty() || cv::countNonZero(mask) == 0) {
      throw OptionsFieldError("hole", which == "painted" ? "paint a hole first (hole brush or lasso)"
                                                         : "segment an object first");
    }
    review->painted = which == "painted";
    review->hole = review->painted ? (mask != 0) : GrowHole(mask, margin);
    const Scan& scan = start.scan;
    review->channel = body.value("channel", std::string(scan.has_color() ? "color" : "intensity"));
    if (review->channel != "color" && review->channel != "intensity")
      throw OptionsFieldError("channel", "expected \"color\" or \"intensity\"");
    if ((review->channel == "color" && !scan.has_color()) ||
        (review->channel == "intensity" && scan.intensity.empty())) {
      throw OptionsFieldError("channel", fmt::format("the scan has no {} channel", review->channel));
    }
    review->job = FillingJob(state, document, review, start);
    document->review = review;  // replaces an idle one: starting again starts over
  }
  Submit(state, document, review, review->job, response);
}

void Decide(State& state, const std::shared_ptr<Document>& document, const nlohmann::json& body,
            httplib::Response& response) {
  if (body.contains("candidate") == body.contains("source"))
    throw OptionsFieldError("candidate", "give exactly one of \"candidate\": N and \"source\": [row, col]");
  std::shared_ptr<ReviewSession> review;
  std::shared_ptr<Job> job;
  {
    std::lock_guard lock(document->mutex);
    review = IdleReview(*document, response);
    if (!review) return;
    const InpaintReview* pending = review->session->pending_review();
    Pixel source;
    if (body.contains("candidate")) {
      const nlohmann::json& index = body.at("candidate");
      if (!index.is_number_integer() || index.get<int64_t>() < 0 ||
          index.get<int64_t>() >= static_cast<int64_t>(pending->candidates.size())) {
        throw OptionsFieldError("candidate", fmt::format("expected a candidate index in [0, {}), got {}",
                                                         pending->candidates.size(), index.dump()));
      }
      source = pending->candidates[index.get<size_t>()].source;
    } else {
      const nlohmann::json& cell = body.at("source");
      if (!cell.is_array() || cell.size() != 2 || !cell[0].is_number_integer() ||
          !cell[1].is_number_integer())
        throw OptionsFieldError("source",
                                fmt::format("expected [row, col] whole numbers, got {}", cell.dump()));
      source = {cell[0].get<int>(), cell[1].get<int>()};
    }
    try {
      review->session->Decide(source);
    } catch (const InputError& error) {
      // A hand-placed patch that is not wholly known, or outside the scan: the user's mistake, not the file's.
      throw OptionsFieldError("source",
                              fmt::format("({}, {}) is not the centre of a patch wholly outside the "
                                          "hole and inside the scan ({})",
                                          source.row, source.col, error.what()));
    }
    review->job = FillingJob(state, document, review, document->now);
    job = review->job;
  }
  Submit(state, document, review, job, response);
}

}  // namespace

void AddReviewRoutes(State& state) {
  httplib::Server& http = state.http;
  PostDocument(state, R"(/api/docs/(\d+)/inpaint/review)", Start);
  PostDocument(state, R"(/api/docs/(\d+)/inpaint/review/decide)", Decide);
  http.Get(R"(/api/docs/(\d+)/inpaint/review)", [&state](const httplib::Request& request,
                                                         httplib::Response& response) {
    auto document = state.FindDocument(request, response);
    if (!document) return;
    std::lock_guard lock(document->mutex);
    auto review = IdleReview(*document, response);
    if (!review) return;
    const InpaintReview& pending = *review->session->pending_review();
    SendJson(response, ToJson(PendingReviewReply{"review", review->channel, review->hole.rows,
                                                 review->hole.cols, cv::countNonZero(review->hole),
                                                 DecisionEntries(review->session->decisions()),
                                                 ReviewDetailOf(pending, review->options.patch_radius)}));
  });
  // The pixels: the fill so far (`canvas`, candidates are cut from it) or with the best candidate pasted
  // (`tentative`), 8-bit, the ray image's size and orientation.
  http.Get(R"(/api/docs/(\d+)/inpaint/review/image.png)", [&state](const httplib::Request& request,
                                                                   httplib::Response& response) {
    auto document = state.FindDocument(request, response);
    if (!document) return;
    const std::string layer =
        request.has_param("layer") ? request.get_param_value("layer") : std::string("canvas");
    if (layer != "canvas" && layer != "tentative")
      return SendError(response, 400, fmt::format("layer '{}': expected canvas or tentative", layer));
    std::lock_guard lock(document->mutex);
    auto review = IdleReview(*document, response);
    if (!review) return;
    SendPng(response, Display(layer == "tentative" ? review->session->pending_review()->tentative_image
                                                   : review->session->Result().image));
  });
  http.Delete(R"(/api/docs/(\d+)/inpaint/review)",
              [&state](const httplib::Request& request, httplib::Response& response) {
                auto document = state.FindDocument(request, response);
                if (!document) return;
                std::lock_guard lock(document->mutex);
                if (!document->review) return SendError(response, 404, "no review in progress");
                if (document->review->job) document->review->job->progress.Cancel();
                document->review = nullptr;
                SendJson(response, ToJson(ReviewClosedReply{}));
              });
}

}  // namespace lidarshop::server
