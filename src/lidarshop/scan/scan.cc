#include "lidarshop/scan/scan.h"

#include <cmath>
#include <cstring>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

#include "lidarshop/scan/ray_directions.h"
#include "lidarshop/scan/rgbd_cell.h"
#include "lidarshop/scan/scan_channels.h"
#include "lidarshop/scan/scan_window.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop {

double AzimuthOf(const Eigen::Vector3f& direction) { return std::atan2(direction.x(), direction.y()); }

double ElevationOf(const Eigen::Vector3f& direction) {
  const double norm = direction.norm();
  if (norm == 0) return 0.0;
  return std::asin(std::clamp(direction.z() / norm, -1.0, 1.0));
}

double WrapAngle(double angle_rad) {
  double wrapped = std::fmod(angle_rad + M_PI, 2.0 * M_PI);
  if (wrapped < 0) wrapped += 2.0 * M_PI;
  return wrapped - M_PI;
}

ScanGrid GridOf(const Scan& scan) {
  if (static_cast<int>(scan.grid.azimuth_rad.size()) == scan.cols &&
      static_cast<int>(scan.grid.elevation_rad.size()) == scan.rows) {
    return scan.grid;
  }
  if (scan.direction.empty() && scan.num_cells() > 0)
    throw InputError(fmt::format("scan '{}': no ray directions and no complete grid", scan.name));
  // The k-th cell out from the middle of `count`: middle, middle - 1, middle + 1, ... (wrapping).
  auto outward = [](int k, int count) {
    return (count / 2 + (k % 2 == 0 ? k / 2 : -(k + 1) / 2) + count) % count;
  };
  auto direction_at = [&](int r, int c) {
    const cv::Vec3f d = scan.direction.at<cv::Vec3f>(r, c);
    return Eigen::Vector3f(d[0], d[1], d[2]);
  };
  ScanGrid grid;
  grid.azimuth_rad.resize(static_cast<size_t>(scan.cols));
  for (int c = 0; c < scan.cols; ++c) {
    bool found = false;
    for (int k = 0; k < scan.rows && !found; ++k) {
      const Eigen::Vector3f d = direction_at(outward(k, scan.rows), c);
      if (d.squaredNorm() > 0) {
        grid.azimuth_rad[static_cast<size_t>(c)] = AzimuthOf(d);
        found = true;
      }
    }
    if (!found) throw InputError(fmt::format("scan '{}': column {} has no ray direction", scan.name, c));
  }
  grid.elevation_rad.resize(static_cast<size_t>(scan.rows));
  for (int r = 0; r < scan.rows; ++r) {
    bool found = false;
    for (int k = 0; k < scan.cols && !found; ++k) {
      const Eigen::Vector3f d = direction_at(r, outward(k, scan.cols));
      if (d.squaredNorm() > 0) {
        grid.elevation_rad[static_cast<size_t>(r)] = ElevationOf(d);
        found = true;
      }
    }
    if (!found) throw InputError(fmt::format("scan '{}': row {} has no ray direction", scan.name, r));
  }
  return grid;
}

int64_t Scan::CountValid() const { return valid.empty() ? 0 : cv::countNonZero(valid); }

Scan Clone(const Scan& scan) {
  Scan copy = scan;
  for (cv::Mat* channel :
       {&copy.direction, &copy.valid, &copy.range, &copy.point, &copy.intensity, &copy.color, &copy.label,
        &copy.normal, &copy.curvature, &copy.true_range, &copy.synthesized, &copy.from_station}) {
    *channel = channel->clone();
  }
  for (auto& [name, values] : copy.attributes) values = values.clone();
  return copy;
}

