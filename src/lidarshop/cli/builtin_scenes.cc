#include "lidarshop/cli/builtin_scenes.h"

#include <filesystem>

#include <fmt/format.h>

#include "lidarshop/cli/commands.h"
#include "lidarshop/util/error.h"

namespace lidarshop::cli {

std::string BuiltinSceneNames() {
  std::string names;
  for (const BuiltinScene& builtin : BuiltinScenes()) names += fmt::format(" {}", builtin.name);
  return names;
}

SceneDescription LoadSceneOrBuiltin(const std::string& scene) {
  for (const BuiltinScene& builtin : BuiltinScenes()) {
    if (scene == builtin.name) return ParseScene(builtin.json, fmt::format("built-in scene '{}'", scene), "");
  }
  std::error_code not_a_file;
  if (std::filesystem::exists(scene, not_a_file)) {
    SceneDescription description = LoadScene(scene);
    PrintWarnings(description.warnings);
    return description;
  }
  throw InputError(fmt::format("'{}' is neither a built-in scene (one of:{}) nor a scene file", scene,
                               BuiltinSceneNames()));
}

}  // namespace lidarshop::cli
