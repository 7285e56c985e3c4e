// The server's internals: its state and the route groups. Internal to src/server.
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "lidarshop/io/scan_io.h"
#include "lidarshop/render/render.h"
#include "lidarshop/site/site_stations.h"
#include "lidarshop/util/error.h"
#include "lidarshop/verify/verify.h"
#include "server.h"
#include "state.h"
// After every Eigen include: httplib pulls in <resolv.h>, whose `_res` macro breaks Eigen's headers.
#include <httplib.h>

#include "gated_server.h"

namespace lidarshop::server {

// A model placed in scans: its mesh (for drawing) and its verification side (built once).
struct ModelEntry {
  int id = 0;
  std::string name;
  TriangleMesh mesh;
  VerifierModel model;
};

// Opening one more document is refused: too many are open (`status` 409) or they would hold more memory than
// allowed (507). Thrown by AddDocument; an InputError for the CLI's `serve SCAN...`.
class DocumentLimitError : public InputError {
 public:
  DocumentLimitError(int status, const std::string& message) : InputError(message), status(status) {}
  int status;
};

// The bytes of the distinct buffers of `document`'s state, undo and redo history and photos (buffers the
// snapshots share count once). Caller holds document.mutex.
int64_t DocumentBytes(const Document& document);
// DocumentBytes with `next` committed (the current state kept for undo): what an edit would make it hold.
int64_t DocumentBytesWith(const Document& document, const Snapshot& next);

// A site: open documents that are the stations of one site — the scans of one file of several (an E57 with
// several data3D), a built-in site, or documents the user grouped (docs/stations.md "In the editor").
// routes_stations.cc.
struct Site {
  int id = 0;
  std::string name;
  std::vector<int> documents;  // station i is document documents[i] (a closed one stays listed as closed)
  // Where each station stands, as opened (poses do not change with edits); the returns are re-counted live.
  std::vector<StationSummary> stations;
};

struct EditorServer::State {
  ServerOptions options;
  GatedServer http;  // httplib's server behind the connection gate (gated_server.h)
  int port = 0;
  std::vector<std::string> allowed_hosts;  // AllowedHosts of the bound address, set by Bind()
  int listen_socket = -1;
  std::unique_ptr<JobRunner> runner;
  std::mutex documents_mutex;
  std::map<int, std::shared_ptr<Document>> documents;
  int last_document = 0;
  std::map<int, std::shared_ptr<ModelEntry>> models;  // guarded by documents_mutex
  int last_model = 0;
  std::map<int, std::shared_ptr<Site>> sites;  // guarded by documents_mutex
  int last_site = 0;