Scan MaskScan(const Scan& scan, const cv::Mat& keep_mask) {
  CheckScan(scan);
  if (keep_mask.rows != scan.rows || keep_mask.cols != scan.cols || keep_mask.type() != CV_8U) {
    throw std::logic_error("MaskScan: the mask must be CV_8U of the scan's size");
  }
  Scan masked = Clone(scan);
  const cv::Mat drop = keep_mask == 0;
  // Each channel gets its own no-return value (see MakeScan); `direction` stays: every cell keeps its ray.
  masked.valid.setTo(0, drop);
  masked.range.setTo(0, drop);
  masked.point.setTo(cv::Scalar::all(0), drop);
  if (!masked.intensity.empty()) masked.intensity.setTo(0.5, drop);
  if (!masked.color.empty()) masked.color.setTo(cv::Scalar::all(0), drop);
  if (!masked.label.empty()) masked.label.setTo(kNoLabel, drop);
  if (!masked.normal.empty()) masked.normal.setTo(cv::Scalar::all(0), drop);
  if (!masked.curvature.empty()) masked.curvature.setTo(NAN, drop);
  if (!masked.true_range.empty()) masked.true_range.setTo(0, drop);
  if (!masked.synthesized.empty()) masked.synthesized.setTo(0, drop);
  if (!masked.from_station.empty()) masked.from_station.setTo(0, drop);
  for (auto& [name, values] : masked.attributes) values.setTo(cv::Scalar::all(0), drop);
  return masked;
}

namespace {

using scan_internal::ForEachChannel;

void CheckWindow(const Scan& scan, const cv::Rect& window, const char* what) {
  if (window.x < 0 || window.y < 0 || window.width < 0 || window.height < 0 ||
      window.x + window.width > scan.cols || window.y + window.height > scan.rows) {
    throw std::logic_error(std::string(what) + ": the window is not inside the scan");
  }
}

}  // namespace

namespace {

// CropScan's cells as copies (`copy`) or as regions of the scan's buffers.
Scan CropCells(const Scan& scan, const cv::Rect& window, bool copy, const char* caller) {
  CheckScan(scan);
  CheckWindow(scan, window, caller);
  Scan part = scan_internal::ResampledScan(scan, window.height, window.width, [&](const cv::Mat& channel) {
    return copy ? channel(window).clone() : channel(window);
  });
  if (static_cast<int>(scan.grid.azimuth_rad.size()) == scan.cols &&
      static_cast<int>(scan.grid.elevation_rad.size()) == scan.rows) {
    part.grid = scan.grid;
    part.grid.azimuth_rad.assign(scan.grid.azimuth_rad.begin() + window.x,
                                 scan.grid.azimuth_rad.begin() + window.x + window.width);
    part.grid.elevation_rad.assign(scan.grid.elevation_rad.begin() + window.y,
                                   scan.grid.elevation_rad.begin() + window.y + window.height);
  }
  return part;
}

}  // namespace

Scan CropScan(const Scan& scan, const cv::Rect& window) { return CropCells(scan, window, true, "CropScan"); }

Scan CropScanView(const Scan& scan, const cv::Rect& window) {
  return CropCells(scan, window, false, "CropScanView");
}

