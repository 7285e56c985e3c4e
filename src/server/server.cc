#include "server.h"

#include <filesystem>
#include <random>

#include <fmt/format.h>

#include "http.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/util/error.h"

namespace lidarshop::server {

namespace fs = std::filesystem;

namespace {

std::string RandomToken() {
  std::random_device device;  // a secret, not an algorithm's random choice: not seeded on purpose
  std::uniform_int_distribution<uint32_t> word;
  return fmt::format("{:08x}{:08x}{:08x}{:08x}", word(device), word(device), word(device), word(device));
}

// Constant-time comparison: the token must not leak through response times.
bool SameToken(const std::string& given, const std::string& token) {
  if (given.size() != token.size()) return false;
  unsigned char difference = 0;
  for (size_t i = 0; i < given.size(); ++i) difference |= static_cast<unsigned char>(given[i] ^ token[i]);
  return difference == 0;
}

}  // namespace

EditorServer::EditorServer(ServerOptions options) : state_(std::make_unique<State>()) {
  if (options.token.empty()) options.token = RandomToken();
  for (std::string& root : options.roots) root = fs::weakly_canonical(fs::absolute(root)).string();
  state_->options = std::move(options);
  state_->runner = std::make_unique<JobRunner>(1, 256);
  httplib::Server& http = state_->http;
  // Debian's httplib listens with a backlog of 5: a burst of new clients overflows it and some connections
  // stall or fail. The socket is remembered here and given a full backlog after binding (a second listen()
  // on a listening socket only changes its backlog).
  http.set_socket_options([this](socket_t socket) {
    int yes = 1;
    setsockopt(socket, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes));
    state_->listen_socket = socket;
  });
  // Before any route is looked at: the Host (every request), then for /api/ where the call comes from and
  // its token; an unauthenticated or foreign caller learns nothing.
  http.set_pre_routing_handler([this](const httplib::Request& request, httplib::Response& response) {
    const bool api = request.path.rfind("/api/", 0) == 0;
    std::string refused = RefusedHost(request, state_->allowed_hosts);
    if (refused.empty() && api) refused = RefusedOrigin(request, state_->allowed_hosts);
    if (!refused.empty()) {
      SendError(response, 403, refused);
      return httplib::Server::HandlerResponse::Handled;
    }
    const std::string& token = state_->options.token;
    const std::string cookie = TokenCookieName(state_->port);
    if (!api) {
      // The first page load (the URL `serve` printed): the token goes into a cookie the browser sends back on
      // every call from this page, and the page is loaded again without the token in its URL (nor in the
      // history, nor in a Referer).
      if ((request.method == "GET" || request.method == "HEAD") && request.has_param("token") &&
          SameToken(request.get_param_value("token"), token)) {
        std::string query;
        for (const auto& [key, value] : request.params) {
          if (key == "token") continue;
          query += (query.empty() ? "?" : "&") + httplib::detail::encode_query_param(key) + "=" +
                   httplib::detail::encode_query_param(value);
        }
        response.set_header("Set-Cookie",
                            fmt::format("{}={}; HttpOnly; SameSite=Strict; Path=/", cookie, token));
        response.set_header("Cache-Control", "no-store");
        response.set_redirect(request.path + query, 303);
        return httplib::Server::HandlerResponse::Handled;
      }
      return httplib::Server::HandlerResponse::Unhandled;
    }
    std::string given = request.get_param_value("token");
    const std::string header = request.get_header_value("Authorization");
    if (given.empty() && header.rfind("Bearer ", 0) == 0) given = header.substr(7);
    if (given.empty()) given = CookieValue(request, cookie);
    if (!SameToken(given, token)) {
      SendError(response, 401, "missing or wrong token (the one `lidarshop serve` printed)");
      return httplib::Server::HandlerResponse::Handled;
    }
    return httplib::Server::HandlerResponse::Unhandled;
  });
  http.set_post_routing_handler(
      [](const httplib::Request&, httplib::Response& response) { AddSecurityHeaders(response); });
  http.set_exception_handler(
      [](const httplib::Request&, httplib::Response& response, std::exception_ptr error) {
        try {
          std::rethrow_exception(error);
        } catch (const nlohmann::json::exception& e) {
          // A field of the request of the wrong type, found past the routes' own checks: the request's fault.
          SendError(response, 400, fmt::format("a field of the request has the wrong type: {}", e.what()));
        } catch (const std::exception& e) {
          SendError(response, 500, e.what());
        } catch (...) {
          SendError(response, 500, "internal error");
        }
      });
  http.set_error_handler([](const httplib::Request& request, httplib::Response& response) {
    if (response.body.empty()) {
      SendError(response, response.status, fmt::format("{} {}: no such route", request.method, request.path));
    }
  });
  AddScanRoutes(*state_);
  AddEditRoutes(*state_);
  AddVerifyRoutes(*state_);
  AddRecolorRoutes(*state_);
  AddReviewRoutes(*state_);
  AddStationRoutes(*state_);
  AddTileRoutes(*state_);
  if (!state_->options.web_dir.empty()) {
    if (!http.set_mount_point("/", state_->options.web_dir)) {
      throw InputError(
          fmt::format("{}: not a folder with the built editor (index.html)", state_->options.web_dir));
    }
  }
}

