#include "lidarshop/util/error.h"

namespace lidarshop {

std::string FormatInputError(std::string_view file, std::string_view place, std::string_view field,
                             std::string_view message) {
  std::string text;
  auto append = [&text](std::string_view part) {
    if (part.empty()) return;
    if (!text.empty()) text += ": ";
    text += part;
  };
  append(file);
  append(place);
  if (!field.empty()) append(fmt::format("field '{}'", field));
  append(message);
  return text;
}

void ThrowInputError(std::string_view file, std::string_view place, std::string_view field,
                     std::string_view message) {
  throw InputError(FormatInputError(file, place, field, message));
}

}  // namespace lidarshop
