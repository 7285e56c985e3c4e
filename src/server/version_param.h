// `?since=V`, the version of a document a client already holds, as the picture, tile and points routes take it.
#pragma once

#include <cstdint>
#include <cstdlib>
#include <string>

#include "http.h"

namespace lidarshop::server {

// Sets *since to the request's `since` (-1 when it has none) and returns true; answers 400 and returns false
// when the value is not a whole number >= 0.
inline bool ReadSinceParam(const httplib::Request& request, httplib::Response& response, int64_t* since) {
  *since = -1;
  if (!request.has_param("since")) return true;
  const std::string text = request.get_param_value("since");
  char* end = nullptr;
  const long long value = std::strtoll(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || value < 0) {
    SendError(response, 400, "since: expected a version (a whole number >= 0)");
    return false;
  }
  *since = value;
  return true;
}

}  // namespace lidarshop::server
