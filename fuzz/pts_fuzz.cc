// libFuzzer target for the PTS reader: the bytes as a .pts file through ReadScanFile
// (the point count against the file size, columns, numbers).
#include "fuzz/fuzz_util.h"
#include "lidarshop/io/scan_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  lidarshop::fuzz::LimitMemory();
  const std::string path = lidarshop::fuzz::WriteInput(data, size, "pts");
  lidarshop::fuzz::Expect([&] { lidarshop::ReadScanFile(path); });
  return 0;
}
