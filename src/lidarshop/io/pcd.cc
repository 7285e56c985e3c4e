#include "lidarshop/io/pcd.h"

#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <string_view>

#include <fmt/format.h>
#include <liblzf/lzf.h>
#include <Eigen/Geometry>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/io/io_common.h"
#include "lidarshop/io/scan_header.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/io/text_cursor.h"
#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/input_file.h"
#include "lidarshop/util/memory_budget.h"

namespace lidarshop {
namespace {

using io_internal::TextCursor;

struct PcdField {
  std::string name;
  int size = 4;
  char type = 'F';  // I, U or F
  int count = 1;
  int64_t offset = 0;  // byte offset in a binary point record
};

struct PcdHeader {
  std::vector<PcdField> fields;
  int64_t width = 0, height = 0, points = -1;
  double viewpoint[7] = {0, 0, 0, 1, 0, 0, 0};
  // From lidarshop's comment "# lidarshop_scan world_from_scanner <16 numbers, row major>": the points are
  // world coordinates (in the VIEWPOINT frame, identity when lidarshop wrote them) of a scan in this pose.
  bool has_scanner_pose = false;
  Eigen::Matrix4d world_from_scanner = Eigen::Matrix4d::Identity();
  std::string data;
  int64_t point_size = 0;
  size_t data_offset = 0;
  int64_t data_line = 0;

