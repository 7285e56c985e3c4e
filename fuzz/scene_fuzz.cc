// libFuzzer target for scene JSON (ParseScene): every primitive and transform, checked for complexity and
// extent before any mesh is made. Mesh paths resolve in /tmp/lidarshop_fuzz_scene (empty).
#include <filesystem>

#include "fuzz/fuzz_util.h"
#include "lidarshop/scanner/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  lidarshop::fuzz::LimitMemory();
  static const std::string folder = [] {
    const std::string path = "/tmp/lidarshop_fuzz_scene";
    std::filesystem::create_directories(path);
    return path;
  }();
  const std::string text(reinterpret_cast<const char*>(data), size);
  lidarshop::fuzz::Expect([&] { lidarshop::ParseScene(text, "fuzz.json", folder); });
  return 0;
}
