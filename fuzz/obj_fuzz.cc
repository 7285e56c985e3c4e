// libFuzzer target for the OBJ reader (ReadMesh): vertices, faces, texture coordinates, mtllib lines.
#include "fuzz/fuzz_util.h"
#include "lidarshop/io/mesh_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  lidarshop::fuzz::LimitMemory();
  const std::string path = lidarshop::fuzz::WriteInput(data, size, "obj");
  lidarshop::fuzz::Expect([&] { lidarshop::ReadMesh(path); });
  return 0;
}
