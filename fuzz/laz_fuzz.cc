// libFuzzer target for the LAZ reader: the bytes as a .laz file through ReadScanFile (the LAS header, the
// laszip VLR, the chunk table and LASzip's arithmetic-coded chunks; seeded with the shared interop LAZ files).
#include "fuzz/fuzz_util.h"
#include "lidarshop/io/scan_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  lidarshop::fuzz::LimitMemory();
  const std::string path = lidarshop::fuzz::WriteInput(data, size, "laz");
  lidarshop::fuzz::Expect([&] { lidarshop::ReadScanFile(path); });
  return 0;
}
