// libFuzzer target for the header readers (io/scan_header.h, `lidarshop info` without --stats): the first
// byte picks the format (ptx, ply, pcd, las, e57), the rest is the file. For E57 the rest is a logical
// stream (pages without their CRCs) and the target adds the checksums, so that mutations reach the header
// and the XML section, as e57_fuzz does.
#include <cstdint>
#include <string>
#include <vector>

#include "fuzz/fuzz_util.h"
#include "lidarshop/io/e57_format.h"
#include "lidarshop/io/scan_header.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  lidarshop::fuzz::LimitMemory();
  lidarshop::e57::g_max_cells = int64_t{1} << 20;
  if (size == 0) return 0;
  static const char* kExtensions[] = {"ptx", "ply", "pcd", "las", "e57"};
  const std::string extension = kExtensions[data[0] % 5];
  std::vector<uint8_t> bytes(data + 1, data + size);
  if (extension == "e57") bytes = lidarshop::e57::PagesFromLogical(bytes);
  const std::string path = lidarshop::fuzz::WriteInput(bytes.data(), bytes.size(), extension);
  lidarshop::fuzz::Expect([&] { lidarshop::ReadScanHeader(path); });
  return 0;
}
