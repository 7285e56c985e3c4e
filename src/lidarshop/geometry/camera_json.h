// Internal to the geometry module: the field readers the camera JSON files share (camera.cc, the pinhole
// file; camera_model.cc, every model). Errors name `what` (the file) and the field.
#pragma once

#include <string>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

namespace lidarshop::camera_json {

// The number `key` of `object`; 0 when absent and not `required`. InputError when missing (required) or not
// a number.
double NumberField(const nlohmann::json& object, const char* key, const std::string& what, bool required);

// "world_from_camera": 4 rows of 4 numbers (required).
Eigen::Matrix4d WorldFromCamera(const nlohmann::json& object, const std::string& what);

}  // namespace lidarshop::camera_json
