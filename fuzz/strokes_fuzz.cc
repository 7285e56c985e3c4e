// libFuzzer target for stroke JSON (StrokesFromJson) on a 48 x 32 scan grid.
#include "fuzz/fuzz_util.h"
#include "lidarshop/render/strokes.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  lidarshop::fuzz::LimitMemory();
  const std::string text(reinterpret_cast<const char*>(data), size);
  lidarshop::fuzz::Expect([&] { lidarshop::StrokesFromJson(text, 32, 48, "fuzz.json"); });
  return 0;
}
