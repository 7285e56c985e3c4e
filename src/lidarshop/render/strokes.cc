#include "lidarshop/render/strokes.h"

#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "lidarshop/io/image_io.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/input_file.h"
#include "lidarshop/util/json_input.h"
#include "lidarshop/util/options.h"

namespace lidarshop {

cv::Mat StrokesFromImage(const cv::Mat& painted, const std::string& what) {
  if (painted.depth() != CV_8U || (painted.channels() != 3 && painted.channels() != 4)) {
    ThrowInputError(what, "", "", "a stroke image must be 8-bit RGB or RGBA");
  }
  cv::Mat strokes(painted.rows, painted.cols, CV_8U, cv::Scalar(kStrokeNone));
  const int channels = painted.channels();
  for (int row = 0; row < painted.rows; ++row) {
    const uint8_t* in = painted.ptr<uint8_t>(row);
    uint8_t* out = strokes.ptr<uint8_t>(row);
    for (int col = 0; col < painted.cols; ++col) {
      const uint8_t* px = in + col * channels;
      if (channels == 4 && px[3] < 128) continue;
      const int r = px[0], g = px[1], b = px[2];
      if (g >= 160 && r <= 96 && b <= 96)
        out[col] = kStrokeObject;
      else if (r >= 160 && g <= 96 && b <= 96)
        out[col] = kStrokeBackground;
    }
  }
  return strokes;
}

cv::Mat StrokesFromJson(const std::string& json_text, int rows, int cols, const std::string& what) {
  const nlohmann::json doc = ParseJsonInput(json_text, what);
  if (!doc.is_object() || !doc.contains("strokes") || !doc["strokes"].is_array()) {
    ThrowInputError(what, "", "strokes", "expected an object with an array \"strokes\"");
  }
  cv::Mat strokes(rows, cols, CV_8U, cv::Scalar(kStrokeNone));
  const nlohmann::json& list = doc["strokes"];
  for (size_t k = 0; k < list.size(); ++k) {
    const nlohmann::json& stroke = list[k];
    const std::string place = fmt::format("stroke {}", k);
    if (!stroke.is_object()) ThrowInputError(what, place, "", "a stroke must be an object");
    if (!stroke.contains("label") || !stroke["label"].is_string()) {
      ThrowInputError(what, place, "label", "missing or not a string");
    }
    const std::string label = stroke["label"].get<std::string>();
    uint8_t value = kStrokeNone;
    if (label == "object" || label == "foreground")
      value = kStrokeObject;
    else if (label == "background")
      value = kStrokeBackground;
    else
      ThrowInputError(what, place, "label",
                      fmt::format("must be \"object\" or \"background\", got \"{}\"", label));
    int width = 1;
    if (stroke.contains("width")) {
      if (!stroke["width"].is_number_integer() || stroke["width"].get<int>() < 1 ||
          stroke["width"].get<int>() > 255) {
        ThrowInputError(what, place, "width", "must be an integer in [1, 255]");
      }
      width = stroke["width"].get<int>();
    }
    if (!stroke.contains("points") || !stroke["points"].is_array() || stroke["points"].empty()) {
      ThrowInputError(what, place, "points", "missing, not an array, or empty");
    }
    std::vector<cv::Point> points;
    for (size_t j = 0; j < stroke["points"].size(); ++j) {
      const nlohmann::json& p = stroke["points"][j];
      const std::string field = fmt::format("points[{}]", j);
      if (!p.is_array() || p.size() != 2 || !p[0].is_number() || !p[1].is_number()) {
        ThrowInputError(what, place, field, "must be a [col, row] pair of numbers");
      }
      const double col = p[0].get<double>(), row = p[1].get<double>();
      if (!(col >= 0 && col <= cols - 1 && row >= 0 && row <= rows - 1)) {
        ThrowInputError(
            what, place, field,
            fmt::format("[{}, {}] lies outside the {} x {} image (cols x rows)", col, row, cols, rows));
      }
      points.emplace_back(static_cast<int>(std::lround(col)), static_cast<int>(std::lround(row)));
    }
    if (points.size() == 1) points.push_back(points[0]);
    for (size_t j = 0; j + 1 < points.size(); ++j) {
      cv::line(strokes, points[j], points[j + 1], cv::Scalar(value), width, cv::LINE_8);
    }
  }
  return strokes;
}

cv::Mat ReadStrokes(const std::string& path, int rows, int cols) {
  cv::Mat strokes;
  if (FileExtension(path) == "json") {
    constexpr int64_t kMaxStrokeFileBytes = int64_t{64} << 20;
    strokes = StrokesFromJson(ReadRegularFile(path, kMaxStrokeFileBytes), rows, cols, path);
  } else {
    // The size is compared from the image's header, before decoding.
    cv::Mat painted =
        ReadImage(path, cv::Size(cols, rows), "the scan's grid (a stroke image has one pixel per ray)");
    if (painted.depth() != CV_8U) ThrowInputError(path, "", "", "a stroke image must be 8-bit");
    strokes = StrokesFromImage(painted, path);
  }
  return strokes;
}

std::string PaintedStrokes::Describe() const {
  const std::string cells_text =
      fmt::format("{} object and {} background cells", cv::countNonZero(cells == kStrokeObject),
                  cv::countNonZero(cells == kStrokeBackground));
  if (!mapping) return fmt::format("strokes on the scan's grid: {}", cells_text);
  return fmt::format("strokes painted on a {} x {} {} picture: {}", mapping->image_size.width,
                     mapping->image_size.height, ToString(mapping->view), cells_text);
}

PaintedStrokes ReadStrokesForScan(const std::string& path, const Scan& scan, const std::string& layout_path,
                                  const std::string& what_scan) {
  PaintedStrokes strokes;
  if (FileExtension(path) == "json") {
    strokes.cells = ReadStrokes(path, scan.rows, scan.cols);
    return strokes;
  }
  const cv::Mat painted = ReadImage(path);
  if (painted.depth() != CV_8U) ThrowInputError(path, "", "", "a stroke image must be 8-bit");
  const cv::Mat labels = StrokesFromImage(painted, path);
  strokes.mapping = FindPictureMapping(scan, path, labels.size(), layout_path, what_scan);
  if (!strokes.mapping) {
    strokes.cells = labels;
    return strokes;
  }
  strokes.cells = CellsFromPicture(scan, *strokes.mapping, labels);
  strokes.picture = labels(cv::Rect(cv::Point(0, 0), strokes.mapping->picture_size)).clone();
  return strokes;
}

cv::Mat StrokesToImage(const cv::Mat& strokes) {
  cv::Mat image(strokes.rows, strokes.cols, CV_8UC3, cv::Scalar(0, 0, 0));
  image.setTo(cv::Scalar(0, 255, 0), strokes == kStrokeObject);
  image.setTo(cv::Scalar(255, 0, 0), strokes == kStrokeBackground);
  return image;
}

}  // namespace lidarshop
