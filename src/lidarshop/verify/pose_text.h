// Poses and number lists as the command line, pose files and the HTTP API give them: the one place where
// pose text and pose JSON become a world_from_model (`verify --pose`, `points transform --matrix`, the
// server's verify route). Angles become a rotation only through geometry/transform.h's
// RotationFromEulerDegrees: R = Rz(yaw) · Ry(pitch) · Rx(roll).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

namespace lidarshop {

// Numbers separated by spaces, commas, semicolons or line breaks. Throws InputError naming `what` for a
// token that is not a finite number.
std::vector<double> ParseNumbers(const std::string& text, const std::string& what);

// A world_from_model from `text`, which is one of
//   x,y,z,yaw_deg[,pitch_deg,roll_deg]   metres and degrees (PoseFromXyzYaw, verify/verify.h)
//   16 numbers                           the 4 x 4 matrix, row major (commas, spaces or line breaks)
//   the path of a pose file              a regular file of at most 1 MiB holding 4 rows of 4 numbers, or a
//                                        JSON object as PoseFromJson reads it
// Throws InputError naming `what` (the flag) or the file for anything else, for a pose that is not a rotation
// times one uniform scale, or for a position beyond kMaxCoordinateM.
Eigen::Matrix4d ParsePose(const std::string& text, const std::string& what = "--pose");

// A world_from_model from a JSON object, one of
//   {"x_m": 1, "y_m": 2, "z_m": 0, "yaw_deg": 90, "pitch_deg": 0, "roll_deg": 0}   every key optional,
//                                                                                    default 0
//   {"world_from_model": [[r00, r01, r02, tx], [...], [...], [0, 0, 0, 1]]}         4 rows of 4 numbers
// Throws OptionsFieldError (util/options.h) naming the key, e.g. "x_m: expected a number, got \"left\"", for
// a value of the wrong kind, an unknown key, a pose that is not a rotation times one uniform scale, or a
// position beyond kMaxCoordinateM.
Eigen::Matrix4d PoseFromJson(const nlohmann::json& pose);

}  // namespace lidarshop
