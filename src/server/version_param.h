// Whole-number query parameters: `?since=V`, the version of a document a client already holds, as the picture,
// tile and points routes take it, and the jobs route's `?wait_ms=`.
#pragma once

#include <cstdint>
#include <cstdlib>
#include <limits>
#include <string>

#include "http.h"

namespace lidarshop::server {

// Sets *value to the request's parameter `name` and returns true (leaving *value as it was when there is none);
// answers 400 naming the parameter and returns false when it is not a whole number in [min, max].
inline bool ReadWholeNumberParam(const httplib::Request& request, httplib::Response& response,
                                 const char* name, int64_t min, int64_t max, const char* expected,
                                 int64_t* value) {
  if (!request.has_param(name)) return true;
  const std::string text = request.get_param_value(name);
  char* end = nullptr;
  const long long parsed = std::strtoll(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || parsed < min || parsed > max) {
    SendError(response, 400, std::string(name) + ": expected " + expected);
    return false;
  }
  *value = parsed;
  return true;
}

// Sets *since to the request's `since` (-1 when it has none) and returns true; answers 400 and returns false
// when the value is not a whole number >= 0.
inline bool ReadSinceParam(const httplib::Request& request, httplib::Response& response, int64_t* since) {
  *since = -1;
  return ReadWholeNumberParam(request, response, "since", 0, std::numeric_limits<int64_t>::max(),
                              "a version (a whole number >= 0)", since);
}

}  // namespace lidarshop::server
