#include "lidarshop/verify/pose_text.h"

#include <cmath>
#include <filesystem>
#include <sstream>

#include <fmt/format.h>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/input_file.h"
#include "lidarshop/verify/verify.h"

namespace lidarshop {

std::vector<double> ParseNumbers(const std::string& text, const std::string& what) {
  std::vector<double> numbers;
  std::string normalized = text;
  for (char& c : normalized) {
    if (c == ',' || c == ';' || c == '\n' || c == '\t' || c == '\r') c = ' ';
  }
  std::istringstream stream(normalized);
  std::string token;
  while (stream >> token) {
    size_t used = 0;
    double value = 0;
    try {
      value = std::stod(token, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != token.size() || !std::isfinite(value)) {
      throw InputError(fmt::format("{}: not a number: '{}'", what, token));
    }
    numbers.push_back(value);
  }
  return numbers;
}

Eigen::Matrix4d ParsePose(const std::string& text) {
  std::vector<double> numbers;
  std::string what = "--pose";
  std::error_code not_a_path;  // e.g. "File name too long" for 16 numbers: then it is pose text
  if (std::filesystem::exists(text,
                              not_a_path)) {  // stat only: a FIFO is refused by ReadRegularFile, never opened
    what = text;
    numbers = ParseNumbers(ReadRegularFile(text, int64_t{1} << 20), what);
    if (numbers.size() != 16) {
      throw InputError(
          fmt::format("{}: a pose file holds 4 rows of 4 numbers, found {} numbers", what, numbers.size()));
    }
  } else {
    numbers = ParseNumbers(text, what);
  }
  for (double number : numbers) {
    if (!std::isfinite(number)) throw InputError(fmt::format("{}: the pose holds a non-finite number", what));
  }
  if (numbers.size() == 4 || numbers.size() == 6) {
    if (std::abs(numbers[0]) > kMaxCoordinateM || std::abs(numbers[1]) > kMaxCoordinateM ||
        std::abs(numbers[2]) > kMaxCoordinateM) {
      throw InputError(fmt::format("{}: the position is beyond {} m", what, kMaxCoordinateM));
    }
    return PoseFromXyzYaw(numbers[0], numbers[1], numbers[2], numbers[3],
                          numbers.size() == 6 ? numbers[4] : 0.0, numbers.size() == 6 ? numbers[5] : 0.0);
  }
  if (numbers.size() != 16) {
    throw InputError(
        fmt::format("{}: expected a file of 4x4 numbers, 16 numbers or x,y,z,yaw_deg[,pitch_deg,roll_deg], "
                    "got {} numbers",
                    what, numbers.size()));
  }
  Eigen::Matrix4d pose;
  for (int i = 0; i < 16; ++i) pose(i / 4, i % 4) = numbers[i];
  if ((pose.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).norm() > 1e-9) {
    throw InputError(fmt::format("{}: the last row of world_from_model must be 0 0 0 1", what));
  }
  const std::string problem = PoseProblem(pose, /*allow_uniform_scale=*/true);
  if (!problem.empty()) throw InputError(fmt::format("{}: world_from_model {}", what, problem));
  return pose;
}

}  // namespace lidarshop
