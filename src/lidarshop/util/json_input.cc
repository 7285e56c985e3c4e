#include "lidarshop/util/json_input.h"

#include <fmt/format.h>

#include "lidarshop/util/error.h"

namespace lidarshop {

nlohmann::json ParseJsonInput(const std::string& text, const std::string& what) {
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    ThrowInputError(what, fmt::format("byte {}", e.byte), "", "not valid JSON");
  } catch (const nlohmann::json::exception& e) {
    ThrowInputError(what, "", "", fmt::format("not usable JSON: {}", e.what()));
  }
}

}  // namespace lidarshop
