#include "lidarshop/io/ply_fields.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/io/io_common.h"
#include "lidarshop/util/error.h"

namespace lidarshop::io_internal {

const PlyElement& RequireElement(const PlyData& ply, const std::string& name, const std::string& file) {
  const PlyElement* element = ply.Find(name);
  if (element == nullptr) ThrowInputError(file, "header", "element " + name, "missing");
  return *element;
}

const PlyProperty* FindScalar(const PlyElement& element, std::initializer_list<const char*> names) {
  for (const char* name : names) {
    const PlyProperty* property = element.Find(name);
    if (property != nullptr && !property->is_list) return property;
  }
  return nullptr;
}

std::vector<Eigen::Vector3f> Vector3Property(const PlyElement& element, const char* a, const char* b,
                                             const char* c, const std::string& file, bool required) {
  const PlyProperty* pa = FindScalar(element, {a});
  const PlyProperty* pb = FindScalar(element, {b});
  const PlyProperty* pc = FindScalar(element, {c});
  if (pa == nullptr || pb == nullptr || pc == nullptr) {
    if (required) {
      ThrowInputError(file, "header", fmt::format("{} {} {} {}", element.name, a, b, c), "missing property");
    }
    return {};
  }
  std::vector<Eigen::Vector3f> values(element.count);
  for (int64_t i = 0; i < element.count; ++i) {
    values[i] = Eigen::Vector3f(static_cast<float>(pa->values[i]), static_cast<float>(pb->values[i]),
                                static_cast<float>(pc->values[i]));
  }
  return values;
}

std::vector<Rgb8> ColorProperty(const PlyElement& element) {
  const PlyProperty* channels[3] = {FindScalar(element, {"red", "r", "diffuse_red"}),
                                    FindScalar(element, {"green", "g", "diffuse_green"}),
                                    FindScalar(element, {"blue", "b", "diffuse_blue"})};
  if (channels[0] == nullptr || channels[1] == nullptr || channels[2] == nullptr) return {};
  const bool unit_floats = channels[0]->type == PlyType::kFloat32 || channels[0]->type == PlyType::kFloat64;
  const double scale = unit_floats ? 255.0 : 1.0;
  std::vector<Rgb8> colors(element.count);
  for (int64_t i = 0; i < element.count; ++i) {
    for (int k = 0; k < 3; ++k) {
      colors[i][k] = static_cast<uint8_t>(std::clamp(std::round(channels[k]->values[i] * scale), 0.0, 255.0));
    }
  }
  return colors;
}

void AddScalarProperty(PlyElement* element, const std::string& name, PlyType type,
                       std::vector<double> values) {
  PlyProperty property;
  property.name = name;
  property.type = type;
  property.values = std::move(values);
  element->properties.push_back(std::move(property));
}

void AddVector3Property(PlyElement* element, const std::vector<Eigen::Vector3f>& values, const char* a,
                        const char* b, const char* c, PlyType type) {
  const char* names[3] = {a, b, c};
  for (int k = 0; k < 3; ++k) {
    std::vector<double> column(values.size());
    for (size_t i = 0; i < values.size(); ++i) column[i] = values[i][k];
    AddScalarProperty(element, names[k], type, std::move(column));
  }
}

void AddColorProperty(PlyElement* element, const std::vector<Rgb8>& colors) {
  const char* names[3] = {"red", "green", "blue"};
  for (int k = 0; k < 3; ++k) {
    std::vector<double> column(colors.size());
    for (size_t i = 0; i < colors.size(); ++i) column[i] = colors[i][k];
    AddScalarProperty(element, names[k], PlyType::kUInt8, std::move(column));
  }
}

std::vector<Eigen::Vector3d> VertexPositions(const PlyElement& vertex, const std::string& file,
                                             std::vector<std::string>* warnings) {
  const PlyProperty* axes[3] = {FindScalar(vertex, {"x"}), FindScalar(vertex, {"y"}),
                                FindScalar(vertex, {"z"})};
  if (axes[0] == nullptr || axes[1] == nullptr) {
    ThrowInputError(file, "header", fmt::format("{} x y", vertex.name),
                    "missing property: the vertices have no x and y, they are not points");
  }
  if (axes[2] == nullptr && warnings != nullptr && vertex.count > 0) {
    warnings->push_back(fmt::format("{}: the {} element has no z property: every point is read with z = 0",
                                    file, vertex.name));
  }
  std::vector<Eigen::Vector3d> positions(vertex.count, Eigen::Vector3d::Zero());
  for (int axis = 0; axis < 3; ++axis) {
    if (axes[axis] == nullptr) continue;
    for (int64_t i = 0; i < vertex.count; ++i) {
      const double value = axes[axis]->values[i];
      if (!(std::abs(value) <= kMaxCoordinateM)) {
        ThrowInputError(file, fmt::format("{} {}", vertex.name, i), std::string(1, "xyz"[axis]),
                        fmt::format("{} is not a coordinate within {} m", value, kMaxCoordinateM));
      }
      positions[i][axis] = value;
    }
  }
  return positions;
}

PointCloud PointCloudFromPly(const PlyData& ply, const std::string& file, bool require_positions) {
  const PlyElement& vertex = RequireElement(ply, "vertex", file);
  PointCloud cloud;
  cloud.points = Vector3Property(vertex, "x", "y", "z", file, require_positions);
  cloud.normals = Vector3Property(vertex, "nx", "ny", "nz", file, false);
  cloud.colors = ColorProperty(vertex);
  if (const PlyProperty* p = FindScalar(vertex, {"intensity", "scalar_intensity", "scalar_Intensity"})) {
    cloud.intensities.assign(p->values.begin(), p->values.end());
  }
  if (const PlyProperty* p = FindScalar(vertex, {"label", "scalar_label", "class", "classification"})) {
    cloud.labels.reserve(p->values.size());
    for (double value : p->values) cloud.labels.push_back(ToInt32(value, kNoLabel));
  }
  if (const PlyProperty* p = FindScalar(vertex, {"synthesized"})) {
    cloud.synthesized.reserve(p->values.size());
    for (double value : p->values) cloud.synthesized.push_back(value != 0 ? 1 : 0);
  }
  return cloud;
}

PlyElement VertexElementFromCloud(const PointCloud& cloud, bool double_positions) {
  PlyElement vertex{"vertex", static_cast<int64_t>(cloud.size()), {}};
  AddVector3Property(&vertex, cloud.points, "x", "y", "z",
                     double_positions ? PlyType::kFloat64 : PlyType::kFloat32);
  if (!cloud.normals.empty()) AddVector3Property(&vertex, cloud.normals, "nx", "ny", "nz");
  if (!cloud.colors.empty()) AddColorProperty(&vertex, cloud.colors);
  if (!cloud.intensities.empty()) {
    AddScalarProperty(&vertex, "intensity", PlyType::kFloat32,
                      std::vector<double>(cloud.intensities.begin(), cloud.intensities.end()));
  }
  if (!cloud.labels.empty()) {
    AddScalarProperty(&vertex, "label", PlyType::kInt32,
                      std::vector<double>(cloud.labels.begin(), cloud.labels.end()));
  }
  if (!cloud.synthesized.empty()) {
    AddScalarProperty(&vertex, "synthesized", PlyType::kUInt8,
                      std::vector<double>(cloud.synthesized.begin(), cloud.synthesized.end()));
  }
  return vertex;
}

}  // namespace lidarshop::io_internal
