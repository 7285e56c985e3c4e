#include "lidarshop/io/scan_io.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <string_view>

#include <fmt/format.h>
#include <Eigen/LU>

#include "lidarshop/io/e57.h"
#include "lidarshop/io/formats.h"
#include "lidarshop/io/io_common.h"
#include "lidarshop/io/las.h"
#include "lidarshop/io/pcd.h"
#include "lidarshop/io/ply.h"
#include "lidarshop/io/ply_fields.h"
#include "lidarshop/io/ptx.h"
#include "lidarshop/io/scan_header.h"
#include "lidarshop/io/xyz.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/input_file.h"
#include "lidarshop/util/text.h"

namespace lidarshop {
namespace {

using namespace io_internal;  // NOLINT: the PLY field helpers

// PLY's `curvature` where it is unknown: NaN would be refused by PLY readers that check numbers (ours does).
constexpr double kNoCurvature = -1.0;

constexpr char kScanComment[] = "lidarshop_scan ";

// ---- PLY: a scan is its valid points in the world frame plus row/col/scan
// properties and a pose comment ----

// A 1 x N scan of a cloud (world frame) with its channels: every point a return, (0, 0, 0) included, kept
// relative to a local origin (io_common.h UnorganizedScan); `positions` are the points in double precision
// (the cloud's own points are floats or absent).
Scan ScanFromPointCloud(const PointCloud& cloud, const std::vector<Eigen::Vector3d>& positions) {
  Scan scan = UnorganizedScan(positions, {}, !cloud.colors.empty(), !cloud.intensities.empty());
  if (!cloud.labels.empty()) scan.label = cv::Mat(1, scan.cols, CV_32S, cv::Scalar(kNoLabel));
  if (!cloud.normals.empty()) scan.normal = cv::Mat(1, scan.cols, CV_32FC3, cv::Scalar::all(0));
  if (!cloud.synthesized.empty()) scan.synthesized = cv::Mat(1, scan.cols, CV_8U, cv::Scalar(0));
  const Eigen::Matrix3d scanner_from_world = scan.world_from_scanner.topLeftCorner<3, 3>().transpose();
  for (int i = 0; i < scan.cols; ++i) {
    if (!cloud.intensities.empty()) scan.intensity.at<float>(0, i) = cloud.intensities[i];
    if (!cloud.colors.empty())
      scan.color.at<cv::Vec3b>(0, i) = cv::Vec3b(cloud.colors[i][0], cloud.colors[i][1], cloud.colors[i][2]);
    if (!cloud.labels.empty()) scan.label.at<int32_t>(0, i) = cloud.labels[i];
    if (!cloud.normals.empty()) {
      const Eigen::Vector3f n = (scanner_from_world * cloud.normals[i].cast<double>()).cast<float>();
      scan.normal.at<cv::Vec3f>(0, i) = cv::Vec3f(n.x(), n.y(), n.z());
    }
    if (!cloud.synthesized.empty()) scan.synthesized.at<uint8_t>(0, i) = cloud.synthesized[i] ? kValid : 0;
  }
  return scan;
}

Scan ScanFromPointCloud(const PointCloud& cloud) {
  std::vector<Eigen::Vector3d> positions(cloud.points.size());
  for (size_t i = 0; i < positions.size(); ++i) positions[i] = cloud.points[i].cast<double>();
  return ScanFromPointCloud(cloud, positions);
}

struct PlyScanHeader {
  int index = 0;
  int64_t rows = 0, cols = 0;
  Eigen::Matrix4d world_from_scanner = Eigen::Matrix4d::Identity();
};

std::vector<PlyScanHeader> ParseScanComments(const PlyData& ply, const std::string& path,
                                             int64_t file_bytes) {
  std::vector<PlyScanHeader> headers;
  int64_t total_cells = 0;  // every scan is allocated at once: bound them together, not one by one
  for (const std::string& comment : ply.comments) {
    if (comment.rfind(kScanComment, 0) != 0) continue;
    std::istringstream stream(comment.substr(sizeof(kScanComment) - 1));
    PlyScanHeader header;
    stream >> header.index >> header.rows >> header.cols;
    for (int i = 0; i < 16; ++i) stream >> header.world_from_scanner(i / 4, i % 4);
    if (!stream || header.index != static_cast<int>(headers.size())) {
      ThrowInputError(
          path, "header", "comment lidarshop_scan",
          "expected 'lidarshop_scan <index> <rows> <cols> <16 matrix values>' with indices 0, 1, ...");
    }
    CheckGridFromData(header.rows, header.cols, file_bytes, path,
                      fmt::format("header: scan {}", header.index));
    total_cells += header.rows * header.cols;
    CheckCellsFromData(total_cells, kScanBytesPerCell, file_bytes, path,
                       fmt::format("header: scans 0 to {}", header.index),
                       "cells of the lidarshop_scan grids");
    headers.push_back(header);
  }
  return headers;
}

std::vector<Scan> ReadPlyScans(const std::string& path, std::vector<std::string>* warnings) {
  const PlyData ply = ReadPly(path);
  const PlyElement& vertex = RequireElement(ply, "vertex", path);
  // The positions as the file stores them (doubles when the writer needed them): the cloud's floats would
  // lose half metres 5,000 km out before the pose takes them back to the scanner frame.
  const std::vector<Eigen::Vector3d> positions = VertexPositions(vertex, path, warnings);
  const PointCloud cloud = PointCloudFromPly(ply, path, /*require_positions=*/false);
  const std::vector<PlyScanHeader> headers = ParseScanComments(ply, path, CheckRegularFile(path));
  const PlyProperty* row_property = FindScalar(vertex, {"row"});
  const PlyProperty* col_property = FindScalar(vertex, {"col"});
  const PlyProperty* scan_property = FindScalar(vertex, {"scan"});
  const PlyProperty* true_range_property = FindScalar(vertex, {"true_range"});
  const PlyProperty* curvature_property = FindScalar(vertex, {"curvature"});
  const PlyProperty* from_station_property = FindScalar(vertex, {"from_station"});

  if (headers.empty() || row_property == nullptr || col_property == nullptr) {
    // A plain point cloud: one 1 x N scan, every point a return.
    if (positions.empty()) ThrowInputError(path, "header", "element vertex", "no points");
    CheckScanSize(1, static_cast<int64_t>(positions.size()), path, "header");
    return {ScanFromPointCloud(cloud, positions)};
  }

  std::vector<Scan> scans;
  std::vector<Eigen::Matrix4d> scanner_from_world;
  for (const PlyScanHeader& header : headers) {
    Scan scan = MakeScan(static_cast<int>(header.rows), static_cast<int>(header.cols), !cloud.colors.empty(),
                         !cloud.intensities.empty());
    scan.world_from_scanner = header.world_from_scanner;
    if (!cloud.labels.empty()) scan.label = cv::Mat(scan.rows, scan.cols, CV_32S, cv::Scalar(kNoLabel));
    if (!cloud.normals.empty()) scan.normal = cv::Mat(scan.rows, scan.cols, CV_32FC3, cv::Scalar::all(0));
    if (!cloud.synthesized.empty()) scan.synthesized = cv::Mat(scan.rows, scan.cols, CV_8U, cv::Scalar(0));
    if (true_range_property != nullptr)
      scan.true_range = cv::Mat(scan.rows, scan.cols, CV_32F, cv::Scalar(0));
    if (curvature_property != nullptr)
      scan.curvature = cv::Mat(scan.rows, scan.cols, CV_32F, cv::Scalar(NAN));
    if (from_station_property != nullptr)
      scan.from_station = cv::Mat(scan.rows, scan.cols, CV_8U, cv::Scalar(0));
    scanner_from_world.push_back(header.world_from_scanner.inverse());
    scans.push_back(std::move(scan));
  }
  for (size_t i = 0; i < positions.size(); ++i) {
    const int64_t index = scan_property != nullptr ? ToInt32(scan_property->values[i]) : 0;
    const int64_t row = ToInt32(row_property->values[i]);
    const int64_t col = ToInt32(col_property->values[i]);
    if (index < 0 || index >= static_cast<int64_t>(scans.size()) || row < 0 || row >= scans[index].rows ||
        col < 0 || col >= scans[index].cols) {
      ThrowInputError(
          path, fmt::format("vertex {}", i), "scan/row/col",
          fmt::format("scan {} row {} col {} is outside the scans the header declares", index, row, col));
    }
    Scan& scan = scans[index];
    const Eigen::Matrix4d& inverse = scanner_from_world[index];
    const Eigen::Vector3d p = inverse.topLeftCorner<3, 3>() * positions[i] + inverse.topRightCorner<3, 1>();
    if (p.isZero()) continue;
    if (scan.valid.at<uint8_t>(row, col)) {
      ThrowInputError(path, fmt::format("vertex {}", i), "row/col",
                      fmt::format("scan {} row {} col {} already holds a point (two points in one cell)",
                                  index, row, col));
    }
    scan.valid.at<uint8_t>(row, col) = kValid;
    scan.point.at<cv::Vec3f>(row, col) = cv::Vec3f(p.x(), p.y(), p.z());
    if (!cloud.intensities.empty()) scan.intensity.at<float>(row, col) = cloud.intensities[i];
    if (!cloud.colors.empty()) {
      scan.color.at<cv::Vec3b>(row, col) =
          cv::Vec3b(cloud.colors[i][0], cloud.colors[i][1], cloud.colors[i][2]);
    }
    if (!cloud.labels.empty()) scan.label.at<int32_t>(row, col) = cloud.labels[i];
    if (!cloud.normals.empty()) {
      const Eigen::Vector3d n = inverse.topLeftCorner<3, 3>() * cloud.normals[i].cast<double>();
      scan.normal.at<cv::Vec3f>(row, col) = cv::Vec3f(n.x(), n.y(), n.z());
    }
    if (!cloud.synthesized.empty())
      scan.synthesized.at<uint8_t>(row, col) = cloud.synthesized[i] ? kValid : 0;
    if (true_range_property != nullptr) scan.true_range.at<float>(row, col) = true_range_property->values[i];
    if (curvature_property != nullptr && curvature_property->values[i] >= 0.0)  // < 0: unknown (kNoCurvature)
      scan.curvature.at<float>(row, col) = curvature_property->values[i];
    if (from_station_property != nullptr) {
      const double from = from_station_property->values[i];
      scan.from_station.at<uint8_t>(row, col) =
          std::isfinite(from) ? static_cast<uint8_t>(std::clamp(from, 0.0, 255.0)) : 0;
    }
  }
  for (Scan& scan : scans) FinishScan(&scan, /*fit_grid=*/true);
  return scans;
}

void WritePlyScans(const std::string& path, const std::vector<Scan>& scans) {
  PlyData ply;
  ply.comments.push_back("written by lidarshop: points in the world frame; row/col in image orientation");
  ply.comments.push_back("frame world");
  int64_t total = 0;
  bool color = false, label = false, normal = false, curvature = false, synthesized = false,
       true_range = false, far = false, any_intensity = false, from_station = false;
  for (size_t k = 0; k < scans.size(); ++k) {
    const Scan& scan = scans[k];
    CheckScan(scan);
    std::string comment = fmt::format("{}{} {} {}", kScanComment, k, scan.rows, scan.cols);
    for (int i = 0; i < 16; ++i) comment += fmt::format(" {}", scan.world_from_scanner(i / 4, i % 4));
    ply.comments.push_back(comment);
    total += scan.CountValid();
    color |= scan.has_color();
    any_intensity |= scan.has_intensity();
    label |= !scan.label.empty();
    normal |= !scan.normal.empty();
    curvature |= !scan.curvature.empty();
    synthesized |= !scan.synthesized.empty();
    true_range |= !scan.true_range.empty();
    from_station |= !scan.from_station.empty();
  }
  std::vector<double> x, y, z, nx, ny, nz, curv, red, green, blue, intensity, labels, synth, truth, rows,
      cols, index, from;
  for (std::vector<double>* column : {&x, &y, &z, &intensity, &rows, &cols, &index}) column->reserve(total);
  for (size_t k = 0; k < scans.size(); ++k) {
    const Scan& scan = scans[k];
    const Eigen::Matrix4d& pose = scan.world_from_scanner;
    for (int row = 0; row < scan.rows; ++row) {
      for (int col = 0; col < scan.cols; ++col) {
        if (!scan.valid.at<uint8_t>(row, col)) continue;
        const cv::Vec3f& p = scan.point.at<cv::Vec3f>(row, col);
        const Eigen::Vector3d world =
            pose.topLeftCorner<3, 3>() * Eigen::Vector3d(p[0], p[1], p[2]) + pose.topRightCorner<3, 1>();
        // Past kCloudFloatSafeM floats would lose more than 0.06 mm: doubles then.
        far |= world.cwiseAbs().maxCoeff() > kCloudFloatSafeM;
        x.push_back(world.x());
        y.push_back(world.y());
        z.push_back(world.z());
        // A scan without intensity among scans with it gets the PTX no-information value 0.5.
        if (any_intensity)
          intensity.push_back(scan.has_intensity() ? scan.intensity.at<float>(row, col) : 0.5);
        rows.push_back(row);
        cols.push_back(col);
        index.push_back(static_cast<double>(k));
        if (color) {
          const cv::Vec3b c = scan.has_color() ? scan.color.at<cv::Vec3b>(row, col) : cv::Vec3b(0, 0, 0);
          red.push_back(c[0]);
          green.push_back(c[1]);
          blue.push_back(c[2]);
        }
        if (normal) {
          Eigen::Vector3d n = Eigen::Vector3d::Zero();
          if (!scan.normal.empty()) {
            const cv::Vec3f& v = scan.normal.at<cv::Vec3f>(row, col);
            n = pose.topLeftCorner<3, 3>() * Eigen::Vector3d(v[0], v[1], v[2]);
          }
          nx.push_back(n.x());
          ny.push_back(n.y());
          nz.push_back(n.z());
        }
        if (curvature) {
          const float value = scan.curvature.empty() ? NAN : scan.curvature.at<float>(row, col);
          curv.push_back(std::isnan(value) ? kNoCurvature : value);
        }
        if (label) labels.push_back(scan.label.empty() ? kNoLabel : scan.label.at<int32_t>(row, col));
        if (synthesized)
          synth.push_back(!scan.synthesized.empty() && scan.synthesized.at<uint8_t>(row, col) ? 1 : 0);
        if (true_range) truth.push_back(scan.true_range.empty() ? 0.0 : scan.true_range.at<float>(row, col));
        if (from_station)
          from.push_back(scan.from_station.empty() ? 0 : scan.from_station.at<uint8_t>(row, col));
      }
    }
  }
  PlyElement vertex{"vertex", total, {}};
  const PlyType position_type = far ? PlyType::kFloat64 : PlyType::kFloat32;
  AddScalarProperty(&vertex, "x", position_type, std::move(x));
  AddScalarProperty(&vertex, "y", position_type, std::move(y));
  AddScalarProperty(&vertex, "z", position_type, std::move(z));
  if (normal) {
    AddScalarProperty(&vertex, "nx", PlyType::kFloat32, std::move(nx));
    AddScalarProperty(&vertex, "ny", PlyType::kFloat32, std::move(ny));
    AddScalarProperty(&vertex, "nz", PlyType::kFloat32, std::move(nz));
  }
  if (curvature) AddScalarProperty(&vertex, "curvature", PlyType::kFloat32, std::move(curv));
  if (color) {
    AddScalarProperty(&vertex, "red", PlyType::kUInt8, std::move(red));
    AddScalarProperty(&vertex, "green", PlyType::kUInt8, std::move(green));
    AddScalarProperty(&vertex, "blue", PlyType::kUInt8, std::move(blue));
  }
  if (any_intensity) AddScalarProperty(&vertex, "intensity", PlyType::kFloat32, std::move(intensity));
  if (label) AddScalarProperty(&vertex, "label", PlyType::kInt32, std::move(labels));
  if (synthesized) AddScalarProperty(&vertex, "synthesized", PlyType::kUInt8, std::move(synth));
  if (true_range) AddScalarProperty(&vertex, "true_range", PlyType::kFloat32, std::move(truth));
  if (from_station) AddScalarProperty(&vertex, "from_station", PlyType::kUInt8, std::move(from));
  AddScalarProperty(&vertex, "row", PlyType::kInt32, std::move(rows));
  AddScalarProperty(&vertex, "col", PlyType::kInt32, std::move(cols));
  AddScalarProperty(&vertex, "scan", PlyType::kInt32, std::move(index));
  ply.elements.push_back(std::move(vertex));
  WritePly(path, ply);
}

// The scans of a PLY file as its header describes them: lidarshop's scan comments give the grids and poses
// (organized when the vertices have row/col), else one cloud of `vertex` points.
ScanFileHeader PlyFileHeader(const std::string& path) {
  int64_t data_bytes = 0;
  const PlyData ply = ReadPlyHeader(path, &data_bytes);
  const PlyElement& vertex = RequireElement(ply, "vertex", path);
  ScanFileHeader file;
  file.format_version = ply.format == PlyData::Format::kAscii             ? "PLY ascii"
                        : ply.format == PlyData::Format::kBinaryBigEndian ? "PLY binary_big_endian"
                                                                          : "PLY binary_little_endian";
  std::vector<std::string> channels = {"xyz", "range"};
  if (FindScalar(vertex, {"intensity", "scalar_intensity", "scalar_Intensity"}))
    channels.push_back("intensity");
  channels.insert(channels.end(), {"valid", "direction"});
  if (FindScalar(vertex, {"red", "r", "diffuse_red"}) &&
      FindScalar(vertex, {"green", "g", "diffuse_green"}) &&
      FindScalar(vertex, {"blue", "b", "diffuse_blue"})) {
    channels.push_back("rgb");
  }
  if (FindScalar(vertex, {"label", "scalar_label", "class", "classification"})) channels.push_back("label");
  if (FindScalar(vertex, {"nx"}) && FindScalar(vertex, {"ny"}) && FindScalar(vertex, {"nz"}))
    channels.push_back("normal");
  const std::vector<PlyScanHeader> headers = ParseScanComments(ply, path, CheckRegularFile(path));
  const bool organized = !headers.empty() && FindScalar(vertex, {"row"}) && FindScalar(vertex, {"col"});
  if (FindScalar(vertex, {"curvature"})) channels.push_back("curvature");
  if (organized && FindScalar(vertex, {"true_range"})) channels.push_back("true_range");
  if (FindScalar(vertex, {"synthesized"})) channels.push_back("synthesized");
  if (organized && FindScalar(vertex, {"from_station"})) channels.push_back("from_station");
  if (!organized) {
    if (vertex.count == 0) ThrowInputError(path, "header", "element vertex", "no points");
    CheckScanSize(1, vertex.count, path, "header");
    ScanHeader scan;
    scan.rows = 1;
    scan.cols = vertex.count;
    scan.points = vertex.count;
    scan.channels = channels;
    file.scans.push_back(scan);
  }
  for (const PlyScanHeader& header : headers) {
    if (!organized) break;
    ScanHeader scan;
    scan.organized = true;
    scan.rows = header.rows;
    scan.cols = header.cols;
    // The vertices of several scans are told apart by their `scan` property: only the total is in the header.
    scan.points = headers.size() == 1 ? vertex.count : -1;
    scan.world_from_scanner = header.world_from_scanner;
    scan.channels = channels;
    file.scans.push_back(scan);
  }
  return file;
}

// ---- The table ----

// The reader and writer of each format of the registry (io/formats.h), which says what each holds and which
// are read and written; formats_test checks that the two tables agree.
struct ScanCodec {
  std::string_view extension;
  // Reads the scans of a file, adding what it left out to `warnings`.
  std::vector<Scan> (*read)(const std::string& path, std::vector<std::string>* warnings);
  void (*write)(const std::string& path, const std::vector<Scan>& scans);
};

const std::vector<ScanCodec>& ScanCodecs() {
  static const std::vector<ScanCodec> formats = {
      {"ptx",
       [](const std::string& path, std::vector<std::string>* warnings) {
         return ReadPtx(path, {}, warnings);
       },
       &WritePtx},
      {"ply", &ReadPlyScans, &WritePlyScans},
      {"pcd",
       [](const std::string& path, std::vector<std::string>* warnings) {
         return std::vector<Scan>{ReadPcd(path, warnings)};
       },
       [](const std::string& path, const std::vector<Scan>& scans) {
         if (scans.size() != 1) {
           ThrowInputError(path, "", "",
                           fmt::format("PCD holds one scan, got {}; write .ptx, .ply or .e57", scans.size()));
         }
         WritePcd(path, scans[0]);
       }},
      {"e57",
       [](const std::string& path, std::vector<std::string>* warnings) {
         E57File file = ReadE57(path);
         warnings->insert(warnings->end(), file.warnings.begin(), file.warnings.end());
         return std::move(file.scans);
       },
       &WriteE57},
      {"las",
       [](const std::string& path, std::vector<std::string>* warnings) {
         return std::vector<Scan>{ReadLas(path, warnings)};
       },
       [](const std::string& path, const std::vector<Scan>& scans) { WriteLas(path, scans); }},
      {"laz",
       [](const std::string& path, std::vector<std::string>* warnings) {
         return std::vector<Scan>{ReadLas(path, warnings)};
       },
       nullptr},
      {"xyz",
       [](const std::string& path, std::vector<std::string>* warnings) {
         return std::vector<Scan>{ReadPointList(path, PointListKind::kXyz, warnings)};
       },
       [](const std::string& path, const std::vector<Scan>& scans) {
         WritePointList(path, scans, PointListKind::kXyz);
       }},
      {"pts",
       [](const std::string& path, std::vector<std::string>* warnings) {
         return std::vector<Scan>{ReadPointList(path, PointListKind::kPts, warnings)};
       },
       [](const std::string& path, const std::vector<Scan>& scans) {
         WritePointList(path, scans, PointListKind::kPts);
       }},
  };
  return formats;
}

enum class Access { kRead, kWrite };

const ScanCodec& FormatFor(const std::string& path, Access access) {
  const std::string extension = FileExtension(path);
  const ScanFormatInfo* format = FindScanFormat(extension);
  if (format != nullptr && access == Access::kWrite && !format->write)
    ThrowInputError(path, "", "", std::string(format->write_refusal));
  for (const ScanCodec& codec : ScanCodecs()) {
    if (format != nullptr && extension == codec.extension) return codec;
  }
  std::string known;
  for (const ScanFormatInfo& readable : ScanFormats()) {
    if (readable.read) known += fmt::format("{}.{}", known.empty() ? "" : " ", readable.extension);
  }
  ThrowInputError(path, "", "",
                  fmt::format("unknown scan format '{}' (lidarshop reads {})",
                              extension.empty() ? std::string("no extension") : "." + extension, known));
}

}  // namespace

ScanFileHeader io_internal::ReadPlyScanHeader(const std::string& path) { return PlyFileHeader(path); }

std::string FileExtension(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  if (!extension.empty() && extension[0] == '.') extension.erase(0, 1);
  return AsciiLower(extension);
}

void CheckScanFileFormat(const std::string& path) { FormatFor(path, Access::kWrite); }

void CheckScanFileReadable(const std::string& path) { FormatFor(path, Access::kRead); }

std::vector<std::string> SupportedScanReadExtensions() {
  std::vector<std::string> extensions;
  for (const ScanFormatInfo& format : ScanFormats())
    if (format.read) extensions.emplace_back(format.extension);
  return extensions;
}

std::vector<std::string> SupportedScanWriteExtensions() {
  std::vector<std::string> extensions;
  for (const ScanFormatInfo& format : ScanFormats())
    if (format.write) extensions.emplace_back(format.extension);
  return extensions;
}

ScanFile ReadScanFile(const std::string& path) {
  const ScanCodec& format = FormatFor(path, Access::kRead);
  ScanFile file;
  file.path = path;
  file.format = std::string(format.extension);
  CheckRegularFile(path);  // a FIFO would block the reader, a folder has no bytes to check counts against
  file.scans = format.read(path, &file.warnings);
  for (size_t i = 0; i < file.scans.size(); ++i) {
    CheckScanNumbers(file.scans[i], path, fmt::format("scan {}", i));
  }
  return file;
}

void WriteScanFile(const std::string& path, const std::vector<Scan>& scans) {
  const ScanCodec& format = FormatFor(path, Access::kWrite);
  if (scans.empty()) ThrowInputError(path, "", "", "no scan to write");
  if (format.extension == "e57" ||
      std::none_of(scans.begin(), scans.end(), [](const Scan& s) { return s.num_cells() == 0; })) {
    format.write(path, scans);
    return;
  }
  // PTX, PLY and PCD have no empty scan (0 x 0 is not a size their readers take); LAS, XYZ and PTS hold points.
  std::vector<Scan> kept;
  for (const Scan& scan : scans) {
    if (scan.num_cells() > 0) kept.push_back(scan);
  }
  if (kept.empty()) ThrowInputError(path, "", "", "no point to write: every scan of the input is empty");
  format.write(path, kept);
}

void WriteScanWithLayer(const std::string& path, const Scan& front, const Scan& behind) {
  const std::string extension(FormatFor(path, Access::kWrite).extension);
  CheckScan(front);
  CheckScan(behind);
  if (front.rows != behind.rows || front.cols != behind.cols) {
    ThrowInputError(path, "", "layers",
                    fmt::format("the layer behind ({} x {}) does not match the front scan's grid ({} x {})",
                                behind.rows, behind.cols, front.rows, front.cols));
  }
  if (!front.world_from_scanner.isApprox(behind.world_from_scanner, 1e-9)) {
    ThrowInputError(path, "", "layers", "the layer behind has another pose than the front scan");
  }
  const ScanFormatInfo& format = *FindScanFormat(extension);
  if (!format.layer_behind) ThrowInputError(path, "", "", LayerBehindRefusal(format));
  if (extension == "e57") {
    WriteE57WithLayer(path, front, behind);
    return;
  }
  // Points of both layers, world frame, the layer behind flagged synthesized.
  Scan flagged = behind;
  flagged.synthesized = cv::Mat(behind.rows, behind.cols, CV_8U, cv::Scalar(kValid));
  if (extension == "las") {
    // One cloud: the union of both layers' points, the layer behind with the synthetic flag.
    WriteLas(path, {front, flagged});
    return;
  }
  if (extension == "ply") {
    // Two scans of one grid: plain PLY readers see the union of the points, lidarshop gets both layers back.
    WritePlyScans(path, {front, flagged});
    return;
  }
  PointCloud cloud = ToPointCloud(front, /*world=*/true);
  const PointCloud more = ToPointCloud(flagged, /*world=*/true);
  if (cloud.synthesized.empty()) cloud.synthesized.assign(cloud.size(), 0);
  auto append = [](auto& to, const auto& from) { to.insert(to.end(), from.begin(), from.end()); };
  // An optional channel only one layer has is dropped rather than padded with made-up values.
  auto append_optional = [&](auto& to, const auto& from) {
    if (!to.empty() && !from.empty())
      append(to, from);
    else
      to.clear();
  };
  append_optional(cloud.colors, more.colors);
  append_optional(cloud.normals, more.normals);
  append_optional(cloud.labels, more.labels);
  append_optional(cloud.intensities, more.intensities);
  append(cloud.points, more.points);
  append(cloud.synthesized, more.synthesized);
  if (cloud.points.empty()) ThrowInputError(path, "", "", "neither layer has a return to write");
  WritePcd(path, ScanFromPointCloud(cloud));
}

}  // namespace lidarshop
