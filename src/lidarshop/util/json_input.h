// JSON documents that come from users' files (strokes, picture layouts, camera files): parsed with the file
// and the place named in the error, never an escaping nlohmann exception.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace lidarshop {

// Parses `text`, read from `what` (a file name). Throws InputError naming `what` and the byte where the text
// stops being JSON, or saying why a well-formed text cannot be held (a number past double's range: 1e+316).
nlohmann::json ParseJsonInput(const std::string& text, const std::string& what);

}  // namespace lidarshop
