#include "lidarshop/verify/pose_text.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iterator>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/input_file.h"
#include "lidarshop/util/options.h"
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

namespace {

// A pose that is fine as numbers but not as a pose: its problem in words, or "" (PoseProblem, plus the
// last row and the position limit checked first so that their messages are the plainest).
std::string MatrixPoseProblem(const Eigen::Matrix4d& pose) {
  if (!pose.allFinite()) return "the pose holds a non-finite number";
  if ((pose.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).norm() > 1e-9) {
    return "the last row of world_from_model must be 0 0 0 1";
  }
  const std::string problem = PoseProblem(pose, /*allow_uniform_scale=*/true);
  return problem.empty() ? "" : "world_from_model " + problem;
}

Eigen::Matrix4d PoseFromNumbers(const std::vector<double>& numbers, const std::string& what) {
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
  const std::string problem = MatrixPoseProblem(pose);
  if (!problem.empty()) throw InputError(fmt::format("{}: {}", what, problem));
  return pose;
}

double PoseNumber(const nlohmann::json& value, const std::string& key) {
  if (!value.is_number() || !std::isfinite(value.get<double>())) {
    throw OptionsFieldError(key, fmt::format("expected a number, got {}", value.dump()));
  }
  return value.get<double>();
}

}  // namespace

Eigen::Matrix4d ParsePose(const std::string& text, const std::string& what) {
  std::error_code not_a_path;  // e.g. "File name too long" for 16 numbers: then it is pose text
  // stat only: a FIFO is refused by ReadRegularFile, never opened.
  if (!std::filesystem::exists(text, not_a_path)) return PoseFromNumbers(ParseNumbers(text, what), what);
  const std::string contents = ReadRegularFile(text, int64_t{1} << 20);
  const size_t first = contents.find_first_not_of(" \t\r\n");
  if (first != std::string::npos && contents[first] == '{') {
    nlohmann::json json;
    try {
      json = nlohmann::json::parse(contents);
    } catch (const nlohmann::json::exception& error) {  // a syntax error, or a number past double's range
      throw InputError(fmt::format("{}: not JSON: {}", text, error.what()));
    }
    try {
      return PoseFromJson(json);
    } catch (const OptionsFieldError& error) {
      throw InputError(fmt::format("{}: {}", text, error.what()));
    }
  }
  const std::vector<double> numbers = ParseNumbers(contents, text);
  if (numbers.size() != 16) {
    throw InputError(
        fmt::format("{}: a pose file holds 4 rows of 4 numbers, found {} numbers", text, numbers.size()));
  }
  return PoseFromNumbers(numbers, text);
}

Eigen::Matrix4d PoseFromJson(const nlohmann::json& pose) {
  if (!pose.is_object()) {
    throw OptionsFieldError("pose", fmt::format("expected an object, got {}", pose.dump()));
  }
  if (pose.contains("world_from_model")) {
    if (pose.size() != 1) {
      throw OptionsFieldError("world_from_model", "give either world_from_model or x_m, y_m, z_m and angles");
    }
    const nlohmann::json& rows = pose.at("world_from_model");
    if (!rows.is_array() || rows.size() != 4) {
      throw OptionsFieldError("world_from_model", "expected 4 rows of 4 numbers");
    }
    Eigen::Matrix4d matrix;
    for (int r = 0; r < 4; ++r) {
      if (!rows[r].is_array() || rows[r].size() != 4) {
        throw OptionsFieldError("world_from_model", "expected 4 rows of 4 numbers");
      }
      for (int c = 0; c < 4; ++c) {
        matrix(r, c) = PoseNumber(rows[r][c], fmt::format("world_from_model[{}][{}]", r, c));
      }
    }
    const std::string problem = PoseProblem(matrix, /*allow_uniform_scale=*/true);
    if (!problem.empty()) throw OptionsFieldError("world_from_model", problem);
    return matrix;
  }
  static const char* const kKeys[] = {"x_m", "y_m", "z_m", "yaw_deg", "pitch_deg", "roll_deg"};
  double values[6] = {0, 0, 0, 0, 0, 0};
  for (const auto& [key, value] : pose.items()) {
    const auto known = std::find(std::begin(kKeys), std::end(kKeys), key);
    if (known == std::end(kKeys)) {
      throw OptionsFieldError(
          key, "unknown key (x_m, y_m, z_m, yaw_deg, pitch_deg, roll_deg or world_from_model)");
    }
    values[known - std::begin(kKeys)] = PoseNumber(value, key);
  }
  for (int i = 0; i < 3; ++i) {
    if (std::abs(values[i]) > kMaxCoordinateM) {
      throw OptionsFieldError(kKeys[i], fmt::format("beyond {} m", kMaxCoordinateM));
    }
  }
  return PoseFromXyzYaw(values[0], values[1], values[2], values[3], values[4], values[5]);
}

}  // namespace lidarshop