  int Find(const std::string& name) const {
    for (size_t i = 0; i < fields.size(); ++i) {
      if (fields[i].name == name) return static_cast<int>(i);
    }
    return -1;
  }
};

constexpr std::string_view kPoseComment = "lidarshop_scan world_from_scanner";

// The optical frame of an organized cloud from the scanner frame: (x, y, z)_camera = (x, -z, y)_scanner.
Eigen::Matrix4d CameraFromScanner() {
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  m(0, 0) = 1;
  m(1, 2) = -1;
  m(2, 1) = 1;
  m(3, 3) = 1;
  return m;
}

PcdHeader ParseHeader(const std::string& bytes, const std::string& file) {
  PcdHeader header;
  TextCursor cursor(bytes, file);
  std::vector<int> sizes, counts;
  std::vector<char> types;
  for (;;) {
    cursor.SkipEmptyLines();
    if (cursor.AtEnd()) cursor.Fail("DATA", "missing: the header never ends (truncated or not a PCD file)");
    if (cursor.offset() > (1 << 16)) cursor.Fail("header", "longer than 64 KiB: not a PCD file");
    const std::string_view keyword = cursor.Token();
    if (!keyword.empty() && keyword[0] == '#') {
      const std::string_view comment = cursor.RestOfLine();
      if (keyword == "#" && comment.substr(0, kPoseComment.size()) == kPoseComment) {
        TextCursor numbers(comment.substr(kPoseComment.size()), file, cursor.line());
        for (int i = 0; i < 16; ++i) header.world_from_scanner(i / 4, i % 4) = numbers.Double(kPoseComment);
        if (!numbers.AtEndOfLine()) numbers.Fail(kPoseComment, "more than 16 numbers");
        const std::string problem = PoseProblem(header.world_from_scanner, /*allow_uniform_scale=*/false);
        if (!problem.empty()) numbers.Fail(kPoseComment, fmt::format("the pose {}", problem));
        header.has_scanner_pose = true;
      }
      cursor.NextLine();
      continue;
    }
    if (keyword.empty()) {
      cursor.NextLine();
      continue;
    }
    if (keyword == "VERSION") {
      cursor.RestOfLine();
    } else if (keyword == "FIELDS" || keyword == "COLUMNS") {
      while (!cursor.AtEndOfLine()) {
        PcdField field;
        field.name = std::string(cursor.Token());
        header.fields.push_back(field);
      }
    } else if (keyword == "SIZE") {
      while (!cursor.AtEndOfLine()) sizes.push_back(static_cast<int>(cursor.Int("SIZE")));
    } else if (keyword == "TYPE") {
      while (!cursor.AtEndOfLine()) {
        const std::string_view type = cursor.Token();
        if (type.size() != 1 || (type[0] != 'I' && type[0] != 'U' && type[0] != 'F')) {
          cursor.Fail("TYPE", fmt::format("'{}' is not I, U or F", io_internal::Printable(type)));
        }
        types.push_back(type[0]);
      }
    } else if (keyword == "COUNT") {
      while (!cursor.AtEndOfLine()) counts.push_back(static_cast<int>(cursor.Int("COUNT")));
    } else if (keyword == "WIDTH") {
      header.width = cursor.Int("WIDTH");
    } else if (keyword == "HEIGHT") {
      header.height = cursor.Int("HEIGHT");
    } else if (keyword == "VIEWPOINT") {
      for (double& value : header.viewpoint) value = cursor.Double("VIEWPOINT");
    } else if (keyword == "POINTS") {
      header.points = cursor.Int("POINTS");
    } else if (keyword == "DATA") {
      header.data = std::string(cursor.Token());
      if (header.data != "ascii" && header.data != "binary" && header.data != "binary_compressed") {
        cursor.Fail("DATA", fmt::format("unknown data format '{}'", io_internal::Printable(header.data)));
      }
      cursor.NextLine();
      break;
    } else {
      cursor.Fail("header",
                  fmt::format("unknown keyword '{}' (not a PCD file?)", io_internal::Printable(keyword)));
    }
    cursor.EndLine(std::string(keyword));
  }
  header.data_offset = static_cast<size_t>(cursor.offset());
  header.data_line = cursor.line();
  const size_t n = header.fields.size();
  if (n == 0) ThrowInputError(file, "header", "FIELDS", "missing");
  if (sizes.size() != n || types.size() != n || (!counts.empty() && counts.size() != n)) {
    ThrowInputError(file, "header", "SIZE/TYPE/COUNT",
                    fmt::format("{} fields but {} sizes, {} types and {} counts", n, sizes.size(),
                                types.size(), counts.size()));
  }
  for (size_t i = 0; i < n; ++i) {
    PcdField& field = header.fields[i];
    field.size = sizes[i];
    field.type = types[i];
    field.count = counts.empty() ? 1 : counts[i];
    const bool ok_size = field.type == 'F'
                             ? (field.size == 4 || field.size == 8)
                             : (field.size == 1 || field.size == 2 || field.size == 4 || field.size == 8);
    if (!ok_size || field.count < 1 || field.count > 1 << 16) {
      ThrowInputError(
          file, "header", field.name,
          fmt::format("unsupported SIZE {} / TYPE {} / COUNT {}", field.size, field.type, field.count));
    }
    field.offset = header.point_size;
    header.point_size += static_cast<int64_t>(field.size) * field.count;
  }
  if (header.height <= 0) header.height = 1;
  if (header.points < 0) header.points = header.width * header.height;
  io_internal::CheckScanSize(header.height, header.width, file, "header: WIDTH x HEIGHT");
  if (header.points != header.width * header.height) {
    ThrowInputError(
        file, "header", "POINTS",
        fmt::format("{} points but WIDTH x HEIGHT = {} x {}", header.points, header.width, header.height));
  }
  for (const char* name : {"x", "y", "z"}) {
    if (header.Find(name) < 0) ThrowInputError(file, "header", "FIELDS", fmt::format("no '{}' field", name));
  }
  return header;
}

double LoadValue(const char* p, const PcdField& field) {
  switch (field.type) {
    case 'F':
      if (field.size == 4) {
        float value;
        std::memcpy(&value, p, 4);
        return value;
      } else {
        double value;
        std::memcpy(&value, p, 8);
        return value;
      }
    case 'U':
      switch (field.size) {
        case 1:
          return static_cast<uint8_t>(*p);
        case 2: {
          uint16_t v;
          std::memcpy(&v, p, 2);
          return v;
        }
        case 4: {
          uint32_t v;
          std::memcpy(&v, p, 4);
          return v;
        }
        default: {
          uint64_t v;
          std::memcpy(&v, p, 8);
          return static_cast<double>(v);
        }
      }
    default:
      switch (field.size) {
        case 1:
          return static_cast<int8_t>(*p);
        case 2: {
          int16_t v;
          std::memcpy(&v, p, 2);
          return v;
        }
        case 4: {
          int32_t v;
          std::memcpy(&v, p, 4);
          return v;
        }
        default: {
          int64_t v;
          std::memcpy(&v, p, 8);
          return static_cast<double>(v);
        }
      }
  }
}

// Packed colour bits of an rgb/rgba field (a float whose bits are 0xAARRGGBB, or an unsigned integer).
uint32_t PackedColor(const char* p, const PcdField& field) {
  uint32_t bits = 0;
  if (field.size == 4) std::memcpy(&bits, p, 4);
  return bits;
}

// VIEWPOINT as a matrix: the frame the file's coordinates are in.
Eigen::Matrix4d Viewpoint(const PcdHeader& header, const std::string& file) {
  const double* v = header.viewpoint;
  Eigen::Matrix4d viewpoint = Eigen::Matrix4d::Identity();
  const Eigen::Quaterniond rotation(v[3], v[4], v[5], v[6]);
  if (rotation.norm() < 1e-9)
    ThrowInputError(file, "header", "VIEWPOINT", "the orientation quaternion is zero");
  viewpoint.topLeftCorner<3, 3>() = rotation.normalized().toRotationMatrix();
  viewpoint.topRightCorner<3, 1>() = Eigen::Vector3d(v[0], v[1], v[2]);
  return viewpoint;
}

// The scan's pose: the one lidarshop's comment names (its points are world coordinates), else VIEWPOINT,
// turned from the optical frame for a foreign organized cloud (a camera image).
Eigen::Matrix4d WorldFromScanner(const PcdHeader& header, const std::string& file) {
  if (header.has_scanner_pose) return header.world_from_scanner;
  const Eigen::Matrix4d viewpoint = Viewpoint(header, file);
  return header.height > 1 ? Eigen::Matrix4d(viewpoint * CameraFromScanner()) : viewpoint;
}

}  // namespace

Scan ParsePcd(const std::string& bytes, const std::string& file) {
  if (bytes.empty()) ThrowInputError(file, "byte 0", "", "the file is empty");
  const PcdHeader header = ParseHeader(bytes, file);
  const int64_t points = header.points;
  const int64_t data_size = points * header.point_size;
  const size_t available = bytes.size() - header.data_offset;
  // The point records in AoS layout (one record after the other), whatever the file used.
  std::vector<char> records;
  auto allocate = [&](int64_t size) {
    if (size > static_cast<int64_t>(kMaxScanCells) * 64) {
      ThrowInputError(file, "header", "POINTS",
                      fmt::format("{} bytes of point data is more than lidarshop accepts", size));
    }
    CheckMemoryBudget(
        size, fmt::format("{}: header: POINTS: {} points of {} bytes", file, points, header.point_size));
    records.resize(static_cast<size_t>(size));
  };
  if (header.data == "binary") {
    if (static_cast<int64_t>(available) < data_size) {
      ThrowInputError(file, fmt::format("byte {}", bytes.size()), "DATA",
                      fmt::format("truncated: {} points of {} bytes need {} bytes, {} follow the header",
                                  points, header.point_size, data_size, available));
    }
    allocate(data_size);
    std::memcpy(records.data(), bytes.data() + header.data_offset, records.size());
  } else if (header.data == "binary_compressed") {
    if (available < 8) {
      ThrowInputError(file, fmt::format("byte {}", header.data_offset), "compressed size", "truncated");
    }
    uint32_t compressed_size = 0, uncompressed_size = 0;
    std::memcpy(&compressed_size, bytes.data() + header.data_offset, 4);
    std::memcpy(&uncompressed_size, bytes.data() + header.data_offset + 4, 4);
    if (uncompressed_size != data_size) {
      ThrowInputError(file, fmt::format("byte {}", header.data_offset + 4), "uncompressed size",
                      fmt::format("{} but {} points of {} bytes need {}", uncompressed_size, points,
                                  header.point_size, data_size));
    }
    if (compressed_size > available - 8) {
      ThrowInputError(
          file, fmt::format("byte {}", header.data_offset), "compressed size",
          fmt::format("truncated: {} compressed bytes claimed, {} follow", compressed_size, available - 8));
    }
    // LZF expands at most 264 bytes from a 3-byte back reference: a size past that ratio is refused before
    // the buffer is zero-filled (a 172-byte file claimed 1.2 GB).
    constexpr int64_t kLzfMaxBytesPerByte = 88;
    if (data_size > (int64_t{compressed_size} + 3) * kLzfMaxBytesPerByte) {
      ThrowInputError(
          file, fmt::format("byte {}", header.data_offset + 4), "uncompressed size",
          fmt::format("{} bytes cannot come from {} bytes of LZF data", data_size, compressed_size));
    }
    CheckMemoryBudget(SaturatingBytes(data_size, 2), fmt::format("{}: header: POINTS: {} points of {} bytes",
                                                                 file, points, header.point_size));
    std::vector<char> planar(static_cast<size_t>(data_size));
    const unsigned int decompressed =
        data_size == 0 ? 0
                       : lzf_decompress(bytes.data() + header.data_offset + 8, compressed_size, planar.data(),
                                        static_cast<unsigned int>(planar.size()));
    if (decompressed != static_cast<unsigned int>(data_size)) {
      ThrowInputError(file, fmt::format("byte {}", header.data_offset + 8), "compressed data",
                      fmt::format("LZF decompression gave {} bytes, expected {} (corrupt data)", decompressed,
                                  data_size));
    }
    allocate(data_size);
    // binary_compressed stores each field for all points (SoA); interleave into records.
    int64_t plane = 0;
    for (const PcdField& field : header.fields) {
      const int64_t field_bytes = static_cast<int64_t>(field.size) * field.count;
      for (int64_t i = 0; i < points; ++i) {
        std::memcpy(records.data() + i * header.point_size + field.offset,
                    planar.data() + plane + i * field_bytes, field_bytes);
      }
      plane += points * field_bytes;
    }
  } else {
    // ascii: every value into a binary record of the declared type.
    // Every value takes at least a digit and a separator.
    int64_t values_per_point = 0;
    for (const PcdField& field : header.fields) values_per_point += field.count;
    if (static_cast<int64_t>(available) + 1 < SaturatingBytes(points, 2 * values_per_point)) {
      ThrowInputError(file, fmt::format("line {}", header.data_line), "DATA",
                      fmt::format("truncated: {} points of {} values claimed, only {} bytes follow", points,
                                  values_per_point, available));
    }
    allocate(data_size);
    TextCursor cursor(std::string_view(bytes).substr(header.data_offset), file, header.data_line);
    for (int64_t i = 0; i < points; ++i) {
      cursor.SkipEmptyLines();
      if (cursor.AtEnd()) cursor.Fail("", fmt::format("truncated: {} points claimed, found {}", points, i));
      for (const PcdField& field : header.fields) {
        for (int k = 0; k < field.count; ++k) {
          char* out = records.data() + i * header.point_size + field.offset + k * field.size;
          const double value = cursor.Number<double>(field.name, /*allow_nonfinite=*/true);
          if (field.type == 'F' && field.size == 4) {
            const float f = static_cast<float>(value);
            std::memcpy(out, &f, 4);
          } else if (field.type == 'F') {
            std::memcpy(out, &value, 8);
          } else {
            if (!(std::abs(value) < 0x1p63)) cursor.Fail(field.name, "not an integer in range");
            const int64_t integer = static_cast<int64_t>(value);
            const uint64_t bits = static_cast<uint64_t>(integer);
            std::memcpy(out, &bits, field.size);  // little-endian truncation
          }
        }
      }
      cursor.EndLine("the fields of a point");
    }
    cursor.SkipEmptyLines();
    if (!cursor.AtEnd()) cursor.Fail("POINTS", fmt::format("more point lines than the {} claimed", points));
  }

  const bool organized = header.height > 1;
  const int rows = static_cast<int>(header.height), cols = static_cast<int>(header.width);
  const int fx = header.Find("x"), fy = header.Find("y"), fz = header.Find("z");
  int fcolor = header.Find("rgba");
  if (fcolor < 0) fcolor = header.Find("rgb");
  const int fintensity = header.Find("intensity");
  const int flabel = header.Find("label");
  const int fnx = header.Find("normal_x"), fny = header.Find("normal_y"), fnz = header.Find("normal_z");
  const int fcurvature = header.Find("curvature");
  const int fsynth = header.Find("synthesized");
  const int ftrue = header.Find("true_range");
  Scan scan = MakeScan(rows, cols, fcolor >= 0, /*with_intensity=*/fintensity >= 0);
  if (flabel >= 0) scan.label = cv::Mat(rows, cols, CV_32S, cv::Scalar(kNoLabel));
  const bool normals = fnx >= 0 && fny >= 0 && fnz >= 0;
  if (normals) scan.normal = cv::Mat(rows, cols, CV_32FC3, cv::Scalar::all(0));
  if (fcurvature >= 0) scan.curvature = cv::Mat(rows, cols, CV_32F, cv::Scalar(NAN));
  if (fsynth >= 0) scan.synthesized = cv::Mat(rows, cols, CV_8U, cv::Scalar(0));
  if (ftrue >= 0) scan.true_range = cv::Mat(rows, cols, CV_32F, cv::Scalar(0));
  // The file's coordinates are in the VIEWPOINT frame: world = viewpoint · file. lidarshop's own files say
  // in a comment which scan pose they hold (the points are world coordinates); a foreign organized cloud is
  // a camera image in the optical frame, a foreign unorganized one a cloud in the viewpoint's frame.
  scan.world_from_scanner = WorldFromScanner(header, file);
  Eigen::Matrix4d scanner_from_file = Eigen::Matrix4d::Identity();
  if (header.has_scanner_pose)
    scanner_from_file = header.world_from_scanner.inverse() * Viewpoint(header, file);
  else if (organized)
    scanner_from_file = CameraFromScanner().inverse();  // (x, y, z) → (x, z, −y), exactly
  const Eigen::Matrix3d rotate = scanner_from_file.topLeftCorner<3, 3>();
  const Eigen::Vector3d shift = scanner_from_file.topRightCorner<3, 1>();
  const auto& f = header.fields;
  for (int row = 0; row < rows; ++row) {
    for (int col = 0; col < cols; ++col) {
      const char* record = records.data() + (static_cast<int64_t>(row) * cols + col) * header.point_size;
      const double x = LoadValue(record + f[fx].offset, f[fx]);
      const double y = LoadValue(record + f[fy].offset, f[fy]);
      const double z = LoadValue(record + f[fz].offset, f[fz]);
      if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z) || (x == 0 && y == 0 && z == 0))
        continue;
      scan.valid.at<uint8_t>(row, col) = kValid;
      const Eigen::Vector3f p = (rotate * Eigen::Vector3d(x, y, z) + shift).cast<float>();
      scan.point.at<cv::Vec3f>(row, col) = cv::Vec3f(p.x(), p.y(), p.z());
      if (fcolor >= 0) {
        const uint32_t bits = PackedColor(record + f[fcolor].offset, f[fcolor]);
        scan.color.at<cv::Vec3b>(row, col) = cv::Vec3b((bits >> 16) & 0xff, (bits >> 8) & 0xff, bits & 0xff);
      }
      if (fintensity >= 0) {
        const double value = LoadValue(record + f[fintensity].offset, f[fintensity]);
        if (std::isfinite(value)) scan.intensity.at<float>(row, col) = static_cast<float>(value);
      }
      if (flabel >= 0) {
        scan.label.at<int32_t>(row, col) =
            io_internal::ToInt32(LoadValue(record + f[flabel].offset, f[flabel]), kNoLabel);
      }
      if (normals) {
        const double nx = LoadValue(record + f[fnx].offset, f[fnx]);
        const double ny = LoadValue(record + f[fny].offset, f[fny]);
        const double nz = LoadValue(record + f[fnz].offset, f[fnz]);
        if (std::isfinite(nx) && std::isfinite(ny) && std::isfinite(nz)) {
          const Eigen::Vector3f n = (rotate * Eigen::Vector3d(nx, ny, nz)).cast<float>();
          scan.normal.at<cv::Vec3f>(row, col) = cv::Vec3f(n.x(), n.y(), n.z());
        }
      }
      if (fcurvature >= 0) {
        scan.curvature.at<float>(row, col) =
            static_cast<float>(LoadValue(record + f[fcurvature].offset, f[fcurvature]));
      }
      if (fsynth >= 0 && LoadValue(record + f[fsynth].offset, f[fsynth]) != 0) {
        scan.synthesized.at<uint8_t>(row, col) = kValid;
      }
      if (ftrue >= 0) scan.true_range.at<float>(row, col) = LoadValue(record + f[ftrue].offset, f[ftrue]);
    }
  }
  io_internal::FinishScan(&scan, /*fit_grid=*/organized);
  return scan;
}

