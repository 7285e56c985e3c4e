// Routes that edit scans — strokes, segmentation, removal, fill, undo — and the operations they start
// (docs/api.md). Long operations run as jobs off the request thread; clients poll /api/jobs/ID (a long poll
// with ?wait_ms=).
#include <chrono>
#include <cstdlib>
#include <optional>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "http.h"
#include "lidarshop/fill/fill.h"
#include "lidarshop/fill/remove.h"
#include "lidarshop/segment/segment.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "replies.h"
#include "version_param.h"

namespace lidarshop::server {

namespace {

// Cells [[row, col], ...] of `json[key]` painted with `value` as discs of `radius` into `strokes`.
// Returns the box of the cells it painted (empty when none).
cv::Rect PaintCells(const nlohmann::json& json, const char* key, uint8_t value, int radius,
                    cv::Mat& strokes) {
  cv::Rect painted;
  if (!json.contains(key)) return painted;
  const nlohmann::json& cells = json.at(key);
  if (!cells.is_array()) throw OptionsFieldError(key, "expected a list of [row, col] cells");
  if (cells.size() > 1000000) throw OptionsFieldError(key, "more than 1,000,000 cells in one request");
  for (const auto& cell : cells) {
    if (!cell.is_array() || cell.size() != 2 || !cell[0].is_number_integer() ||
        !cell[1].is_number_integer()) {
      throw OptionsFieldError(
          key, fmt::format("expected [row, col] whole numbers, got {}", Excerpt(cell.dump(), 80)));
    }
    const int row = cell[0].get<int>(), col = cell[1].get<int>();
    if (row < 0 || row >= strokes.rows || col < 0 || col >= strokes.cols) {
      throw OptionsFieldError(key, fmt::format("cell [{}, {}] is outside the {} x {} scan", row, col,
                                               strokes.rows, strokes.cols));
    }
    cv::circle(strokes, cv::Point(col, row), radius, cv::Scalar(value), cv::FILLED);
    painted |= cv::Rect(col - radius, row - radius, 2 * radius + 1, 2 * radius + 1) &
               cv::Rect(0, 0, strokes.cols, strokes.rows);
  }
  return painted;
}

// The polygon [[row, col], ...] of `json[key]` (a lasso), filled with 255 into `mask`.
void FillPolygon(const nlohmann::json& json, const char* key, cv::Mat& mask) {
  if (!json.contains(key)) return;
  cv::Mat vertices = NewZeros(mask.size(), CV_8U);
  PaintCells(json, key, 255, 0, vertices);  // checks every vertex
  std::vector<cv::Point> polygon;
  for (const auto& cell : json.at(key)) polygon.emplace_back(cell[1].get<int>(), cell[0].get<int>());
  if (polygon.size() < 3) throw OptionsFieldError(key, "a lasso needs at least 3 cells");
  cv::fillPoly(mask, std::vector<std::vector<cv::Point>>{polygon}, cv::Scalar(255));
}

template <class Options>
Options OptionsOf(const nlohmann::json& body) {
  return body.contains("options") ? FromJson<Options>(body.at("options")) : Options{};
}

void Segment(State& state, const std::shared_ptr<Document>& document, const nlohmann::json& body,
             httplib::Response& response) {
  const SegmentOptions options = OptionsOf<SegmentOptions>(body);
  // refine: add the strokes painted since the last cut to it as hard constraints and re-run its max-flow
  // incrementally (SegmentSession::Refine) — the live update after each stroke. Without a usable session
  // (first cut, other options, the scan edited since) it is a full cut.
  const bool refine = body.value("refine", false);
  const int undo_depth = state.options.undo_depth;
  StartJob(
      state, document, "segment",
      [document, options, refine, undo_depth](Progress& progress) {
        Snapshot start;
        std::shared_ptr<SegmentCut> cut;
        {
          std::lock_guard lock(document->mutex);
          start = document->now;
          cut = document->cut;
        }
        progress.Restart("segment", 1);
        // The session says whether the strokes only add to those of its cut (RefineTo); strokes erased or
        // undone since then need a full cut, and so do other options or a scan edited since.
        const bool same =
            cut && cut->scan_data == start.scan.range.data && ToJson(cut->options) == ToJson(options);
        std::optional<SegmentResult> refined_result;
        if (same && refine && cut->ran)
          refined_result = cut->session.RefineTo(start.strokes, start.strokes_box);
        const bool refined = refined_result.has_value();
        bool prepared = false;
        SegmentResult result;
        if (refined) {
          result = std::move(*refined_result);
        } else {
          // A session built ahead of the first cut (PrepareCut) is used once, as if made here.
          prepared = same && !cut->ran;
          if (!prepared) {
            cut = std::make_shared<SegmentCut>(
                SegmentCut{SegmentSession(start.scan, options), options, start.scan.range.data});
          }
          result = cut->session.Run(start.strokes);
          cut->ran = true;
        }
        progress.Advance();
        std::lock_guard lock(document->mutex);
        document->cut = cut;
        Snapshot next = document->now;
        SetObject(&next, result);
        Commit(*document, std::move(next), undo_depth);
        // prepared: the session was built ahead (PrepareCut)
        return Joined(ToJson(result), ToJson(SegmentReply{refined, prepared, document->version}));
      },
      response);
}

void Remove(State& state, const std::shared_ptr<Document>& document, const nlohmann::json& body,
            httplib::Response& response) {
  const RemoveOptions options = OptionsOf<RemoveOptions>(body);
  const int undo_depth = state.options.undo_depth;
  StartJob(
      state, document, "remove",
      [document, options, undo_depth](Progress& progress) {
        Snapshot start;
        {
          std::lock_guard lock(document->mutex);
          start = document->now;
        }
        const RemoveResult result = RemoveObject(start.scan, start.strokes, options, &progress);
        std::lock_guard lock(document->mutex);
        Snapshot next = document->now;
        if (options.keep_object) {  // fill shadow: the object stays, the surface behind it is a second layer
          next.behind = result.behind;
          SetObject(&next, result.cut);  // the removal's own cut: nothing else holds its mask
        } else {
          next.scan = result.fill.scan;
          next.object_mask = cv::Mat();
          next.behind = Scan();
        }
        ClearStrokes(&next);  // a new buffer: see Snapshot
        Commit(*document, std::move(next), undo_depth);
        return Joined(ToJson(result), ToJson(VersionReply{document->version}));
      },
      response);
}

// Fills the last segmentation's object grown by margin_cells (the object removed without a new cut).
void Fill(State& state, const std::shared_ptr<Document>& document, const nlohmann::json& body,
          httplib::Response& response) {
  const FillOptions options = OptionsOf<FillOptions>(body);
  const int margin = body.value("margin_cells", 2);
  if (margin < 0 || margin > 100) throw OptionsFieldError("margin_cells", "out of range [0, 100]");
  const std::string which = body.value("hole", std::string("object"));
  if (which != "object" && which != "painted")
    throw OptionsFieldError("hole", "expected \"object\" or \"painted\"");
  const bool painted = which == "painted";
  {
    std::lock_guard lock(document->mutex);
    const cv::Mat& mask = painted ? document->now.hole : document->now.object_mask;
    if (mask.empty() || (painted ? cv::countNonZero(mask) : document->now.object_cells) == 0) {
      throw OptionsFieldError("hole", painted ? "paint a hole first (hole brush or lasso)"
                                              : "segment an object first: the fill fills the object's cells");
    }
  }
  const int undo_depth = state.options.undo_depth;
  StartJob(
      state, document, "fill",
      [document, options, margin, painted, undo_depth](Progress& progress) {
        Snapshot start;
        {
          std::lock_guard lock(document->mutex);
          start = document->now;
        }
        const cv::Mat hole = painted ? start.hole : GrowHole(start.object_mask, margin, start.object_box);
        // The fill's window pasted into the scan, sharing with the history every channel it leaves as it was
        // (the ray directions): no whole copy of the station, nor its per-cell images padded to it.
        const FillResult result = FillScanWindow(start.scan, hole, options, &progress);
        Scan filled = start.scan;
        if (result.Window().area() > 0) PasteScanCopyOnWrite(result.scan, result.Window(), &filled);
        std::lock_guard lock(document->mutex);
        Snapshot next = document->now;
        next.scan = std::move(filled);
        (painted ? next.hole : next.object_mask) = cv::Mat();
        Commit(*document, std::move(next), undo_depth);
        return Joined(ToJson(result), ToJson(VersionReply{document->version}));
      },
      response);
}

}  // namespace

void Commit(Document& document, Snapshot next, int undo_depth) {
  // Checked before anything changes: a refused edit leaves the document as it was. Counted with the current
  // state kept for undo and nothing trimmed, so that the check errs on the safe side.
  if (document.check_room) document.check_room(document, DocumentBytesWith(document, next));
  document.undo.push_back(std::move(document.now));
  if (static_cast<int>(document.undo.size()) > undo_depth) document.undo.erase(document.undo.begin());
  document.redo.clear();
  document.now = std::move(next);
  ++document.version;
  RememberState(document);
}

// The longest a GET of a job waits for its end (a request thread is held meanwhile).
constexpr long kMaxJobWaitMs = 2000;

nlohmann::ordered_json JobJson(const Job& job) {
  JobReply reply{job.id,
                 job.kind,
                 job.document,
                 job.state.load(),
                 job.progress.label(),
                 job.progress.done(),
                 job.progress.total(),
                 std::nullopt,
                 std::nullopt};
  std::lock_guard lock(const_cast<std::mutex&>(job.mutex));
  if (!job.error.empty()) reply.error = job.error;
  if (!job.result.is_null()) reply.result = job.result;
  return ToJson(reply);
}

std::shared_ptr<Job> SubmitJob(State& state, const std::shared_ptr<Document>& document,
                               const std::string& kind,
                               std::function<nlohmann::ordered_json(Progress&)> run) {
  auto job = std::make_shared<Job>();
  job->id = state.runner->NextId();
  job->document = document->id;
  job->kind = kind;
  job->run = std::move(run);
  return state.runner->Submit(job) ? job : nullptr;
}

std::shared_ptr<Job> StartJob(State& state, const std::shared_ptr<Document>& document,
                              const std::string& kind, std::function<nlohmann::ordered_json(Progress&)> run,
                              httplib::Response& response) {
  std::shared_ptr<Job> job = SubmitJob(state, document, kind, std::move(run));
  if (!job) {
    SendError(response, 503, "too many operations queued; try again");
    return nullptr;
  }
  SendJson(response, JobJson(*job), 202);
  return job;
}

// Wraps a document route: finds the document, parses the body, answers 400 for option errors.
void PostDocument(State& state, const std::string& pattern, DocumentHandler handler) {
  state.http.Post(pattern, [&state, handler](const httplib::Request& request, httplib::Response& response) {
    auto document = state.FindDocument(request, response);
    if (!document) return;
    const auto body = BodyJson(request, response);
    if (!body) return;
    try {
      handler(state, document, *body, response);
    } catch (const OptionsError& error) {
      SendError(response, 400, error.what());
    } catch (const DocumentLimitError& error) {  // the edit would pass the memory limit: 507
      SendError(response, error.status, error.what());
    } catch (const InputError& error) {
      SendError(response, 422, error.what());
    } catch (const nlohmann::json::exception& error) {  // a field of the wrong type (body.value)
      SendError(response, 400, fmt::format("a field of the request has the wrong type: {}", error.what()));
    }
  });
}

// The first cut's session built in the background once the first stroke is painted (the strokes route, with
// the document's mutex held), so that the cut a stroke later finds it ready: at 100 M rays building it (the
// level of every 4th ray, the statistics) took 0.60 s of the first cut's 0.91 (editor.md). Built with the default options
// (a cut with others builds its own); not built while a usable one exists. A full queue: the cut builds it.
void PrepareCut(State& state, const std::shared_ptr<Document>& document) {
  const Snapshot& now = document->now;
  if (document->preparing_cut || (document->cut && document->cut->scan_data == now.scan.range.data)) return;
  const auto build = [document](Progress&) {
    Scan scan;
    {
      std::lock_guard lock(document->mutex);
      scan = document->now.scan;
    }
    std::shared_ptr<SegmentCut> cut;
    try {
      cut = std::make_shared<SegmentCut>(
          SegmentCut{SegmentSession(scan, SegmentOptions{}), SegmentOptions{}, scan.range.data});
    } catch (...) {  // a scan the cut refuses: the cut itself will say why
      std::lock_guard lock(document->mutex);
      document->preparing_cut = false;
      throw;
    }
    std::lock_guard lock(document->mutex);
    document->preparing_cut = false;
    if (!document->cut || document->cut->scan_data != scan.range.data) document->cut = cut;
    return ToJson(PreparedReply{document->cut == cut});
  };
  document->preparing_cut = SubmitJob(state, document, "prepare segment", build) != nullptr;
}

void AddEditRoutes(State& state) {
  PostDocument(
      state, R"(/api/docs/(\d+)/strokes)",
      [](State& state, const std::shared_ptr<Document>& document, const nlohmann::json& body,
         httplib::Response& response) {
        const int radius = body.value("radius", 2);
        if (radius < 0 || radius > 200) throw OptionsFieldError("radius", "out of range [0, 200]");
        std::lock_guard lock(document->mutex);
        Snapshot next = document->now;
        // New buffers for what this edit paints (Snapshot: the history shares the current ones); the counts
        // change only in the box painted.
        const bool clear = body.value("clear", false);
        if (clear)
          ClearStrokes(&next);
        else
          next.strokes = CopyOfBox(next.strokes, next.strokes_box);
        cv::Rect painted = PaintCells(body, "object", 1, radius, next.strokes);  // segment.h kStrokeObject
        painted |= PaintCells(body, "background", 2, radius, next.strokes);
        painted |= PaintCells(body, "erase", 0, radius, next.strokes);
        next.strokes_box |= painted;
        if (!painted.empty()) {
          const StrokeCounts now = CountStrokes(next.strokes(painted));
          const StrokeCounts was = clear ? StrokeCounts() : CountStrokes(document->now.strokes(painted));
          next.object_stroke_cells += now.object - was.object;
          next.background_stroke_cells += now.background - was.background;
        }
        if (body.contains("hole") || body.contains("hole_polygon") || body.contains("erase_hole")) {
          next.hole = next.hole.empty() ? NewZeros(next.strokes.size(), CV_8U) : CopyOfMostlyZero(next.hole);
          PaintCells(body, "hole", 255, radius, next.hole);
          PaintCells(body, "erase_hole", 0, radius, next.hole);
          FillPolygon(body, "hole_polygon", next.hole);
        }
        Commit(*document, std::move(next), state.options.undo_depth);
        if (document->now.object_stroke_cells + document->now.background_stroke_cells > 0)
          PrepareCut(state, document);
        SendJson(response,
                 ToJson(StrokesReply{
                     document->version, document->now.hole.empty() ? 0 : cv::countNonZero(document->now.hole),
                     document->now.object_stroke_cells, document->now.background_stroke_cells}));
      });
  PostDocument(state, R"(/api/docs/(\d+)/segment)", Segment);
  PostDocument(state, R"(/api/docs/(\d+)/remove)", Remove);
  PostDocument(state, R"(/api/docs/(\d+)/fill)", Fill);
  for (const bool undo : {true, false}) {
    PostDocument(state, undo ? R"(/api/docs/(\d+)/undo)" : R"(/api/docs/(\d+)/redo)",
                 [undo](State&, const std::shared_ptr<Document>& document, const nlohmann::json&,
                        httplib::Response& response) {
                   std::lock_guard lock(document->mutex);
                   auto& from = undo ? document->undo : document->redo;
                   auto& to = undo ? document->redo : document->undo;
                   if (from.empty()) {
                     SendError(response, 409, undo ? "nothing to undo" : "nothing to redo");
                     return;
                   }
                   to.push_back(std::move(document->now));
                   document->now = std::move(from.back());
                   from.pop_back();
                   ++document->version;
                   RememberState(*document);
                   SendJson(response, ToJson(VersionReply{document->version}));
                 });
  }
  state.http.Get(R"(/api/jobs/(\d+))", [&state](const httplib::Request& request,
                                                httplib::Response& response) {
    const auto job = state.runner->Find(std::atoi(request.matches[1].str().c_str()));
    if (!job) return SendError(response, 404, "no such job");
    // ?wait_ms=N: answer when the job ends, or after N ms (a long poll: the client hears of
    // the end when it comes instead of at its next poll).
    int64_t wait_ms = 0;
    const std::string expected = fmt::format("a whole number of ms from 0 to {}", kMaxJobWaitMs);
    if (!ReadWholeNumberParam(request, response, "wait_ms", 0, kMaxJobWaitMs, expected.c_str(), &wait_ms)) {
      return;
    }
    if (wait_ms > 0) job->WaitEnded(std::chrono::milliseconds(wait_ms));
    SendJson(response, JobJson(*job));
  });
  state.http.Post(R"(/api/jobs/(\d+)/cancel)",
                  [&state](const httplib::Request& request, httplib::Response& response) {
                    const auto job = state.runner->Find(std::atoi(request.matches[1].str().c_str()));
                    if (!job) return SendError(response, 404, "no such job");
                    job->progress.Cancel();
                    SendJson(response, JobJson(*job));
                  });
}

}  // namespace lidarshop::server
