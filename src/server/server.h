// The editor's HTTP server: a thin layer that turns JSON requests into library calls on open scans
// (docs/api.md). No algorithm lives here; options and results travel in the library's one JSON form
// (util/options.h).
//
// Safety (docs/api.md "Security"): it listens on loopback unless told otherwise (a warning on stderr when
// not); every /api/ call needs the token printed at start (401 before any routing), as `?token=`, an
// `Authorization: Bearer` header or the cookie the first page load sets (HttpOnly, SameSite=Strict; the page
// is then redirected to drop the token from its URL); every request must name this server in its Host, and
// /api/ calls from another site or origin are refused (403); JSON bodies must say Content-Type:
// application/json (415); every answer carries a Content-Security-Policy, X-Frame-Options: DENY, nosniff and
// no-referrer; saves go through a private folder (mkdtemp, 0700); files are opened only under the folders
// given at start (403 for `..`, symlinks or absolute paths leading outside them); request bodies are
// size-limited (JSON bodies further, in size and nesting depth, before parsing; photos by their pixels, read
// from the header before decoding); a malformed request gets a 4xx with a one-line message that does not
// echo unbounded input; slow, idle or too many clients cannot starve the others (gated_server.h); one
// scan more than the limits of count and memory is refused, never an open one closed.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "lidarshop/scan/scan.h"

namespace lidarshop::server {

struct ServerOptions {
  std::string host = "127.0.0.1";  // loopback only by default
  int port = 8080;                 // 0 = any free port (tests)
  std::string token;               // required on /api/ calls; empty = a random 128-bit token
  std::vector<std::string> roots;  // folders files may be opened from (canonical paths are compared)
  std::string web_dir;             // the built front end (index.html), served at /; empty = none
  int64_t max_body_bytes = int64_t{64} << 20;  // request bodies above this get 413
  // Request threads: requests served at once (operations run on their own threads). A connection takes one
  // only once a request's headers have all arrived (gated_server.h), so idle and slow clients hold none.
  int threads = 64;
  int max_connections = 4096;    // open at once (also kept below the descriptor limit); then the oldest idle
                                 // one is closed, or the newcomer gets 503
  double header_timeout_s = 10;  // from a request's first byte to the end of its headers (408 after)
  double idle_timeout_s = 5;     // a connection with no request under way is closed after this
  // Open scans at once: one more is refused (409) until the user closes one; an open scan is never closed
  // behind the user's back (its unsaved edits would go with it).
  int max_documents = 16;
  // The memory open scans may hold, with their undo history and photos, bytes; opening one more past it is
  // refused (507). 0 = the memory budget (util/memory_budget.h, --max-memory).
  int64_t max_document_bytes = 0;
  int64_t max_photo_pixels = 100'000'000;  // an uploaded photo's width x height, read from its header (413)
  int undo_depth = 8;                      // edits kept per scan for undo
  // Built-in scenes: their names, and a function scanning one (the CLI passes its compiled-in scenes).
  std::vector<std::string> builtin_scenes;
  std::function<Scan(const std::string& name)> scan_builtin;
  // Every station of a built-in scene (a site: parking_lot_stations), in order; one scan for a scene with one
  // scanner. Empty = the site is opened as scan_builtin's one scan (routes_stations.cc).
  std::function<std::vector<Scan>(const std::string& name)> scan_builtin_stations;
};

// http://HOST:PORT/?token=T, with an IPv6 address in brackets (http://[::1]:8080/...).
std::string EditorUrl(const std::string& host, int port, const std::string& token);
// A warning for stderr when `host` is not a loopback address (0.0.0.0, ::, a LAN address), else empty.
std::string BindWarning(const std::string& host);

class EditorServer {
 public:
  explicit EditorServer(ServerOptions options);
  ~EditorServer();
  EditorServer(const EditorServer&) = delete;
  EditorServer& operator=(const EditorServer&) = delete;

  // Binds the port (throws InputError naming host:port when it cannot); then Run() serves until Stop().
  void Bind();
  void Run();
  void Stop();

  int port() const;
  const std::string& token() const;
  std::string Url() const;  // http://HOST:PORT/?token=T

  // Opens a scan file at start (`serve SCAN…`); its folder becomes a root. Returns the document id; the
  // reader's warnings go to `warnings` when it is not null.
  int OpenAtStart(const std::string& path, std::vector<std::string>* warnings = nullptr);
  // Scans a built-in scene and opens it (throws InputError for an unknown name).
  int OpenScene(const std::string& name);

  struct State;

 private:
  std::unique_ptr<State> state_;
};

}  // namespace lidarshop::server
