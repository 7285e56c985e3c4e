// The server's own replies as described structs (util/options.h; described in replies.cc): what a route
// answers, or adds beside a library result (`Joined`), is one of these written with ToJson, never keys written by
// hand, so that web/src/api_types.generated.ts (src/server/api_types.cc) types every reply. The keys, their
// order and their values are those of docs/api.md.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "lidarshop/io/formats.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop::server {

enum class JobState;  // state.h

// `json` (a described struct's JSON form, e.g. a library result) with the fields of `extra` after its own: a
// result with the route's keys beside it. The two must not share a key (LIDARSHOP_CHECK).
nlohmann::ordered_json Joined(nlohmann::ordered_json json, const nlohmann::ordered_json& extra);

// Every refusal: {"error": one line}.
struct ErrorReply {
  std::string error;
};

// GET /api/health.
struct HealthReply {
  bool ok = true;
};

// GET /api/scenes.
struct ScenesReply {
  std::vector<std::string> scenes;
};

// DELETE /api/docs/ID: the id of the scan closed.
struct ClosedReply {
  int closed = 0;
};

// GET /api/docs/ID/save-plan?format=F (io/scan_write_plan.h).
struct SavePlanReply {
  std::string format;
  std::vector<std::string> channels;
  std::vector<std::string> dropped;
  std::string refused;  // why a save in that format would fail; "" when it would not
};

// The document's version after an edit: undo, redo, and beside the results of remove and fill.
struct VersionReply {
  int64_t version = 0;
};

// POST /api/docs/ID/strokes.
struct StrokesReply {
  int64_t version = 0;
  int64_t hole_cells = 0;
  int64_t object_stroke_cells = 0;
  int64_t background_stroke_cells = 0;
};

// Beside a SegmentResult: how the cut was made.
struct SegmentReply {
  bool refined = false;   // the strokes were added to the last cut (SegmentSession::Refine)
  bool prepared = false;  // the session a `prepare segment` job built was used
  int64_t version = 0;
};

// The result of a `prepare segment` job.
struct PreparedReply {
  bool prepared = false;  // the session built is the document's (not one a cut made meanwhile)
};

// GET /api/jobs/ID: a job's state; its "result", the operation's own reply, follows when it has one.
struct JobReply {
  int id = 0;
  std::string kind;
  int document = 0;
  JobState state{};  // kQueued
  std::string label;
  int64_t done = 0;
  int64_t total = 0;
  std::optional<std::string> error;
  // The operation's own reply (a described struct's JSON form, or several joined), once it has one: its type
  // depends on the job's kind.
  std::optional<nlohmann::ordered_json> result;
};

// POST /api/docs/ID/photo and .../photo-from-e57.
struct PhotoReply {
  int width_px = 0;
  int height_px = 0;
  std::optional<std::string> name;  // the E57 photo's name (photo-from-e57)
};

// The result of a recolour job (photo <-> scan pairs): the resection's, then the recolouring's.
struct RecolorReply {
  int inliers = 0;
  uint64_t pairs = 0;
  double rms_px = 0;
  std::vector<double> reprojection_error_px;  // per pair
  std::vector<uint8_t> inlier;                // per pair: 1 = inlier
  int64_t recolored_count = 0;
  int64_t hidden = 0;
  int64_t uncertain = 0;
  int64_t outside_image = 0;
  std::string summary;
  std::vector<std::string> warnings;
  int64_t version = 0;
};

// Beside a LandmarkAlignment (POST /api/docs/ID/align): its matrix (not a described field of the library's
// struct) as the 16 numbers the editor multiplies poses with.
struct AlignReply {
  std::vector<double> target_from_source_column_major;
  bool applied = false;
  int64_t version = 0;
};

// Beside a PhotoPairModel (POST /api/docs/ID/photo-match): its 3 x 3 matrix by rows.
struct PhotoMatchReply {
  std::vector<double> matrix_row_major;
};

// The result of a review job stopped at a review point.
struct ReviewPointReply {
  std::string state = "review";
  int review_point = 0;
  std::vector<int> target;  // [row, col]
  uint64_t candidates = 0;
  uint64_t clusters = 0;
};

// The result of a review job whose review was dropped while it ran.
struct ReviewStoppedReply {
  std::string state = "stopped";
};

// DELETE /api/docs/ID/inpaint/review.
struct ReviewClosedReply {
  bool closed = true;
};

// GET /api/docs/ID/removed.
struct RemovedReply {
  int64_t version = 0;
  std::vector<int64_t> cells;  // row * cols + col
};

// GET /api/models.
struct ModelsReply {
  std::vector<std::string> builtin;
  std::vector<std::string> files;
};

// POST /api/models.
struct ModelReply {
  int id = 0;
  std::string name;
  uint64_t vertices = 0;
  uint64_t triangles = 0;
  std::vector<double> size_m;  // [x, y, z]
  std::vector<std::string> warnings;
};

// Beside a VerifyResult (POST /api/docs/ID/verify).
struct VerifyReply {
  std::string summary;
};

// One scan file of GET /api/files.
struct FileEntry {
  std::string path;
  uint64_t bytes = 0;
  bool readable = false;             // its header reads
  std::optional<std::string> error;  // why not
};

