// libFuzzer target for pose files and --pose text (ParsePose): 4 x 4 matrices, 16 numbers or
// x,y,z,yaw[,pitch,roll], each checked to be a rotation times one scale within kMaxCoordinateM.
#include "fuzz/fuzz_util.h"
#include "lidarshop/verify/pose_text.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  lidarshop::fuzz::LimitMemory();
  const std::string path = lidarshop::fuzz::WriteInput(data, size, "txt");
  lidarshop::fuzz::Expect([&] { lidarshop::ParsePose(path); });  // as a pose file
  const std::string text(reinterpret_cast<const char*>(data), size);
  if (text.find('/') == std::string::npos) {  // as --pose text (never a path of this machine)
    lidarshop::fuzz::Expect([&] { lidarshop::ParsePose(text); });
  }
  return 0;
}
