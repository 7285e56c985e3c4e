// libFuzzer target for mask pictures (ReadMask of a .png: signature and IEND checks, OpenCV's decoder within
// the pixel limit, size and depth checks). OpenCV and libpng are not instrumented: coverage is lidarshop's.
#include "fuzz/fuzz_util.h"
#include "lidarshop/io/image_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  lidarshop::fuzz::LimitMemory();
  const std::string path = lidarshop::fuzz::WriteInput(data, size, "png");
  lidarshop::fuzz::Expect([&] { lidarshop::ReadMask(path, cv::Size(48, 32), "fuzz"); });
  return 0;
}
