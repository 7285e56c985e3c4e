// libFuzzer target for the E57 reader (fuzz/run_e57_fuzz.sh builds and runs it).
//
// The input is an E57 file's *logical* byte stream (pages without their CRCs): the target adds the checksums,
// so that mutations reach the XML, section and codec layers instead of failing at the first page. Inputs
// whose size is a whole number of pages are also read as they are, which exercises the CRC layer. An
// InputError is the expected outcome for broken input; anything else (another exception, a sanitizer report,
// a crash) is a bug.
#include <cstdint>
#include <vector>

#include "lidarshop/io/e57.h"
#include "lidarshop/io/e57_format.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/memory_budget.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  lidarshop::e57::g_max_cells = int64_t{1} << 20;  // keep allocations within the fuzzer's memory limit
  lidarshop::SetMemoryBudgetBytes(int64_t{256} << 20);
  const std::vector<uint8_t> logical(data, data + size);
  try {
    lidarshop::ReadE57Bytes(lidarshop::e57::PagesFromLogical(logical), "fuzz.e57");
  } catch (const lidarshop::InputError&) {
  }
  if (size > 0 && size % lidarshop::e57::kPageSize == 0) {
    try {
      lidarshop::ReadE57Bytes(logical, "fuzz_raw.e57");
    } catch (const lidarshop::InputError&) {
    }
  }
  return 0;
}
