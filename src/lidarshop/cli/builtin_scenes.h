// The scenes of data/scenes/, compiled into the executable (see this folder's CMakeLists.txt).
#pragma once

#include <string>
#include <vector>

#include "lidarshop/scanner/scene.h"

namespace lidarshop::cli {

struct BuiltinScene {
  const char* name;  // the file name without .json, e.g. "parking_lot"
  const char* json;  // the scene file's text
};

const std::vector<BuiltinScene>& BuiltinScenes();

// `scene` as `scan` and `demo` take it: the name of a built-in scene, else a scene JSON file (its warnings
// printed). Throws InputError listing the built-in names when it is neither. builtin_scenes.cc.
SceneDescription LoadSceneOrBuiltin(const std::string& scene);

// " parking_lot electric_box ...": the built-in names, for help texts and errors.
std::string BuiltinSceneNames();

}  // namespace lidarshop::cli