// GET /api/files: scan files under the roots, in name order.
struct FilesReply {
  std::vector<std::string> roots;
  std::vector<FileEntry> files;
};

// A photo a document carries from its E57 file (images2D).
struct E57ImageEntry {
  uint64_t index = 0;
  std::string name;
  int width_px = 0;
  int height_px = 0;
  bool usable = false;  // decoded: the recolour tool can take it
};

// GET /api/docs/ID: an open scan.
struct DocumentReply {
  int id = 0;
  std::string name;
  int rows = 0;
  int cols = 0;
  std::vector<std::string> channels;
  int64_t valid_cells = 0;
  int64_t synthesized_cells = 0;
  int64_t object_cells = 0;
  int64_t hole_cells = 0;
  int64_t object_stroke_cells = 0;
  int64_t background_stroke_cells = 0;
  int64_t behind_cells = 0;
  std::vector<double> world_from_scanner_column_major;  // 16
  double azimuth_step_deg = 0;
  double elevation_step_deg = 0;
  int64_t version = 0;
  bool can_undo = false;
  bool can_redo = false;
  std::vector<E57ImageEntry> e57_images;
};

// Beside a reply from a file: what the reader left out of it, one sentence each (GET /api/open).
struct WarningsReply {
  std::vector<std::string> warnings;
};

// GET /api/docs.
struct DocumentsReply {
  std::vector<DocumentReply> documents;
};

// One label of GET /api/docs/ID/labels.
struct LabelEntry {
  int label = 0;
  int64_t cells = 0;
  std::vector<int64_t> box;     // [row0, col0, row1, col1]
  std::vector<int64_t> center;  // [row, col]
};

// GET /api/docs/ID/labels.
struct LabelsReply {
  std::vector<LabelEntry> labels;
};

// GET /api/formats.
struct FormatsReply {
  std::vector<std::string> read;
  std::vector<std::string> write;
  std::vector<ScanFormatSummary> formats;  // the library's table of formats (io/formats.h)
};

// One level of the tile pyramid.
struct TileLevelEntry {
  int level = 0;
  int rows = 0;
  int cols = 0;
  int tiles_x = 0;
  int tiles_y = 0;
};

// GET /api/docs/ID/tiles.json.
struct TilesReply {
  int64_t version = 0;
  int rows = 0;
  int cols = 0;
  int tile_px = 0;
  std::vector<TileLevelEntry> levels;
  std::vector<int> changed;  // [col, row, width, height] of level-0 pixels
};

// An E57 photo a station recolouring used or skipped.
struct StationPhotoEntry {
  int index = 0;
  std::string name;
  std::optional<std::string> why;  // skipped: why
};

// The result of a recolor-station job.
struct RecolorStationReply {
  int64_t returns = 0;
  int64_t coloured = 0;
  int64_t constraints = 0;
  std::vector<StationPhotoEntry> used;
  std::vector<StationPhotoEntry> skipped;
  std::string summary;
  int64_t version = 0;
};

// A decision of the patch review.
struct ReviewDecisionEntry {
  std::vector<int> target;  // [row, col]
  std::vector<int> source;  // [row, col]
};

// A candidate of a review point.
struct ReviewCandidateEntry {
  uint64_t index = 0;
  std::vector<int> source;  // [row, col]
  double difference = 0;
  int cluster = 0;
  bool accepted = false;
  std::string test;
  double value = 0;
  double threshold = 0;
  double margin = 0;
};

// A cluster of near-identical candidates.
struct ReviewClusterEntry {
  uint64_t index = 0;
  int representative = 0;
  std::vector<uint64_t> members;
};

// A review point (inpaint/review.h InpaintReview).
struct ReviewDetail {
  int review_point = 0;
  int iteration = 0;
  std::vector<int> target;  // [row, col]
  int patch_radius = 0;
  std::vector<ReviewCandidateEntry> candidates;
  std::vector<ReviewClusterEntry> clusters;
};

// GET /api/docs/ID/inpaint/review.
struct PendingReviewReply {
  std::string state = "review";
  std::string channel;
  int rows = 0;
  int cols = 0;
  int64_t hole_cells = 0;
  std::vector<ReviewDecisionEntry> decisions;
  ReviewDetail review;
};

// The result of a review job at its end.
struct ReviewDoneReply {
  std::string state = "done";
  std::string channel;
  std::vector<ReviewDecisionEntry> decisions;
  std::string summary;
  int64_t version = 0;
};

// A station of a site (site/site_stations.h StationSummary) with its document.
struct StationEntry {
  int index = 0;
  std::string name;
  std::vector<double> position_m;  // [x, y, z], world
  double heading_deg = 0;
  std::vector<double> world_from_scanner_column_major;  // 16
  int rows = 0;
  int cols = 0;
  int64_t returns = 0;
  bool organized = false;
  int document = 0;
  bool open = false;
  bool current = false;
  std::optional<int64_t> version;        // while open
  std::optional<int64_t> removed_cells;  // while open
};

