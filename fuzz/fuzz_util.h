// Shared by the libFuzzer targets of fuzz/: each target hands the fuzzer's bytes to one reader through its
// public entry point. InputError and OptionsError are the expected outcomes of broken input; any other
// exception escapes and libFuzzer reports it, like a crash, a sanitizer report or a leak.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <string>

#include "lidarshop/util/error.h"
#include "lidarshop/util/memory_budget.h"

namespace lidarshop::fuzz {

// Keeps the readers' allocations below libFuzzer's -rss_limit_mb (scripts/fuzz.sh: this budget + 200 MB +
// AddressSanitizer's own): a request past 256 MiB must become an InputError, which is exactly what the budget
// promises. (Images: io/image_io.h checks the header's size against the budget before decoding; OpenCV's
// OPENCV_IO_MAX_IMAGE_PIXELS is read when OpenCV loads, before this could set it.)
inline void LimitMemory() {
  static const bool set = [] {
    SetMemoryBudgetBytes(int64_t{256} << 20);  // scripts/fuzz.sh's -rss_limit_mb counts on this value
    return true;
  }();
  (void)set;
}

// Writes `data` to a file in /tmp with the extension `extension` (the readers pick the format from it) and
// returns its path; the same path is reused by every input of one process.
inline std::string WriteInput(const uint8_t* data, size_t size, const std::string& extension) {
  const std::string path = "/tmp/lidarshop_fuzz_" + std::to_string(getpid()) + "." + extension;
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (file == nullptr) __builtin_trap();
  if (size > 0) std::fwrite(data, 1, size, file);
  std::fclose(file);
  return path;
}

// Runs `read`, swallowing the two documented error kinds only.
template <typename Read>
void Expect(Read read) {
  try {
    read();
  } catch (const InputError&) {
  } catch (const OptionsError&) {
  }
}

}  // namespace lidarshop::fuzz
