// The scenes of data/scenes/, compiled into the executable (see this folder's CMakeLists.txt).
#pragma once

#include <string>
#include <vector>

namespace lidarshop::cli {

struct BuiltinScene {
  const char* name;  // the file name without .json, e.g. "parking_lot"
  const char* json;  // the scene file's text
};

const std::vector<BuiltinScene>& BuiltinScenes();

}  // namespace lidarshop::cli