EditorServer::~EditorServer() { Stop(); }

void EditorServer::Bind() {
  const ServerOptions& options = state_->options;
  if (options.port == 0) {
    state_->port = state_->http.bind_to_any_port(options.host);
  } else if (state_->http.bind_to_port(options.host, options.port)) {
    state_->port = options.port;
  }
  if (state_->port > 0 && state_->listen_socket >= 0) ::listen(state_->listen_socket, SOMAXCONN);
  if (state_->port <= 0) {
    throw InputError(fmt::format("{}:{}: cannot listen there (in use, or not an address of this machine)",
                                 UrlHost(options.host), options.port));
  }
  state_->allowed_hosts = AllowedHosts(options.host, state_->port);
  const std::string warning = BindWarning(options.host);
  if (!warning.empty()) fmt::print(stderr, "{}\n", warning);
}

void EditorServer::Run() {
  const ServerOptions& options = state_->options;
  state_->http.StartGate({.threads = options.threads,
                          .max_connections = options.max_connections,
                          .header_timeout_s = options.header_timeout_s,
                          .idle_timeout_s = options.idle_timeout_s,
                          .max_body_bytes = options.max_body_bytes});
  state_->http.listen_after_bind();
  state_->http.StopGate();
}

void EditorServer::Stop() {
  if (state_->http.is_running()) state_->http.stop();
}

int EditorServer::port() const { return state_->port; }

const std::string& EditorServer::token() const { return state_->options.token; }

std::string EditorServer::Url() const {
  return EditorUrl(state_->options.host, state_->port, state_->options.token);
}

int EditorServer::OpenAtStart(const std::string& path, std::vector<std::string>* warnings) {
  const std::string folder = fs::weakly_canonical(fs::absolute(path)).parent_path().string();
  state_->options.roots.push_back(folder);
  FileForEditing opened = ReadFileForEditing(path);
  ScanFile& file = opened.file;
  if (warnings != nullptr) warnings->insert(warnings->end(), file.warnings.begin(), file.warnings.end());
  if (file.scans.empty()) throw InputError(fmt::format("{}: holds no scan", path));
  return state_->AddDocument(fs::path(path).filename().string(), std::move(file.scans.front()),
                             ImagesOfScan(opened.images, 0));
}

int EditorServer::OpenScene(const std::string& name) {
  const auto& names = state_->options.builtin_scenes;
  if (std::find(names.begin(), names.end(), name) == names.end() || !state_->options.scan_builtin) {
    throw InputError(fmt::format("no built-in scene '{}'", name));
  }
  return state_->AddDocument(name, state_->options.scan_builtin(name));
}

}  // namespace lidarshop::server
