// The scenes of data/scenes/, compiled into the library (see this folder's CMakeLists.txt), so the CLI's `demo`,
// the editor and the Python module need no file beside them.
#pragma once

#include <string>
#include <vector>

#include "lidarshop/scanner/scene.h"

namespace lidarshop {

struct BuiltinScene {
  const char* name;  // the file name without .json, e.g. "parking_lot"
  const char* json;  // the scene file's text
};

// Every built-in scene, in file-name order. Generated: builtin_scenes_data.cc in the build folder.
const std::vector<BuiltinScene>& BuiltinScenes();

// The built-in scene called `name`, or nullptr.
const BuiltinScene* FindBuiltinScene(const std::string& name);

// `scene` as `scan` and `demo` take it: the name of a built-in scene, else a scene JSON file (what its mesh
// files left out in the description's warnings). Throws InputError listing the built-in names when it is neither.
SceneDescription LoadSceneOrBuiltin(const std::string& scene);

// " parking_lot electric_box ...": the built-in names, for help texts and errors.
std::string BuiltinSceneNames();

}  // namespace lidarshop