namespace {

// PasteScan and PasteScanCopyOnWrite: with `copy_on_write` a channel whose window already holds the part's
// values is left as it is, and any other is copied before it is written.
void PasteChannels(const Scan& part, const cv::Rect& window, bool copy_on_write, const char* what,
                   Scan* scan) {
  CheckWindow(*scan, window, what);
  if (part.rows != window.height || part.cols != window.width)
    throw std::logic_error(fmt::format("{}: the part's size differs from the window's", what));
  // A scan that holds no direction image has its grid's rays (ray_directions.h): an edit never changes a ray,
  // and a part's directions would otherwise become a station-sized image.
  const bool rays_from_grid = scan->direction.empty() && HasCompleteGrid(*scan);
  const auto paste = [&](const cv::Mat& values, cv::Mat* target, const cv::Scalar& none) {
    if (values.empty() || (rays_from_grid && target == &scan->direction)) return;
    if (target->empty()) {
      *target = cv::Mat(scan->rows, scan->cols, values.type(), none);
    } else if (copy_on_write) {
      const cv::Mat current = (*target)(window);
      // Equal bytes (a NaN equals itself here, unlike cv::compare): nothing to write, the buffer stays shared.
      bool same = current.type() == values.type();
      for (int row = 0; same && row < window.height; ++row)
        same = std::memcmp(current.ptr(row), values.ptr(row), values.cols * values.elemSize()) == 0;
      if (same) return;
      *target = target->clone();
    }
    values.copyTo((*target)(window));
  };
  std::vector<std::pair<cv::Mat*, cv::Scalar>> targets;
  ForEachChannel(*scan,
                 [&](cv::Mat& channel, const cv::Scalar& none) { targets.emplace_back(&channel, none); });
  size_t i = 0;
  ForEachChannel(part, [&](const cv::Mat& channel, const cv::Scalar&) {
    auto& [target, none] = targets[i++];
    paste(channel, target, none);
  });
  for (const auto& [name, values] : part.attributes)
    paste(values, &scan->attributes[name], cv::Scalar::all(0));
}

}  // namespace

void PasteScan(const Scan& part, const cv::Rect& window, Scan* scan) {
  PasteChannels(part, window, /*copy_on_write=*/false, "PasteScan", scan);
}

void PasteScanCopyOnWrite(const Scan& part, const cv::Rect& window, Scan* scan) {
  PasteChannels(part, window, /*copy_on_write=*/true, "PasteScanCopyOnWrite", scan);
}

Scan MakeScan(int rows, int cols, bool with_color, bool with_intensity) {
  if (rows < 0 || cols < 0) throw std::logic_error("MakeScan: negative size");
  Scan scan = MakeScanWithoutDirections(rows, cols, with_color, with_intensity);
  scan.direction = cv::Mat(rows, cols, CV_32FC3, cv::Scalar::all(0));
  return scan;
}

void CheckScan(const Scan& scan) {
  auto check = [&](const cv::Mat& channel, int type, const char* name, bool required) {
    if (channel.empty()) {
      if (required && scan.rows * scan.cols > 0) {
        throw std::logic_error(std::string("scan channel missing: ") + name);
      }
      return;
    }
    if (channel.rows != scan.rows || channel.cols != scan.cols || channel.type() != type) {
      throw std::logic_error(std::string("scan channel has the wrong size or type: ") + name);
    }
  };
  // Empty: the rays are the grid's (ray_directions.h), or not known yet to a reader that fits the grid.
  check(scan.direction, CV_32FC3, "direction", false);
  check(scan.valid, CV_8U, "valid", true);
  check(scan.range, CV_32F, "range", true);
  check(scan.point, CV_32FC3, "point", true);
  check(scan.intensity, CV_32F, "intensity", false);
  check(scan.color, CV_8UC3, "color", false);
  check(scan.label, CV_32S, "label", false);
  check(scan.normal, CV_32FC3, "normal", false);
  check(scan.curvature, CV_32F, "curvature", false);
  check(scan.true_range, CV_32F, "true_range", false);
  check(scan.synthesized, CV_8U, "synthesized", false);
  check(scan.from_station, CV_8U, "from_station", false);
  for (const auto& [name, values] : scan.attributes) {
    if (values.rows != scan.rows || values.cols != scan.cols) {
      throw std::logic_error("scan attribute has the wrong size: " + name);
    }
  }
}

std::vector<std::string> ChannelNames(const Scan& scan) {
  std::vector<std::string> names = {"xyz", "range"};
  if (!scan.intensity.empty()) names.push_back("intensity");
  names.push_back("valid");
  names.push_back("direction");
  if (!scan.color.empty()) names.push_back("rgb");
  if (!scan.label.empty()) names.push_back("label");
  if (!scan.normal.empty()) names.push_back("normal");
  if (!scan.curvature.empty()) names.push_back("curvature");
  if (!scan.true_range.empty()) names.push_back("true_range");
  if (!scan.synthesized.empty()) names.push_back("synthesized");
  if (!scan.from_station.empty()) names.push_back("from_station");
  return names;
}

