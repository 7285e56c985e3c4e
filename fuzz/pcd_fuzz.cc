// libFuzzer target for the PCD reader: the bytes as a .pcd file through ReadScanFile (format, header
// counts against the file size, numbers, poses).
#include "fuzz/fuzz_util.h"
#include "lidarshop/io/scan_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  lidarshop::fuzz::LimitMemory();
  const std::string path = lidarshop::fuzz::WriteInput(data, size, "pcd");
  lidarshop::fuzz::Expect([&] { lidarshop::ReadScanFile(path); });
  return 0;
}
