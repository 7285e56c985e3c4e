// Pose and number lists as the command line and pose files give them (`verify --pose`).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace lidarshop {

// Numbers separated by spaces, commas, semicolons or line breaks. Throws InputError naming `what` for a
// token that is not a finite number.
std::vector<double> ParseNumbers(const std::string& text, const std::string& what);

// A world_from_model from `text`: the path of a pose file (4 rows of 4 numbers; a regular file of at most
// 1 MiB), 16 comma-separated numbers (row major), or x,y,z,yaw_deg[,pitch_deg,roll_deg]. Throws InputError
// for a pose that is not a rotation times one uniform scale, or lies beyond kMaxCoordinateM.
Eigen::Matrix4d ParsePose(const std::string& text);

}  // namespace lidarshop
