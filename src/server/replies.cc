// Descriptions of the server's replies (replies.h; util/options.h).
#include "replies.h"

#include <fmt/format.h>

#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "state.h"

namespace lidarshop::server {

nlohmann::ordered_json Joined(nlohmann::ordered_json json, const nlohmann::ordered_json& extra) {
  for (const auto& [key, value] : extra.items()) {
    LIDARSHOP_CHECK(!json.contains(key));  // a key twice in one reply
    json[key] = value;
  }
  return json;
}

}  // namespace lidarshop::server

namespace lidarshop {

using namespace server;  // NOLINT: the descriptions name the replies and their members

template <>
const EnumInfo& EnumInfoOf<JobState>() {
  static const EnumInfo info = MakeEnumInfo<JobState>(
      "job state", {{JobState::kQueued, "queued", "waiting for the worker"},
                    {JobState::kRunning, "running", "running"},
                    {JobState::kDone, "done", "ended with a result"},
                    {JobState::kFailed, "failed", "ended with an error"},
                    {JobState::kCancelled, "cancelled", "stopped at a progress step after a cancel"}});
  return info;
}

template <>
const StructInfo& InfoOf<ErrorReply>() {
  static const StructInfo info = [] {
    StructBuilder<ErrorReply> b("ErrorReply", "a refused request (any 4xx or 5xx)");
    b.Field(&ErrorReply::error, "error", "why, one line");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<HealthReply>() {
  static const StructInfo info = [] {
    StructBuilder<HealthReply> b("HealthReply", "GET /api/health");
    b.Field(&HealthReply::ok, "ok", "the server answers");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ScenesReply>() {
  static const StructInfo info = [] {
    StructBuilder<ScenesReply> b("ScenesReply", "GET /api/scenes");
    b.Field(&ScenesReply::scenes, "scenes", "the built-in scenes /api/open?scene= opens");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ClosedReply>() {
  static const StructInfo info = [] {
    StructBuilder<ClosedReply> b("ClosedReply", "DELETE /api/docs/ID");
    b.Field(&ClosedReply::closed, "closed", "the id of the scan closed");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<SavePlanReply>() {
  static const StructInfo info = [] {
    StructBuilder<SavePlanReply> b("SavePlanReply",
                                   "GET /api/docs/ID/save-plan: what a save in a format keeps");
    b.Field(&SavePlanReply::format, "format", "the format's extension");
    b.Field(&SavePlanReply::channels, "channels", "the channels written, in the format's words");
    b.Field(&SavePlanReply::dropped, "dropped", "what the format does not keep, one sentence each");
    b.Field(&SavePlanReply::refused, "refused",
            "why a save in that format would fail (empty when it would not)");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<VersionReply>() {
  static const StructInfo info = [] {
    StructBuilder<VersionReply> b("VersionReply",
                                  "the document's version after an edit (undo, redo; beside RemoveResult and "
                                  "FillResult)");
    b.Field(&VersionReply::version, "version", "the document's version");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<StrokesReply>() {
  static const StructInfo info = [] {
    StructBuilder<StrokesReply> b("StrokesReply", "POST /api/docs/ID/strokes");
    b.Field(&StrokesReply::version, "version", "the document's version");
    b.Field(&StrokesReply::hole_cells, "hole_cells", "cells of the painted hole").Unit("cells");
    b.Field(&StrokesReply::object_stroke_cells, "object_stroke_cells", "cells painted as object")
        .Unit("cells");
    b.Field(&StrokesReply::background_stroke_cells, "background_stroke_cells", "cells painted as background")
        .Unit("cells");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<SegmentReply>() {
  static const StructInfo info = [] {
    StructBuilder<SegmentReply> b("SegmentReply",
                                  "beside a segment job's SegmentResult: how the cut was made");
    b.Field(&SegmentReply::refined, "refined", "the strokes were added to the last cut (incremental)");
    b.Field(&SegmentReply::prepared, "prepared", "the cut used the session a `prepare segment` job built");
    b.Field(&SegmentReply::version, "version", "the document's version");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<PreparedReply>() {
  static const StructInfo info = [] {
    StructBuilder<PreparedReply> b("PreparedReply", "the result of a `prepare segment` job");
    b.Field(&PreparedReply::prepared, "prepared", "the session built is the one the next cut uses");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<JobReply>() {
  static const StructInfo info = [] {
    StructBuilder<JobReply> b("JobReply",
                              "GET /api/jobs/ID: a job and, once it has one, the operation's reply");
    b.Field(&JobReply::id, "id", "the job's id");
    b.Field(&JobReply::kind, "kind", "the operation (\"segment\", \"remove\", \"fill\", ...)");
    b.Field(&JobReply::document, "document", "the id of its scan");
    b.Field(&JobReply::state, "state", "where it is");
    b.Field(&JobReply::label, "label", "the step it is at");
    b.Field(&JobReply::done, "done", "steps done");
    b.Field(&JobReply::total, "total", "steps in all");
    b.Field(&JobReply::error, "error", "why it failed");
    b.Field(&JobReply::result, "result",
            "the operation's own reply, once it has one (its type follows the kind)");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<PhotoReply>() {
  static const StructInfo info = [] {
    StructBuilder<PhotoReply> b("PhotoReply",
                                "POST /api/docs/ID/photo and .../photo-from-e57: the photo taken");
    b.Field(&PhotoReply::width_px, "width_px", "its width").Unit("px");
    b.Field(&PhotoReply::height_px, "height_px", "its height").Unit("px");
    b.Field(&PhotoReply::name, "name", "the E57 photo's name (photo-from-e57)");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<RecolorReply>() {
  static const StructInfo info = [] {
    StructBuilder<RecolorReply> b("RecolorReply",
                                  "the result of a recolor job: the resection from the pairs, then the "
                                  "recolouring");
    b.Field(&RecolorReply::inliers, "inliers", "pairs the camera fits");
    b.Field(&RecolorReply::pairs, "pairs", "pairs given");
    b.Field(&RecolorReply::rms_px, "rms_px", "RMS reprojection error of the inliers").Unit("px");
    b.Field(&RecolorReply::reprojection_error_px, "reprojection_error_px", "per pair").Unit("px");
    b.Field(&RecolorReply::inlier, "inlier", "per pair: 1 = inlier");
    b.Field(&RecolorReply::recolored_count, "recolored_count", "valid cells that took the photo's colour")
        .Unit("cells");
    b.Field(&RecolorReply::hidden, "hidden", "inside the photo but occluded").Unit("cells");
    b.Field(&RecolorReply::uncertain, "uncertain", "too near an occluding edge to trust: kept").Unit("cells");
    b.Field(&RecolorReply::outside_image, "outside_image", "behind the camera or outside the photo")
        .Unit("cells");
    b.Field(&RecolorReply::summary, "summary", "the resection's and the recolouring's summaries");
    b.Field(&RecolorReply::warnings, "warnings", "the resection's then the recolouring's, one sentence each");
    b.Field(&RecolorReply::version, "version", "the document's version");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<AlignReply>() {
  static const StructInfo info = [] {
    StructBuilder<AlignReply> b("AlignReply", "beside a LandmarkAlignment (POST /api/docs/ID/align)");
    b.Field(&AlignReply::target_from_source_column_major, "target_from_source_column_major",
            "the transform fitted, 16 numbers column-major");
    b.Field(&AlignReply::applied, "applied",
            "the scan's pose became target_from_source · world_from_scanner");
    b.Field(&AlignReply::version, "version", "the document's version");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<PhotoMatchReply>() {
  static const StructInfo info = [] {
    StructBuilder<PhotoMatchReply> b("PhotoMatchReply",
                                     "beside a PhotoPairModel (POST /api/docs/ID/photo-match)");
    b.Field(&PhotoMatchReply::matrix_row_major, "matrix_row_major",
            "H (b = H a) or F (b^T F a = 0), 9 numbers by rows, pixel coordinates");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ReviewPointReply>() {
  static const StructInfo info = [] {
    StructBuilder<ReviewPointReply> b("ReviewPointReply",
                                      "the result of a review job stopped at a review point");
    b.Field(&ReviewPointReply::state, "state", "\"review\"");
    b.Field(&ReviewPointReply::review_point, "review_point", "review points before this one");
    b.Field(&ReviewPointReply::target, "target", "the failing target patch's centre [row, col]");
    b.Field(&ReviewPointReply::candidates, "candidates", "candidates listed");
    b.Field(&ReviewPointReply::clusters, "clusters", "clusters of near-identical candidates");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ReviewStoppedReply>() {
  static const StructInfo info = [] {
    StructBuilder<ReviewStoppedReply> b("ReviewStoppedReply",
                                        "the result of a review job whose review was dropped while it ran");
    b.Field(&ReviewStoppedReply::state, "state", "\"stopped\"");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ReviewClosedReply>() {
  static const StructInfo info = [] {
    StructBuilder<ReviewClosedReply> b("ReviewClosedReply", "DELETE /api/docs/ID/inpaint/review");
    b.Field(&ReviewClosedReply::closed, "closed", "the review was dropped");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<RemovedReply>() {
  static const StructInfo info = [] {
    StructBuilder<RemovedReply> b("RemovedReply",
                                  "GET /api/docs/ID/removed: the cells the last clean removed");
    b.Field(&RemovedReply::version, "version", "the document's version");
    b.Field(&RemovedReply::cells, "cells", "row * cols + col of each (empty once the clean is undone)");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ModelsReply>() {
  static const StructInfo info = [] {
    StructBuilder<ModelsReply> b("ModelsReply", "GET /api/models");
    b.Field(&ModelsReply::builtin, "builtin", "the built-in models");
    b.Field(&ModelsReply::files, "files", "OBJ and PLY files under the roots");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ModelReply>() {
  static const StructInfo info = [] {
    StructBuilder<ModelReply> b("ModelReply", "POST /api/models: a model prepared for verification");
    b.Field(&ModelReply::id, "id", "the model's id");
    b.Field(&ModelReply::name, "name", "the built-in model or the file");
    b.Field(&ModelReply::vertices, "vertices", "its mesh's vertices");
    b.Field(&ModelReply::triangles, "triangles", "its mesh's triangles");
    b.Field(&ModelReply::size_m, "size_m", "its box's size [x, y, z]").Unit("m");
    b.Field(&ModelReply::warnings, "warnings", "what the mesh reader left out, one sentence each");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<VerifyReply>() {
  static const StructInfo info = [] {
    StructBuilder<VerifyReply> b("VerifyReply", "beside a VerifyResult (POST /api/docs/ID/verify)");
    b.Field(&VerifyReply::summary, "summary", "the result in one line");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<FileEntry>() {
  static const StructInfo info = [] {
    StructBuilder<FileEntry> b("FileEntry", "a scan file under the roots (GET /api/files)");
    b.Field(&FileEntry::path, "path", "the file");
    b.Field(&FileEntry::bytes, "bytes", "its size").Unit("bytes");
    b.Field(&FileEntry::readable, "readable", "its header reads");
    b.Field(&FileEntry::error, "error", "why it does not");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<FilesReply>() {
  static const StructInfo info = [] {
    StructBuilder<FilesReply> b(
        "FilesReply", "GET /api/files: scan files under the roots, two folders deep, in name order");
    b.Field(&FilesReply::roots, "roots", "the folders served");
    b.Field(&FilesReply::files, "files", "the scan files");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<E57ImageEntry>() {
  static const StructInfo info = [] {
    StructBuilder<E57ImageEntry> b("E57ImageEntry",
                                   "a photo (images2D) of the E57 file a scan was opened from");
    b.Field(&E57ImageEntry::index, "index", "its index in the file's scan");
    b.Field(&E57ImageEntry::name, "name", "its name");
    b.Field(&E57ImageEntry::width_px, "width_px", "its width").Unit("px");
    b.Field(&E57ImageEntry::height_px, "height_px", "its height").Unit("px");
    b.Field(&E57ImageEntry::usable, "usable", "decoded: the recolour tool can take it");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<DocumentReply>() {
  static const StructInfo info = [] {
    StructBuilder<DocumentReply> b("DocumentReply", "GET /api/docs/ID: an open scan");
    b.Field(&DocumentReply::id, "id", "the document's id");
    b.Field(&DocumentReply::name, "name", "its name");
    b.Field(&DocumentReply::rows, "rows", "grid rows");
    b.Field(&DocumentReply::cols, "cols", "grid columns");
    b.Field(&DocumentReply::channels, "channels", "the channels it has");
    b.Field(&DocumentReply::valid_cells, "valid_cells", "cells with a return").Unit("cells");
    b.Field(&DocumentReply::synthesized_cells, "synthesized_cells", "synthesized cells").Unit("cells");
    b.Field(&DocumentReply::object_cells, "object_cells", "cells of the last cut's object").Unit("cells");
    b.Field(&DocumentReply::hole_cells, "hole_cells", "cells of the painted hole").Unit("cells");
    b.Field(&DocumentReply::object_stroke_cells, "object_stroke_cells", "cells painted as object")
        .Unit("cells");
    b.Field(&DocumentReply::background_stroke_cells, "background_stroke_cells", "cells painted as background")
        .Unit("cells");
    b.Field(&DocumentReply::behind_cells, "behind_cells", "cells of the layer behind a kept object")
        .Unit("cells");
    b.Field(&DocumentReply::world_from_scanner_column_major, "world_from_scanner_column_major",
            "the scanner's pose, 16 numbers column-major");
    b.Field(&DocumentReply::azimuth_step_deg, "azimuth_step_deg",
            "the grid's azimuth step (0 without a grid)")
        .Unit("deg");
    b.Field(&DocumentReply::elevation_step_deg, "elevation_step_deg",
            "the grid's elevation step (0 without a grid)")
        .Unit("deg");
    b.Field(&DocumentReply::version, "version", "the document's version");
    b.Field(&DocumentReply::can_undo, "can_undo", "an edit to undo");
    b.Field(&DocumentReply::can_redo, "can_redo", "an edit to redo");
    b.Field(&DocumentReply::e57_images, "e57_images", "the photos of its E57 file");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<WarningsReply>() {
  static const StructInfo info = [] {
    StructBuilder<WarningsReply> b("WarningsReply",
                                   "beside a reply from a file: what the reader left out of it");
    b.Field(&WarningsReply::warnings, "warnings", "one sentence each");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<DocumentsReply>() {
  static const StructInfo info = [] {
    StructBuilder<DocumentsReply> b("DocumentsReply", "GET /api/docs");
    b.Field(&DocumentsReply::documents, "documents", "the open scans");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<LabelEntry>() {
  static const StructInfo info = [] {
    StructBuilder<LabelEntry> b("LabelEntry", "an object label of a labelled scan");
    b.Field(&LabelEntry::label, "label", "the label");
    b.Field(&LabelEntry::cells, "cells", "its cells").Unit("cells");
    b.Field(&LabelEntry::box, "box", "[row0, col0, row1, col1]");
    b.Field(&LabelEntry::center, "center", "[row, col]");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<LabelsReply>() {
  static const StructInfo info = [] {
    StructBuilder<LabelsReply> b("LabelsReply", "GET /api/docs/ID/labels");
    b.Field(&LabelsReply::labels, "labels", "one per label");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<FormatsReply>() {
  static const StructInfo info = [] {
    StructBuilder<FormatsReply> b("FormatsReply", "GET /api/formats");
    b.Field(&FormatsReply::read, "read", "the extensions the library reads");
    b.Field(&FormatsReply::write, "write", "the extensions it writes");
    b.Field(&FormatsReply::formats, "formats", "the library's table of formats, what each holds");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<TileLevelEntry>() {
  static const StructInfo info = [] {
    StructBuilder<TileLevelEntry> b("TileLevelEntry", "one level of the tile pyramid");
    b.Field(&TileLevelEntry::level, "level", "0 = one pixel per ray, each level halving");
    b.Field(&TileLevelEntry::rows, "rows", "pixel rows").Unit("px");
    b.Field(&TileLevelEntry::cols, "cols", "pixel columns").Unit("px");
    b.Field(&TileLevelEntry::tiles_x, "tiles_x", "tiles across");
    b.Field(&TileLevelEntry::tiles_y, "tiles_y", "tiles down");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<TilesReply>() {
  static const StructInfo info = [] {
    StructBuilder<TilesReply> b("TilesReply", "GET /api/docs/ID/tiles.json");
    b.Field(&TilesReply::version, "version", "the document's version");
    b.Field(&TilesReply::rows, "rows", "level-0 rows").Unit("px");
    b.Field(&TilesReply::cols, "cols", "level-0 columns").Unit("px");
    b.Field(&TilesReply::tile_px, "tile_px", "a tile's side").Unit("px");
    b.Field(&TilesReply::levels, "levels", "the pyramid's levels");
    b.Field(&TilesReply::changed, "changed",
            "[col, row, width, height] of the level-0 pixels changed since `since` (0 0 0 0: none)");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<StationPhotoEntry>() {
  static const StructInfo info = [] {
    StructBuilder<StationPhotoEntry> b("StationPhotoEntry",
                                       "an E57 photo a station recolouring used or skipped");
    b.Field(&StationPhotoEntry::index, "index", "its images2D index");
    b.Field(&StationPhotoEntry::name, "name", "its name");
    b.Field(&StationPhotoEntry::why, "why", "skipped: why");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<RecolorStationReply>() {
  static const StructInfo info = [] {
    StructBuilder<RecolorStationReply> b("RecolorStationReply", "the result of a recolor-station job");
    b.Field(&RecolorStationReply::returns, "returns", "valid cells").Unit("cells");
    b.Field(&RecolorStationReply::coloured, "coloured", "valid cells some photo saw").Unit("cells");
    b.Field(&RecolorStationReply::constraints, "constraints", "overlap pairs used to fit the gains");
    b.Field(&RecolorStationReply::used, "used", "the photos used");
    b.Field(&RecolorStationReply::skipped, "skipped", "the photos skipped");
    b.Field(&RecolorStationReply::summary, "summary", "the result in one line");
    b.Field(&RecolorStationReply::version, "version", "the document's version");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ReviewDecisionEntry>() {
  static const StructInfo info = [] {
    StructBuilder<ReviewDecisionEntry> b("ReviewDecisionEntry", "a decision of the patch review");
    b.Field(&ReviewDecisionEntry::target, "target", "the target patch's centre [row, col]");
    b.Field(&ReviewDecisionEntry::source, "source", "the source patch's centre [row, col]");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ReviewCandidateEntry>() {
  static const StructInfo info = [] {
    StructBuilder<ReviewCandidateEntry> b("ReviewCandidateEntry",
                                          "a candidate source patch of a review point");
    b.Field(&ReviewCandidateEntry::index, "index", "its rank, best first");
    b.Field(&ReviewCandidateEntry::source, "source", "its centre [row, col]");
    b.Field(&ReviewCandidateEntry::difference, "difference", "its patch difference");
    b.Field(&ReviewCandidateEntry::cluster, "cluster", "its cluster");
    b.Field(&ReviewCandidateEntry::accepted, "accepted", "the acceptance tests pass it");
    b.Field(&ReviewCandidateEntry::test, "test", "the test that decided");
    b.Field(&ReviewCandidateEntry::value, "value", "the test's value");
    b.Field(&ReviewCandidateEntry::threshold, "threshold", "the test's threshold");
    b.Field(&ReviewCandidateEntry::margin, "margin", "the test's margin");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ReviewClusterEntry>() {
  static const StructInfo info = [] {
    StructBuilder<ReviewClusterEntry> b("ReviewClusterEntry", "a cluster of near-identical candidates");
    b.Field(&ReviewClusterEntry::index, "index", "the cluster");
    b.Field(&ReviewClusterEntry::representative, "representative", "its best candidate");
    b.Field(&ReviewClusterEntry::members, "members", "its candidates");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ReviewDetail>() {
  static const StructInfo info = [] {
    StructBuilder<ReviewDetail> b("ReviewDetail", "a review point (inpaint/review.h InpaintReview)");
    b.Field(&ReviewDetail::review_point, "review_point", "review points before this one");
    b.Field(&ReviewDetail::iteration, "iteration", "the fill iteration it stopped at");
    b.Field(&ReviewDetail::target, "target", "the failing target patch's centre [row, col]");
    b.Field(&ReviewDetail::patch_radius, "patch_radius", "patch half-width").Unit("cells");
    b.Field(&ReviewDetail::candidates, "candidates", "best first");
    b.Field(&ReviewDetail::clusters, "clusters", "clusters of near-identical candidates");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<PendingReviewReply>() {
  static const StructInfo info = [] {
    StructBuilder<PendingReviewReply> b("PendingReviewReply",
                                        "GET /api/docs/ID/inpaint/review: the pending review");
    b.Field(&PendingReviewReply::state, "state", "\"review\"");
    b.Field(&PendingReviewReply::channel, "channel", "the channel reviewed (color or intensity)");
    b.Field(&PendingReviewReply::rows, "rows", "its rows");
    b.Field(&PendingReviewReply::cols, "cols", "its columns");
    b.Field(&PendingReviewReply::hole_cells, "hole_cells", "cells of the hole").Unit("cells");
    b.Field(&PendingReviewReply::decisions, "decisions", "the decisions so far");
    b.Field(&PendingReviewReply::review, "review", "the review point");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ReviewDoneReply>() {
  static const StructInfo info = [] {
    StructBuilder<ReviewDoneReply> b("ReviewDoneReply",
                                     "the result of a review job at its end: the fill as one edit");
    b.Field(&ReviewDoneReply::state, "state", "\"done\"");
    b.Field(&ReviewDoneReply::channel, "channel", "the channel filled");
    b.Field(&ReviewDoneReply::decisions, "decisions", "the decisions made");
    b.Field(&ReviewDoneReply::summary, "summary", "the fill in one line");
    b.Field(&ReviewDoneReply::version, "version", "the document's version");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<StationEntry>() {
  static const StructInfo info = [] {
    StructBuilder<StationEntry> b("StationEntry",
                                  "a station of a site (site/site_stations.h) with its document");
    b.Field(&StationEntry::index, "index", "its index in the site");
    b.Field(&StationEntry::name, "name", "the scan's name");
    b.Field(&StationEntry::position_m, "position_m", "the scanner's origin [x, y, z], world").Unit("m");
    b.Field(&StationEntry::heading_deg, "heading_deg", "+y turned about the world z").Unit("deg");
    b.Field(&StationEntry::world_from_scanner_column_major, "world_from_scanner_column_major",
            "its pose, 16 numbers column-major");
    b.Field(&StationEntry::rows, "rows", "grid rows");
    b.Field(&StationEntry::cols, "cols", "grid columns");
    b.Field(&StationEntry::returns, "returns", "valid cells").Unit("cells");
    b.Field(&StationEntry::organized, "organized", "it has a grid");
    b.Field(&StationEntry::document, "document", "its document's id");
    b.Field(&StationEntry::open, "open", "its document is open");
    b.Field(&StationEntry::current, "current", "the station of the document asked about");
    b.Field(&StationEntry::version, "version", "its document's version (open)");
    b.Field(&StationEntry::removed_cells, "removed_cells", "cells the last clean removed (open)")
        .Unit("cells");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<SiteReply>() {
  static const StructInfo info = [] {
    StructBuilder<SiteReply> b("SiteReply", "a site: GET /api/docs/ID/stations, GET /api/sites");
    b.Field(&SiteReply::site, "site", "the site's id; null for a scan in none").NullWhenAbsent();
    b.Field(&SiteReply::name, "name", "its name");
    b.Field(&SiteReply::station, "station", "the document's station (-1: none)");
    b.Field(&SiteReply::stations, "stations", "its stations");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<SitesReply>() {
  static const StructInfo info = [] {
    StructBuilder<SitesReply> b("SitesReply", "GET /api/sites");
    b.Field(&SitesReply::sites, "sites", "the sites");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<OpenedSiteReply>() {
  static const StructInfo info = [] {
    StructBuilder<OpenedSiteReply> b("OpenedSiteReply", "beside the site POST /api/sites opened");
    b.Field(&OpenedSiteReply::document, "document", "the document of the station to show");
    b.Field(&OpenedSiteReply::warnings, "warnings", "what the reader left out of the file");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<CleanStationEntry>() {
  static const StructInfo info = [] {
    StructBuilder<CleanStationEntry> b("CleanStationEntry", "a station of a clean");
    b.Field(&CleanStationEntry::station, "station", "its index");
    b.Field(&CleanStationEntry::document, "document", "its document");
    b.Field(&CleanStationEntry::removed, "removed", "cells removed").Unit("cells");
    b.Field(&CleanStationEntry::seen_through, "seen_through", "cells with free-space evidence").Unit("cells");
    b.Field(&CleanStationEntry::confirmed, "confirmed", "cells confirmed").Unit("cells");
    b.Field(&CleanStationEntry::filled, "filled", "cells the fill gave a return").Unit("cells");
    b.Field(&CleanStationEntry::changed, "changed", "its points changed (an undoable edit)");
    b.Field(&CleanStationEntry::why, "why", "why not");
    b.Field(&CleanStationEntry::version, "version", "its document's version");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<CleanReply>() {
  static const StructInfo info = [] {
    StructBuilder<CleanReply> b("CleanReply", "the result of a clean job");
    b.Field(&CleanReply::station, "station", "the document's station");
    b.Field(&CleanReply::removed_cells, "removed_cells", "cells removed here").Unit("cells");
    b.Field(&CleanReply::version, "version", "the document's version");
    b.Field(&CleanReply::stations, "stations", "every station cleaned");
    b.Field(&CleanReply::warnings, "warnings", "the fills' warnings, naming the station");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<FillStationEntry>() {
  static const StructInfo info = [] {
    StructBuilder<FillStationEntry> b("FillStationEntry", "a station a fill-from-stations took cells from");
    b.Field(&FillStationEntry::station, "station", "its index");
    b.Field(&FillStationEntry::document, "document", "its document");
    b.Field(&FillStationEntry::cells, "cells", "cells filled from it").Unit("cells");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<FillFromStationsReply>() {
  static const StructInfo info = [] {
    StructBuilder<FillFromStationsReply> b("FillFromStationsReply", "the result of a fill-from-stations job");
    b.Field(&FillFromStationsReply::hole_cells, "hole_cells", "cells of the hole").Unit("cells");
    b.Field(&FillFromStationsReply::from_station_cells, "from_station_cells",
            "cells filled from other stations")
        .Unit("cells");
    b.Field(&FillFromStationsReply::synthesized_cells, "synthesized_cells", "cells synthesized")
        .Unit("cells");
    b.Field(&FillFromStationsReply::no_return_cells, "no_return_cells", "hole cells left without a return")
        .Unit("cells");
    b.Field(&FillFromStationsReply::stations, "stations", "the stations used");
    b.Field(&FillFromStationsReply::warnings, "warnings", "one sentence each");
    b.Field(&FillFromStationsReply::version, "version", "the document's version");
    return b.Build();
  }();
  return info;
}

}  // namespace lidarshop