Scan ReadPcd(const std::string& path) { return ParsePcd(io_internal::ReadFileToString(path), path); }

ScanFileHeader io_internal::ReadPcdHeader(const std::string& path) {
  const int64_t file_bytes = CheckRegularFile(path);
  if (file_bytes == 0) ThrowInputError(path, "byte 0", "", "the file is empty");
  // ParseHeader refuses a header longer than 64 KiB: a little more holds any header it accepts.
  const PcdHeader header = ParseHeader(io_internal::ReadFilePrefix(path, (1 << 16) + 4096), path);
  ScanFileHeader file;
  file.format_version = "PCD DATA " + header.data;
  ScanHeader scan;
  scan.organized = header.height > 1;
  scan.rows = header.height;
  scan.cols = header.width;
  scan.points = header.points;
  scan.world_from_scanner = WorldFromScanner(header, path);
  scan.channels = {"xyz", "range"};
  if (header.Find("intensity") >= 0) scan.channels.push_back("intensity");
  scan.channels.insert(scan.channels.end(), {"valid", "direction"});
  if (header.Find("rgba") >= 0 || header.Find("rgb") >= 0) scan.channels.push_back("rgb");
  if (header.Find("label") >= 0) scan.channels.push_back("label");
  if (header.Find("normal_x") >= 0 && header.Find("normal_y") >= 0 && header.Find("normal_z") >= 0)
    scan.channels.push_back("normal");
  if (header.Find("curvature") >= 0) scan.channels.push_back("curvature");
  if (header.Find("true_range") >= 0) scan.channels.push_back("true_range");
  if (header.Find("synthesized") >= 0) scan.channels.push_back("synthesized");
  file.scans.push_back(scan);
  return file;
}

