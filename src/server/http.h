// The server's internals: its state and the route groups. Internal to src/server.
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

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

struct EditorServer::State {
  ServerOptions options;
  GatedServer http;  // httplib's server behind the connection gate (gated_server.h)
  int port = 0;
  int listen_socket = -1;
  std::unique_ptr<JobRunner> runner;
  std::mutex documents_mutex;
  std::map<int, std::shared_ptr<Document>> documents;
  int last_document = 0;
  std::map<int, std::shared_ptr<ModelEntry>> models;  // guarded by documents_mutex
  int last_model = 0;

  int AddDocument(std::string name, Scan scan);
  std::shared_ptr<Document> Get(int id);
  std::shared_ptr<ModelEntry> FindModel(
      int id);  // nullptr when there is none  // an id AddDocument just returned
  // The document of the request's first path match; nullptr after answering 404.
  std::shared_ptr<Document> FindDocument(const httplib::Request& request, httplib::Response& response);
};
using State = EditorServer::State;

// An error answer: {"error": message} with `status`.
void SendError(httplib::Response& response, int status, const std::string& message);
void SendJson(httplib::Response& response, const nlohmann::ordered_json& json, int status = 200);
// Limits of JSON request bodies (strokes, options, correspondences; photos are uploaded as images).
inline constexpr size_t kMaxJsonBodyBytes = size_t{8} << 20;
inline constexpr int kMaxJsonDepth = 64;
// The request body as a JSON object; nullopt after answering 400 (not JSON, nested deeper than kMaxJsonDepth)
// or 413 (above kMaxJsonBodyBytes).
std::optional<nlohmann::json> BodyJson(const httplib::Request& request, httplib::Response& response);

// The PNG of an 8-bit RGB (3 channels) or grey image as the answer.
void SendPng(httplib::Response& response, const cv::Mat& rgb_or_gray);

// Replaces the document's state with `next`, keeping the old one for undo (at most `undo_depth`); +1 version.
// Caller holds document.mutex.
void Commit(Document& document, Snapshot next, int undo_depth);
// A job's JSON form (GET /api/jobs/ID).
nlohmann::ordered_json JobJson(const Job& job);
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

// A path given by a client, resolved against the roots: the canonical path when it lies inside one (after
// following symlinks), else empty. `..` components are refused before any lookup.
std::string ResolveUnderRoots(const std::vector<std::string>& roots, const std::string& requested);

// Route groups, one file each.
void AddScanRoutes(State& state);     // routes_scan.cc: open, list, pictures, points, save
void AddEditRoutes(State& state);     // routes_edit.cc: strokes, segment, remove, fill, undo, jobs
void AddVerifyRoutes(State& state);   // routes_verify.cc: models, pose verification
void AddRecolorRoutes(State& state);  // routes_recolor.cc: photos, the three kinds of correspondences
void AddReviewRoutes(State& state);   // routes_review.cc: inpainting with the patch review

}  // namespace lidarshop::server
