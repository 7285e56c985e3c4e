#include "lidarshop/scanner/builtin_scenes.h"

#include <filesystem>

#include <fmt/format.h>

#include "lidarshop/util/error.h"

namespace lidarshop {

const BuiltinScene* FindBuiltinScene(const std::string& name) {
  for (const BuiltinScene& builtin : BuiltinScenes()) {
    if (name == builtin.name) return &builtin;
  }
  return nullptr;
}

std::string BuiltinSceneNames() {
  std::string names;
  for (const BuiltinScene& builtin : BuiltinScenes()) names += fmt::format(" {}", builtin.name);
  return names;
}

SceneDescription LoadSceneOrBuiltin(const std::string& scene) {
  if (const BuiltinScene* builtin = FindBuiltinScene(scene)) {
    return ParseScene(builtin->json, fmt::format("built-in scene '{}'", scene), "");
  }
  std::error_code not_a_file;
  if (std::filesystem::exists(scene, not_a_file)) return LoadScene(scene);
  throw InputError(fmt::format("'{}' is neither a built-in scene (one of:{}) nor a scene file", scene,
                               BuiltinSceneNames()));
}

}  // namespace lidarshop