void WritePcd(const std::string& path, const Scan& scan) {
  CheckScan(scan);
  const Eigen::Matrix4d& world_from_scanner = scan.world_from_scanner;
  const Eigen::Matrix3d rotate = world_from_scanner.topLeftCorner<3, 3>();
  const Eigen::Vector3d shift = world_from_scanner.topRightCorner<3, 1>();
  // Far from the origin (georeferenced scans) floats would lose millimetres: doubles then, as in PLY.
  const bool far = shift.norm() > 1e4;

  std::string fields = "x y z", sizes = far ? "8 8 8" : "4 4 4", types = "F F F", counts = "1 1 1";
  auto add = [&](const char* name, const char* size, const char* type) {
    fields += std::string(" ") + name;
    sizes += std::string(" ") + size;
    types += std::string(" ") + type;
    counts += " 1";
  };
  if (scan.has_color()) add("rgb", "4", "F");
  if (scan.has_intensity()) add("intensity", "4", "F");
  if (!scan.label.empty()) add("label", "4", "I");
  if (!scan.normal.empty()) {
    add("normal_x", "4", "F");
    add("normal_y", "4", "F");
    add("normal_z", "4", "F");
  }
  if (!scan.curvature.empty()) add("curvature", "4", "F");  // PCL's PointNormal field
  if (!scan.synthesized.empty()) add("synthesized", "1", "U");
  if (!scan.true_range.empty()) add("true_range", "4", "F");
  std::string pose;
  for (int i = 0; i < 16; ++i) {
    pose += ' ';
    io_internal::AppendNumber(&pose, world_from_scanner(i / 4, i % 4));
  }
  std::string out = fmt::format(
      "# .PCD v0.7 - Point Cloud Data file format (written by lidarshop)\n# frame world\n# {}{}\n"
      "VERSION 0.7\nFIELDS {}\nSIZE {}\nTYPE {}\nCOUNT {}\nWIDTH {}\nHEIGHT {}\nVIEWPOINT 0 0 0 1 0 0 0\n"
      "POINTS {}\nDATA binary\n",
      kPoseComment, pose, fields, sizes, types, counts, scan.cols, scan.rows, scan.num_cells());
  auto put = [&out](auto value) { out.append(reinterpret_cast<const char*>(&value), sizeof(value)); };
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) {
      const bool valid = scan.valid.at<uint8_t>(row, col) != 0;
      if (valid) {
        const cv::Vec3f& p = scan.point.at<cv::Vec3f>(row, col);
        const Eigen::Vector3d world = rotate * Eigen::Vector3d(p[0], p[1], p[2]) + shift;
        for (int i = 0; i < 3; ++i) far ? put(world[i]) : put(static_cast<float>(world[i]));
      } else {
        for (int i = 0; i < 3; ++i) far ? put(static_cast<double>(nan)) : put(nan);
      }
      if (scan.has_color()) {
        const cv::Vec3b& c = scan.color.at<cv::Vec3b>(row, col);
        const uint32_t bits = (uint32_t{255} << 24) | (uint32_t{c[0]} << 16) | (uint32_t{c[1]} << 8) | c[2];
        put(std::bit_cast<float>(bits));
      }
      if (scan.has_intensity()) put(scan.intensity.at<float>(row, col));
      if (!scan.label.empty()) put(static_cast<int32_t>(scan.label.at<int32_t>(row, col)));
      if (!scan.normal.empty()) {
        const cv::Vec3f& n = scan.normal.at<cv::Vec3f>(row, col);
        const Eigen::Vector3f m = (rotate * Eigen::Vector3d(n[0], n[1], n[2])).cast<float>();
        put(m.x());
        put(m.y());
        put(m.z());
      }
      if (!scan.curvature.empty()) put(valid ? scan.curvature.at<float>(row, col) : nan);
      if (!scan.synthesized.empty())
        put(static_cast<uint8_t>(scan.synthesized.at<uint8_t>(row, col) ? 1 : 0));
      if (!scan.true_range.empty()) put(scan.true_range.at<float>(row, col));
    }
  }
  WriteFileAtomically(path, [&](std::ostream& stream) { stream.write(out.data(), out.size()); });
}

}  // namespace lidarshop