ScanGrid UniformGrid(int rows, int cols, double azimuth_min_rad, double azimuth_max_rad,
                     double elevation_min_rad, double elevation_max_rad) {
  ScanGrid grid;
  grid.azimuth_rad.resize(cols);
  grid.elevation_rad.resize(rows);
  const double azimuth_step = cols > 1 ? (azimuth_max_rad - azimuth_min_rad) / (cols - 1) : 0.0;
  const double elevation_step = rows > 1 ? (elevation_max_rad - elevation_min_rad) / (rows - 1) : 0.0;
  for (int col = 0; col < cols; ++col) grid.azimuth_rad[col] = azimuth_min_rad + col * azimuth_step;
  // Image row 0 is the top: the highest elevation.
  for (int row = 0; row < rows; ++row) {
    grid.elevation_rad[row] = elevation_min_rad + (rows - 1 - row) * elevation_step;
  }
  return grid;
}

void scan_internal::FillDirectionsFromGrid(const ScanGrid& grid, cv::Mat* directions) {
  const int rows = static_cast<int>(grid.elevation_rad.size());
  const int cols = static_cast<int>(grid.azimuth_rad.size());
  directions->create(rows, cols, CV_32FC3);
  // DirectionFromAngles' products from tables of the angles' sines and cosines: the same doubles, so the
  // same floats, without four trigonometric calls a cell.
  std::vector<double> sin_azimuth(cols), cos_azimuth(cols);
  for (int col = 0; col < cols; ++col) {
    sin_azimuth[col] = std::sin(grid.azimuth_rad[col]);
    cos_azimuth[col] = std::cos(grid.azimuth_rad[col]);
  }
  ParallelFor(rows, [&](int64_t r) {
    const int row = static_cast<int>(r);
    const double cos_elevation = std::cos(grid.elevation_rad[row]);
    const float sin_elevation = static_cast<float>(std::sin(grid.elevation_rad[row]));
    auto* out = directions->ptr<cv::Vec3f>(row);
    for (int col = 0; col < cols; ++col) {
      out[col] = cv::Vec3f(static_cast<float>(cos_elevation * sin_azimuth[col]),
                           static_cast<float>(cos_elevation * cos_azimuth[col]), sin_elevation);
    }
  });
}

cv::Mat DirectionsFromGrid(const ScanGrid& grid) {
  cv::Mat directions;
  scan_internal::FillDirectionsFromGrid(grid, &directions);
  return directions;
}

PointCloud ToPointCloud(const Scan& scan, bool world, std::vector<int64_t>* cell_index) {
  CheckScan(scan);
  PointCloud cloud;
  const int64_t count = scan.CountValid();
  cloud.points.reserve(count);
  if (cell_index != nullptr) {
    cell_index->clear();
    cell_index->reserve(count);
  }
  const Eigen::Matrix3f rotation = scan.world_from_scanner.topLeftCorner<3, 3>().cast<float>();
  const Eigen::Vector3f translation = scan.world_from_scanner.topRightCorner<3, 1>().cast<float>();
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) {
      if (scan.valid.at<uint8_t>(row, col) == 0) continue;
      const cv::Vec3f& p = scan.point.at<cv::Vec3f>(row, col);
      Eigen::Vector3f point(p[0], p[1], p[2]);
      if (world) point = rotation * point + translation;
      cloud.points.push_back(point);
      if (!scan.intensity.empty()) cloud.intensities.push_back(scan.intensity.at<float>(row, col));
      if (!scan.color.empty()) {
        const cv::Vec3b& c = scan.color.at<cv::Vec3b>(row, col);
        cloud.colors.emplace_back(c[0], c[1], c[2]);
      }
      if (!scan.normal.empty()) {
        const cv::Vec3f& n = scan.normal.at<cv::Vec3f>(row, col);
        Eigen::Vector3f normal(n[0], n[1], n[2]);
        if (world) normal = rotation * normal;
        cloud.normals.push_back(normal);
      }
      if (!scan.label.empty()) cloud.labels.push_back(scan.label.at<int32_t>(row, col));
      if (!scan.synthesized.empty())
        cloud.synthesized.push_back(scan.synthesized.at<uint8_t>(row, col) ? 1 : 0);
      if (cell_index != nullptr) cell_index->push_back(static_cast<int64_t>(row) * scan.cols + col);
    }
  }
  return cloud;
}