  // Throws DocumentLimitError when max_documents are open (nothing else is checked then: call it before
  // reading a file), or when `more_bytes` more would take the open documents past max_document_bytes.
  void CheckRoomForDocument(int64_t more_bytes = 0);
  // Throws DocumentLimitError (507) when `document` holding `bytes_after` and the other open documents
  // (their last counted bytes) would pass max_document_bytes: an edit is refused, the document kept as it was.
  // Caller holds document.mutex (takes documents_mutex, which is never held while waiting for a document).
  void CheckRoomForEdit(const Document& document, int64_t bytes_after);
  // Opens `scan` as a new document after CheckRoomForDocument(its bytes); returns its id.
  int AddDocument(std::string name, Scan scan, std::vector<E57Image> e57_images = {});
  std::mutex open_mutex;  // one open at a time: the room checked is the room used
  std::shared_ptr<Document> Get(int id);
  std::shared_ptr<ModelEntry> FindModel(
      int id);  // nullptr when there is none  // an id AddDocument just returned
  // The document of the request's first path match; nullptr after answering 404.
  std::shared_ptr<Document> FindDocument(const httplib::Request& request, httplib::Response& response);
};
using State = EditorServer::State;

// security.cc: who may talk to the server, and the headers of every answer.
// `text` cut to at most about `max_bytes` (at a UTF-8 boundary) with how much was left out: no answer echoes
// unbounded input.
std::string Excerpt(const std::string& text, size_t max_bytes);
// The Host values a browser may send to this server: `host:port` for localhost, 127.0.0.1, [::1] and the
// --host value, and every address of the machine (and its name) when bound to a wildcard; lower case.
std::vector<std::string> AllowedHosts(const std::string& host, int port);
// Why the request is refused (403), or empty: its Host is not one of `allowed_hosts` (DNS rebinding: a page
// of another site reaching this server through a name of its own).
std::string RefusedHost(const httplib::Request& request, const std::vector<std::string>& allowed_hosts);
// Why an /api/ call is refused (403), or empty: it comes from another site (Sec-Fetch-Site other than
// same-origin or none) or from a page of another origin (Origin), i.e. cross-site request forgery.
std::string RefusedOrigin(const httplib::Request& request, const std::vector<std::string>& allowed_hosts);
// `host` as written in a URL: an IPv6 address in brackets.
std::string UrlHost(const std::string& host);
// Content-Security-Policy, X-Frame-Options: DENY, nosniff, Referrer-Policy: no-referrer.
void AddSecurityHeaders(httplib::Response& response);
// The cookie holding the token (per port: cookies are not kept apart by port), and a cookie's value.
std::string TokenCookieName(int port);
std::string CookieValue(const httplib::Request& request, const std::string& name);

// An error answer: {"error": message} with `status`; the message is cut to kMaxErrorBytes.
void SendError(httplib::Response& response, int status, const std::string& message);
void SendJson(httplib::Response& response, const nlohmann::ordered_json& json, int status = 200);
inline constexpr size_t kMaxErrorBytes = 1000;
// Limits of JSON request bodies (strokes, options, correspondences; photos are uploaded as images).
inline constexpr size_t kMaxJsonBodyBytes = size_t{8} << 20;
inline constexpr int kMaxJsonDepth = 64;
// The request body as a JSON object (an empty body is {}); nullopt after answering 415 (a body not sent as
// Content-Type: application/json), 400 (not JSON, nested deeper than kMaxJsonDepth: checked before parsing)
// or 413 (above kMaxJsonBodyBytes).
std::optional<nlohmann::json> BodyJson(const httplib::Request& request, httplib::Response& response);

// The PNG of an 8-bit RGB (3 channels) or grey image as the answer.
void SendPng(httplib::Response& response, const cv::Mat& rgb_or_gray);

// The cells of a stroke image (segment.h) holding object (1) and background (2) strokes, in one pass and without a
// temporary image: `strokes == 1` of a 100 M-ray station allocated 100 MB twice and took 0.7 s of every reply.
struct StrokeCounts {
  int64_t object = 0, background = 0;
};
StrokeCounts CountStrokes(const cv::Mat& strokes);

// Replaces the document's state with `next`, keeping the old one for undo (at most `undo_depth`); +1 version.
// Throws DocumentLimitError (507), changing nothing, when the memory limit would be passed (Document::check_room).
// Caller holds document.mutex.
void Commit(Document& document, Snapshot next, int undo_depth);
// Records the document's current point state as the one of its current version (Document::recent, the last
// kRecentStates distinct ones), for deltas. Called on every version change. Caller holds document.mutex.
inline constexpr size_t kRecentStates = 8;
void RememberState(Document& document);

// points.cc: the points of a document as typed arrays (docs/api.md "Points"), whole (LSP1) or the cells that
// changed since an earlier version (LSD1). Caller holds document.mutex.
// `step` > 1: a level of detail, only the cells whose row and column are multiples of it (a large scan's
// first view; its deltas then name only those cells too). `box` (x columns, y rows): only the cells inside it
// (a part of the scan seen closer, at a finer step than the rest); none: the whole grid.
// The box of a `box=COL,ROW,WIDTH,HEIGHT` parameter clipped to a rows x cols grid; nullopt when the text is
// not four whole numbers (width and height >= 1) or the box lies outside the grid.
std::optional<cv::Rect> ReadCellBox(const std::string& text, int rows, int cols);
std::string PointsBinary(const Document& document, int step = 1, const std::optional<cv::Rect>& box = {});
// The LSD1 delta from the state the document had at version `since` to now; nullopt when that state is no
// longer kept (or the grid changed): the client then gets the whole points.
std::optional<std::string> PointsDeltaBinary(const Document& document, int64_t since, int step = 1,
                                             const std::optional<cv::Rect>& box = {});
// Header X-Lidarshop-Box "col,row,width,height" (pictures, overlays and points of a box).
void SetBoxHeader(httplib::Response& response, const cv::Rect& box);

// pictures.cc: pictures that travel by what changed (docs/api.md "Pictures"). Caller holds document.mutex.
// The ray image of `options` (`channel` names it): whole, or with `since` >= 0 a kept version's picture, only
// the box of pixels that changed since (headers X-Lidarshop-Box "col,row,width,height" and X-Lidarshop-Size
// "cols,rows"; an empty body when nothing changed). Each kept state's picture is rendered once.
void SendRayPicture(Document& document, const RenderOptions& options, const std::string& channel,
                    int64_t since, httplib::Response& response);
// The picture of `state` in `channel`, rendered once per kept state (Document::pictures).
cv::Mat Picture(Document& document, const Document::PointState& state, const RenderOptions& options,
                const std::string& channel);
// The smallest box holding every pixel where `a` and `b` (same size and type) differ (empty when none).
cv::Rect ChangedBox(const cv::Mat& a, const cv::Mat& b);
// Every buffer RenderScan reads is the same: the two scans render the same picture.
bool SameScanBuffers(const Scan& a, const Scan& b);
// The point state kept for `version` (Document::recent), or nullptr when it is no longer kept.
const Document::PointState* StateAt(const Document& document, int64_t version);

// tiles.cc: the ray image as a tile pyramid (docs/api.md "Tiles"). Caller holds document.mutex.
inline constexpr int kTilePixels = 256;
// Levels above 0 of a rows x cols picture: the coarsest (the highest) holds the whole picture in one tile.
int TileLevels(int rows, int cols);
// {"version", "rows", "cols", "tile_px", "levels": [{"level", "rows", "cols", "tiles_x", "tiles_y"}],
// "changed"}: with `since` a kept version, "changed" is the box [col, row, width, height] of level-0 pixels that
// differ between its picture and the current one ([0, 0, 0, 0] when none), else the whole picture.
nlohmann::ordered_json TilesInfo(Document& document, const RenderOptions& options, const std::string& channel,
                                 int64_t since);
// Tile (tx, ty) of `level` as PNG (404 when the level or the tile does not exist); headers X-Lidarshop-Version
// and X-Lidarshop-Tile-Version (the version whose render made these pixels: a tile untouched by the edits
// since keeps its older one).
void SendTile(Document& document, const RenderOptions& options, const std::string& channel, int level, int tx,
              int ty, httplib::Response& response);
// The bytes the tile cache of a document may hold; the least recently used tiles are dropped above it.
inline constexpr int64_t kMaxTileCacheBytes = int64_t{96} << 20;

// A BGRA overlay as PNG; with `box` (of a `size` picture: cropped to its drawn cells, drawn from those
// cells alone so that a large scan's mostly clear overlay costs its box), with the headers above.
void SendOverlay(httplib::Response& response, const cv::Mat& bgra, const cv::Rect* box, cv::Size size);

// A job's JSON form (GET /api/jobs/ID).
nlohmann::ordered_json JobJson(const Job& job);
// Queues `run` on the document as a job of `kind` without answering (a job the server starts itself); null
// when too many are queued.
std::shared_ptr<Job> SubmitJob(State& state, const std::shared_ptr<Document>& document,
                               const std::string& kind, std::function<nlohmann::ordered_json(Progress&)> run);
// Starts `run` on the document as a job of `kind`; answers 202 with the job's JSON, or 503 (and returns null)
// when too many are queued.
std::shared_ptr<Job> StartJob(State& state, const std::shared_ptr<Document>& document,
                              const std::string& kind, std::function<nlohmann::ordered_json(Progress&)> run,
                              httplib::Response& response);

// A POST route on a document: finds it (404), parses the body as a JSON object (400), then runs `handler`;
// OptionsError becomes 400 and InputError 422, each with its one-line message.
using DocumentHandler =
    std::function<void(State&, const std::shared_ptr<Document>&, const nlohmann::json&, httplib::Response&)>;
void PostDocument(State& state, const std::string& pattern, DocumentHandler handler);

// A scan file read for editing: its scans and the reader's warnings, and for an E57 file its photos
// (images2D), so that a save as E57 writes them back and the recolour tool can use them.
struct FileForEditing {
  ScanFile file;
  std::vector<E57Image> images;
};
FileForEditing ReadFileForEditing(const std::string& path);
// The photos of `images` that belong to scan `index` of their file or to none, associated with the
// document's scan (associated_scan 0) or with none (-1).
std::vector<E57Image> ImagesOfScan(const std::vector<E57Image>& images, int index);

// A path given by a client, resolved against the roots: the canonical path when it lies inside one (after
// following symlinks), else empty. `..` components are refused before any lookup.
std::string ResolveUnderRoots(const std::vector<std::string>& roots, const std::string& requested);

// Route groups, one file each.
void AddScanRoutes(State& state);     // routes_scan.cc: open, list, pictures, points, save
void AddEditRoutes(State& state);     // routes_edit.cc: strokes, segment, remove, fill, undo, jobs
void AddVerifyRoutes(State& state);   // routes_verify.cc: models, pose verification
void AddRecolorRoutes(State& state);  // routes_recolor.cc: photos, the three kinds of correspondences
void AddReviewRoutes(State& state);   // routes_review.cc: inpainting with the patch review
void AddStationRoutes(State& state);  // routes_stations.cc: sites, their stations, clean
void AddTileRoutes(State& state);     // tiles.cc: the ray image's tile pyramid

}  // namespace lidarshop::server