// A site: GET /api/docs/ID/stations, GET /api/sites.
struct SiteReply {
  std::optional<int> site;  // null for a scan in no site
  std::string name;
  int station = -1;  // the document's station (-1: none)
  std::vector<StationEntry> stations;
};

// GET /api/sites.
struct SitesReply {
  std::vector<SiteReply> sites;
};

// Beside a site opened (POST /api/sites).
struct OpenedSiteReply {
  int document = 0;  // the station to show
  std::vector<std::string> warnings;
};

// A station of a clean.
struct CleanStationEntry {
  int station = 0;
  int document = 0;
  int64_t removed = 0;
  int64_t seen_through = 0;
  int64_t confirmed = 0;
  int64_t filled = 0;
  bool changed = false;
  std::optional<std::string> why;  // why not
  int64_t version = 0;
};

// The result of a clean job.
struct CleanReply {
  int station = 0;
  int64_t removed_cells = 0;  // here
  int64_t version = 0;        // here
  std::vector<CleanStationEntry> stations;
  std::vector<std::string> warnings;
};

// A station a fill-from-stations took cells from.
struct FillStationEntry {
  int station = 0;
  int document = 0;
  int64_t cells = 0;
};

// The result of a fill-from-stations job.
struct FillFromStationsReply {
  int64_t hole_cells = 0;
  int64_t from_station_cells = 0;
  int64_t synthesized_cells = 0;
  int64_t no_return_cells = 0;
  std::vector<FillStationEntry> stations;
  std::vector<std::string> warnings;
  int64_t version = 0;
};

}  // namespace lidarshop::server

namespace lidarshop {

template <>
const EnumInfo& EnumInfoOf<server::JobState>();
template <>
const StructInfo& InfoOf<server::ErrorReply>();
template <>
const StructInfo& InfoOf<server::HealthReply>();
template <>
const StructInfo& InfoOf<server::ScenesReply>();
template <>
const StructInfo& InfoOf<server::ClosedReply>();
template <>
const StructInfo& InfoOf<server::SavePlanReply>();
template <>
const StructInfo& InfoOf<server::VersionReply>();
template <>
const StructInfo& InfoOf<server::StrokesReply>();
template <>
const StructInfo& InfoOf<server::SegmentReply>();
template <>
const StructInfo& InfoOf<server::PreparedReply>();
template <>
const StructInfo& InfoOf<server::JobReply>();
template <>
const StructInfo& InfoOf<server::PhotoReply>();
template <>
const StructInfo& InfoOf<server::RecolorReply>();
template <>
const StructInfo& InfoOf<server::AlignReply>();
template <>
const StructInfo& InfoOf<server::PhotoMatchReply>();
template <>
const StructInfo& InfoOf<server::ReviewPointReply>();
template <>
const StructInfo& InfoOf<server::ReviewStoppedReply>();
template <>
const StructInfo& InfoOf<server::ReviewClosedReply>();
template <>
const StructInfo& InfoOf<server::RemovedReply>();
template <>
const StructInfo& InfoOf<server::ModelsReply>();
template <>
const StructInfo& InfoOf<server::ModelReply>();
template <>
const StructInfo& InfoOf<server::VerifyReply>();

template <>
const StructInfo& InfoOf<server::FileEntry>();
template <>
const StructInfo& InfoOf<server::FilesReply>();
template <>
const StructInfo& InfoOf<server::E57ImageEntry>();
template <>
const StructInfo& InfoOf<server::DocumentReply>();
template <>
const StructInfo& InfoOf<server::WarningsReply>();
template <>
const StructInfo& InfoOf<server::DocumentsReply>();
template <>
const StructInfo& InfoOf<server::LabelEntry>();
template <>
const StructInfo& InfoOf<server::LabelsReply>();
template <>
const StructInfo& InfoOf<server::FormatsReply>();
template <>
const StructInfo& InfoOf<server::TileLevelEntry>();
template <>
const StructInfo& InfoOf<server::TilesReply>();
template <>
const StructInfo& InfoOf<server::StationPhotoEntry>();
template <>
const StructInfo& InfoOf<server::RecolorStationReply>();
template <>
const StructInfo& InfoOf<server::ReviewDecisionEntry>();
template <>
const StructInfo& InfoOf<server::ReviewCandidateEntry>();
template <>
const StructInfo& InfoOf<server::ReviewClusterEntry>();
template <>
const StructInfo& InfoOf<server::ReviewDetail>();
template <>
const StructInfo& InfoOf<server::PendingReviewReply>();
template <>
const StructInfo& InfoOf<server::ReviewDoneReply>();
template <>
const StructInfo& InfoOf<server::StationEntry>();
template <>
const StructInfo& InfoOf<server::SiteReply>();
template <>
const StructInfo& InfoOf<server::SitesReply>();
template <>
const StructInfo& InfoOf<server::OpenedSiteReply>();
template <>
const StructInfo& InfoOf<server::CleanStationEntry>();
template <>
const StructInfo& InfoOf<server::CleanReply>();
template <>
const StructInfo& InfoOf<server::FillStationEntry>();
template <>
const StructInfo& InfoOf<server::FillFromStationsReply>();

}  // namespace lidarshop
