#include "lidarshop/recolor/correspondences.h"

#include <cmath>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

// A fixed-size array of finite numbers at pair[key].
template <int N>
Eigen::Matrix<double, N, 1> Vector(const nlohmann::json& pair, const char* key, const std::string& what,
                                   const std::string& place) {
  const auto it = pair.find(key);
  if (it == pair.end()) ThrowInputError(what, place, key, "missing");
  if (!it->is_array() || it->size() != N)
    ThrowInputError(what, place, key, fmt::format("expected {} numbers", N));
  Eigen::Matrix<double, N, 1> v;
  for (int i = 0; i < N; ++i) {
    if (!(*it)[i].is_number()) ThrowInputError(what, place, key, fmt::format("expected {} numbers", N));
    v[i] = (*it)[i].get<double>();
    if (!std::isfinite(v[i])) ThrowInputError(what, place, key, "non-finite number (NaN or infinity)");
  }
  return v;
}

Eigen::Vector3d CellPoint(const Scan* scan, const Eigen::Vector2d& cell, const std::string& what,
                          const std::string& place) {
  if (!scan) ThrowInputError(what, place, "cell", "scan cells need a scan (--scan SCAN)");
  const int row = static_cast<int>(cell.x()), col = static_cast<int>(cell.y());
  if (row != cell.x() || col != cell.y())
    ThrowInputError(what, place, "cell",
                    fmt::format("[{}, {}] is not a cell of the {} x {} scan", cell.x(), cell.y(), scan->rows,
                                scan->cols));
  return WorldPointOfCell(*scan, row, col, what, place);
}

}  // namespace

Correspondences ParseCorrespondences(const std::string& json_text, const std::string& what,
                                     const Scan* scan) {
  nlohmann::json json;
  try {
    json = nlohmann::json::parse(json_text);
  } catch (const nlohmann::json::exception& error) {
    ThrowInputError(what, "", "", fmt::format("not valid JSON: {}", error.what()));
  }
  if (!json.is_object() || !json.contains("pairs") || !json["pairs"].is_array())
    ThrowInputError(what, "", "pairs", "expected {\"pairs\": [...]}");
  Correspondences result;
  if (json.contains("image_size_px")) {
    const Eigen::Vector2d size = Vector<2>(json, "image_size_px", what, "");
    if (size.x() < 1 || size.y() < 1 || size.x() != std::floor(size.x()) || size.y() != std::floor(size.y()))
      ThrowInputError(what, "", "image_size_px", "expected two whole numbers >= 1");
    result.width_px = static_cast<int>(size.x());
    result.height_px = static_cast<int>(size.y());
  }
  const nlohmann::json& pairs = json["pairs"];
  for (size_t i = 0; i < pairs.size(); ++i) {
    const std::string place = fmt::format("pairs[{}]", i);
    const nlohmann::json& pair = pairs[i];
    if (!pair.is_object()) ThrowInputError(what, place, "", "expected an object");
    PairKind kind;
    if (pair.contains("source") || pair.contains("target")) {
      kind = PairKind::kLandmark;
      result.landmarks.push_back(
          {Vector<3>(pair, "source", what, place), Vector<3>(pair, "target", what, place)});
    } else if (pair.contains("pixel_a") || pair.contains("pixel_b")) {
      kind = PairKind::kPixelPixel;
      result.pixel_pixel.push_back(
          {Vector<2>(pair, "pixel_a", what, place), Vector<2>(pair, "pixel_b", what, place)});
    } else {
      kind = PairKind::kPixelPoint;
      const Eigen::Vector2d pixel = Vector<2>(pair, "pixel", what, place);
      if (pair.contains("cell")) {
        result.pixel_point.push_back(
            {pixel, CellPoint(scan, Vector<2>(pair, "cell", what, place), what, place)});
      } else {
        result.pixel_point.push_back({pixel, Vector<3>(pair, "point", what, place)});
      }
    }
    if (i == 0) result.kind = kind;
    if (kind != result.kind)
      ThrowInputError(what, place, "", "mixes kinds of pairs (pixel/point, source/target, pixel_a/pixel_b)");
  }
  return result;
}

Eigen::Vector3d WorldPointOfCell(const Scan& scan, int row, int col, const std::string& what,
                                 const std::string& place) {
  if (row < 0 || col < 0 || row >= scan.rows || col >= scan.cols)
    ThrowInputError(
        what, place, "cell",
        fmt::format("[{}, {}] is not a cell of the {} x {} scan", row, col, scan.rows, scan.cols));
  if (!scan.valid.at<uint8_t>(row, col))
    ThrowInputError(what, place, "cell", fmt::format("[{}, {}] has no return", row, col));
  return WorldPointOfCell(scan, row, col);
}

Correspondences ReadCorrespondences(const std::string& path, const Scan* scan) {
  std::ifstream stream(path, std::ios::binary);
  if (!stream) ThrowInputError(path, "", "", "cannot open the file");
  std::stringstream text;
  text << stream.rdbuf();
  return ParseCorrespondences(text.str(), path, scan);
}

std::string PixelPointPairsToJson(const std::vector<PixelPointPair>& pairs, int width_px, int height_px) {
  nlohmann::ordered_json json;
  if (width_px > 0) json["image_size_px"] = {width_px, height_px};
  json["pairs"] = nlohmann::ordered_json::array();
  for (const PixelPointPair& pair : pairs) {
    json["pairs"].push_back(
        {{"pixel", {pair.pixel_px.x(), pair.pixel_px.y()}},
         {"point", {pair.point_in_world.x(), pair.point_in_world.y(), pair.point_in_world.z()}}});
  }
  return json.dump(1) + "\n";
}

}  // namespace lidarshop
