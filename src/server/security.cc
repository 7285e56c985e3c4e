// Who may talk to the editor's server, and what every answer says about itself (docs/api.md "Security").
#include <arpa/inet.h>
#include <ifaddrs.h>
#include <net/if.h>
#include <netinet/in.h>
#include <unistd.h>

#include <algorithm>

#include <fmt/format.h>

#include "http.h"
#include "lidarshop/util/text.h"

namespace lidarshop::server {

namespace {

bool IsIpv6Literal(const std::string& host) {
  in6_addr address{};
  return inet_pton(AF_INET6, host.c_str(), &address) == 1;
}

// 0.0.0.0, :: or an empty host: every address of the machine.
bool IsWildcard(const std::string& host) { return host.empty() || host == "0.0.0.0" || host == "::"; }

}  // namespace

std::string Excerpt(const std::string& text, size_t max_bytes) {
  if (text.size() <= max_bytes) return text;
  size_t cut = max_bytes;
  // Not inside a UTF-8 sequence: back off continuation bytes (10xxxxxx).
  while (cut > 0 && (static_cast<unsigned char>(text[cut]) & 0xC0) == 0x80) --cut;
  return fmt::format("{}… ({} bytes more)", text.substr(0, cut), text.size() - cut);
}

std::string UrlHost(const std::string& host) {
  return IsIpv6Literal(host) ? fmt::format("[{}]", host) : host;
}

std::string EditorUrl(const std::string& host, int port, const std::string& token) {
  return fmt::format("http://{}:{}/?token={}", UrlHost(host), port, token);
}

std::string BindWarning(const std::string& host) {
  if (host == "localhost") return "";
  in_addr v4{};
  if (inet_pton(AF_INET, host.c_str(), &v4) == 1 && (ntohl(v4.s_addr) >> 24) == 127) return "";
  in6_addr v6{};
  if (inet_pton(AF_INET6, host.c_str(), &v6) == 1 && IN6_IS_ADDR_LOOPBACK(&v6)) return "";
  return fmt::format(
      "serve: warning: listening on {}, {}: anyone there who learns the token can read, edit and save the "
      "open scans, and the connection is not encrypted; use --host 127.0.0.1 (this machine only) unless you "
      "mean it",
      host.empty() ? "every address" : host,
      IsWildcard(host) ? "reachable from every network of this machine" : "reachable from other machines");
}

std::vector<std::string> AllowedHosts(const std::string& host, int port) {
  std::vector<std::string> names = {"localhost", "127.0.0.1", "[::1]"};
  if (!host.empty()) names.push_back(AsciiLower(UrlHost(host)));
  if (IsWildcard(host)) {
    // Reachable at every address of the machine: each is a name a browser may use.
    ifaddrs* addresses = nullptr;
    if (getifaddrs(&addresses) == 0) {
      for (const ifaddrs* a = addresses; a != nullptr; a = a->ifa_next) {
        if (a->ifa_addr == nullptr) continue;
        char text[INET6_ADDRSTRLEN] = {};
        if (a->ifa_addr->sa_family == AF_INET) {
          inet_ntop(AF_INET, &reinterpret_cast<const sockaddr_in*>(a->ifa_addr)->sin_addr, text,
                    sizeof(text));
          names.push_back(text);
        } else if (a->ifa_addr->sa_family == AF_INET6) {
          const auto* v6 = reinterpret_cast<const sockaddr_in6*>(a->ifa_addr);
          if (IN6_IS_ADDR_LINKLOCAL(&v6->sin6_addr)) continue;  // needs a zone in URLs; not offered
          inet_ntop(AF_INET6, &v6->sin6_addr, text, sizeof(text));
          names.push_back(fmt::format("[{}]", text));
        }
      }
      freeifaddrs(addresses);
    }
    char name[256] = {};
    if (gethostname(name, sizeof(name) - 1) == 0 && name[0] != '\0') names.push_back(AsciiLower(name));
  }
  std::vector<std::string> hosts;
  for (const std::string& name : names) {
    hosts.push_back(fmt::format("{}:{}", name, port));
    if (port == 80) hosts.push_back(name);  // browsers leave the default port out
  }
  std::sort(hosts.begin(), hosts.end());
  hosts.erase(std::unique(hosts.begin(), hosts.end()), hosts.end());
  return hosts;
}

namespace {

bool Allowed(const std::vector<std::string>& allowed_hosts, const std::string& host) {
  return std::find(allowed_hosts.begin(), allowed_hosts.end(), AsciiLower(host)) != allowed_hosts.end();
}

}  // namespace

std::string RefusedHost(const httplib::Request& request, const std::vector<std::string>& allowed_hosts) {
  const std::string host = request.get_header_value("Host");
  if (Allowed(allowed_hosts, host)) return "";
  return fmt::format(
      "Host '{}' is not this server's address (a page of another site reaching it through its own name?); "
      "open the URL `lidarshop serve` printed",
      Excerpt(host, 100));
}

std::string RefusedOrigin(const httplib::Request& request, const std::vector<std::string>& allowed_hosts) {
  // Browsers say where a request comes from: only the editor's own page may act (cross-site request forgery).
  const std::string site = request.get_header_value("Sec-Fetch-Site");
  if (!site.empty() && site != "same-origin" && site != "none") {
    return fmt::format("a request from another site ({}) is refused", Excerpt(site, 40));
  }
  if (request.has_header("Origin")) {
    const std::string origin = AsciiLower(request.get_header_value("Origin"));
    if (origin.rfind("http://", 0) != 0 || !Allowed(allowed_hosts, origin.substr(7))) {
      return fmt::format("a request from the page of another origin ('{}') is refused", Excerpt(origin, 100));
    }
  }
  return "";
}

void AddSecurityHeaders(httplib::Response& response) {
  // The editor's own page: its scripts, styles and images come from this server (Vite's build: module
  // scripts and a stylesheet; styles set from scripts; pictures as blobs and data URLs); nothing is framed.
  response.set_header("Content-Security-Policy",
                      "default-src 'self'; script-src 'self'; style-src 'self' 'unsafe-inline'; "
                      "img-src 'self' data: blob:; connect-src 'self'; worker-src 'self' blob:; "
                      "object-src 'none'; base-uri 'none'; form-action 'self'; frame-ancestors 'none'");
  response.set_header("X-Frame-Options", "DENY");
  response.set_header("X-Content-Type-Options", "nosniff");
  response.set_header("Referrer-Policy", "no-referrer");
  response.set_header("Cross-Origin-Resource-Policy", "same-origin");
}

std::string TokenCookieName(int port) { return fmt::format("lidarshop_token_{}", port); }

std::string CookieValue(const httplib::Request& request, const std::string& name) {
  const std::string cookies = request.get_header_value("Cookie");
  size_t start = 0;
  while (start < cookies.size()) {
    size_t end = cookies.find(';', start);
    if (end == std::string::npos) end = cookies.size();
    std::string pair = cookies.substr(start, end - start);
    const size_t first = pair.find_first_not_of(' ');
    pair = first == std::string::npos ? "" : pair.substr(first);
    if (pair.size() > name.size() && pair.compare(0, name.size(), name) == 0 && pair[name.size()] == '=') {
      return pair.substr(name.size() + 1);
    }
    start = end + 1;
  }
  return "";
}

}  // namespace lidarshop::server
