// libFuzzer target for the XYZ reader: the bytes as a .xyz file through ReadScanFile
// (columns, numbers, coordinates).
#include "fuzz/fuzz_util.h"
#include "lidarshop/io/scan_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  lidarshop::fuzz::LimitMemory();
  const std::string path = lidarshop::fuzz::WriteInput(data, size, "xyz");
  lidarshop::fuzz::Expect([&] { lidarshop::ReadScanFile(path); });
  return 0;
}
