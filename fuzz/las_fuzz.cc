// libFuzzer target for the LAS reader: the bytes as a .las file through ReadScanFile (header fields against
// the file size, numbers, poses).
#include "fuzz/fuzz_util.h"
#include "lidarshop/io/scan_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  lidarshop::fuzz::LimitMemory();
  const std::string path = lidarshop::fuzz::WriteInput(data, size, "las");
  lidarshop::fuzz::Expect([&] { lidarshop::ReadScanFile(path); });
  return 0;
}