cv::Mat RangeImage(const Scan& scan) { return scan.range.clone(); }

cv::Mat DepthImage(const Scan& scan) {
  cv::Mat depth(scan.rows, scan.cols, CV_32F, cv::Scalar(0));
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) {
      if (scan.valid.at<uint8_t>(row, col)) depth.at<float>(row, col) = scan.point.at<cv::Vec3f>(row, col)[1];
    }
  }
  return depth;
}

cv::Mat RgbdImage(const Scan& scan) {
  cv::Mat rgbd(scan.rows, scan.cols, CV_32FC4);
  for (int row = 0; row < scan.rows; ++row)
    for (int col = 0; col < scan.cols; ++col) rgbd.at<cv::Vec4f>(row, col) = RgbdAt(scan, row, col);
  return rgbd;
}

cv::Mat ValidMask(const Scan& scan) { return scan.valid.clone(); }

cv::Mat LabelImage16(const Scan& scan) {
  if (scan.label.empty()) throw std::logic_error("LabelImage16: the scan has no label channel");
  cv::Mat labels(scan.rows, scan.cols, CV_16U, cv::Scalar(kNoReturnLabel16));
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) {
      const int32_t label = scan.label.at<int32_t>(row, col);
      if (scan.valid.at<uint8_t>(row, col) && label >= 0 && label < kNoReturnLabel16) {
        labels.at<uint16_t>(row, col) = static_cast<uint16_t>(label);
      }
    }
  }
  return labels;
}

Scan WithRange(const Scan& scan, const cv::Mat& range, const cv::Mat& mark_synthesized) {
  CheckScan(scan);
  if (range.rows != scan.rows || range.cols != scan.cols || range.type() != CV_32F) {
    throw std::logic_error("WithRange: the range image must be CV_32F of the scan's size");
  }
  const RayDirections rays(scan);
  Scan result = scan;
  result.valid = scan.valid.clone();
  result.range = range.clone();
  result.point = scan.point.clone();
  result.intensity = scan.intensity.clone();  // empty stays empty
  if (!mark_synthesized.empty() && result.synthesized.empty()) {
    result.synthesized = cv::Mat(scan.rows, scan.cols, CV_8U, cv::Scalar(0));
  } else if (!result.synthesized.empty()) {
    result.synthesized = scan.synthesized.clone();
  }
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) {
      float& new_range = result.range.at<float>(row, col);
      cv::Vec3f& point = result.point.at<cv::Vec3f>(row, col);
      if (!std::isfinite(new_range) || new_range <= 0) {
        new_range = 0;
        point = cv::Vec3f(0, 0, 0);
        result.valid.at<uint8_t>(row, col) = 0;
        continue;
      }
      cv::Vec3f ray = rays(row, col);
      if (scan.valid.at<uint8_t>(row, col)) {
        const cv::Vec3f& old_point = scan.point.at<cv::Vec3f>(row, col);
        const float old_range = static_cast<float>(cv::norm(old_point));
        if (old_range > 0) ray = old_point / old_range;
      }
      point = ray * new_range;
      result.valid.at<uint8_t>(row, col) = kValid;
      if (!mark_synthesized.empty() && mark_synthesized.at<uint8_t>(row, col)) {
        result.synthesized.at<uint8_t>(row, col) = kValid;
      }
    }
  }
  return result;
}

}  // namespace lidarshop
