#include "lidarshop/io/pcd.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
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

  // The field called `name` (lower case), compared without case: PDAL writes FIELDS X Y Z Intensity.
  int Find(const std::string& name) const {
    for (size_t i = 0; i < fields.size(); ++i) {
      const std::string& field = fields[i].name;
      if (field.size() == name.size() &&
          std::equal(field.begin(), field.end(), name.begin(),
                     [](char a, char b) { return std::tolower(static_cast<unsigned char>(a)) == b; })) {
        return static_cast<int>(i);
      }
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
    } else if (header.fields.empty() && (std::isdigit(static_cast<unsigned char>(keyword[0])) ||
                                         keyword[0] == '-' || keyword[0] == '+' || keyword[0] == '.')) {
      cursor.Fail("header", fmt::format("missing: the file starts with data ('{}'), not with the PCD header "
                                        "(VERSION, FIELDS, SIZE, TYPE, COUNT, WIDTH, HEIGHT, POINTS, DATA)",
                                        io_internal::Printable(keyword)));
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

// VIEWPOINT as a matrix: the sensor's pose in the frame of the points (world_from_sensor).
Eigen::Matrix4d Viewpoint(const PcdHeader& header, const std::string& file) {
  const double* v = header.viewpoint;
  for (int i = 0; i < 7; ++i) {
    if (!(std::abs(v[i]) <= kMaxCoordinateM)) {
      ThrowInputError(file, "header", "VIEWPOINT",
                      fmt::format("{} is not a number within {} m", v[i], kMaxCoordinateM));
    }
  }
  Eigen::Matrix4d viewpoint = Eigen::Matrix4d::Identity();
  const Eigen::Quaterniond rotation(v[3], v[4], v[5], v[6]);
  if (rotation.norm() < 1e-9)
    ThrowInputError(file, "header", "VIEWPOINT", "the orientation quaternion is zero");
  viewpoint.topLeftCorner<3, 3>() = rotation.normalized().toRotationMatrix();
  viewpoint.topRightCorner<3, 1>() = Eigen::Vector3d(v[0], v[1], v[2]);
  return viewpoint;
}

// The scan's pose as the header gives it: the one lidarshop's comment names, else VIEWPOINT, turned from the
// optical frame for a foreign organized cloud (a camera image; ParsePcd may choose the OpenGL frame instead
// from where the points lie, and a local origin for points far from the sensor).
Eigen::Matrix4d WorldFromScanner(const PcdHeader& header, const std::string& file) {
  if (header.has_scanner_pose) return header.world_from_scanner;
  const Eigen::Matrix4d viewpoint = Viewpoint(header, file);
  return header.height > 1 ? Eigen::Matrix4d(viewpoint * CameraFromScanner()) : viewpoint;
}

// ---- ParsePcd's steps ----

// Room for `size` bytes of point records, within what lidarshop accepts and the memory budget allows.
void AllocateRecords(int64_t size, const PcdHeader& header, const std::string& file,
                     std::vector<char>* records) {
  if (size > static_cast<int64_t>(kMaxScanCells) * 64) {
    ThrowInputError(file, "header", "POINTS",
                    fmt::format("{} bytes of point data is more than lidarshop accepts", size));
  }
  CheckMemoryBudget(
      size, fmt::format("{}: header: POINTS: {} points of {} bytes", file, header.points, header.point_size));
  records->resize(static_cast<size_t>(size));
}

// DATA binary: the records as the file holds them.
std::vector<char> BinaryRecords(const std::string& bytes, const std::string& file, const PcdHeader& header) {
  const int64_t data_size = header.points * header.point_size;
  const size_t available = bytes.size() - header.data_offset;
  if (static_cast<int64_t>(available) < data_size) {
    ThrowInputError(file, fmt::format("byte {}", bytes.size()), "DATA",
                    fmt::format("truncated: {} points of {} bytes need {} bytes, {} follow the header",
                                header.points, header.point_size, data_size, available));
  }
  std::vector<char> records;
  AllocateRecords(data_size, header, file, &records);
  std::memcpy(records.data(), bytes.data() + header.data_offset, records.size());
  return records;
}

// DATA binary_compressed: LZF of each field for all points (SoA), interleaved into records.
std::vector<char> CompressedRecords(const std::string& bytes, const std::string& file,
                                    const PcdHeader& header) {
  const int64_t points = header.points;
  const int64_t data_size = points * header.point_size;
  const size_t available = bytes.size() - header.data_offset;
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
    ThrowInputError(
        file, fmt::format("byte {}", header.data_offset + 8), "compressed data",
        fmt::format("LZF decompression gave {} bytes, expected {} (corrupt data)", decompressed, data_size));
  }
  std::vector<char> records;
  AllocateRecords(data_size, header, file, &records);
  int64_t plane = 0;
  for (const PcdField& field : header.fields) {
    const int64_t field_bytes = static_cast<int64_t>(field.size) * field.count;
    for (int64_t i = 0; i < points; ++i) {
      std::memcpy(records.data() + i * header.point_size + field.offset,
                  planar.data() + plane + i * field_bytes, field_bytes);
    }
    plane += points * field_bytes;
  }
  return records;
}

// DATA ascii: every value into a binary record of the declared type, except that F values are kept as doubles
// (*header's sizes and offsets are changed to say so): the text holds the file's precision (UTM coordinates in
// a "SIZE 4" field, as PDAL writes them).
std::vector<char> AsciiRecords(const std::string& bytes, const std::string& file, PcdHeader* header) {
  const int64_t points = header->points;
  const size_t available = bytes.size() - header->data_offset;
  // Every value takes at least a digit and a separator.
  int64_t values_per_point = 0;
  for (const PcdField& field : header->fields) values_per_point += field.count;
  if (static_cast<int64_t>(available) + 1 < SaturatingBytes(points, 2 * values_per_point)) {
    ThrowInputError(file, fmt::format("line {}", header->data_line), "DATA",
                    fmt::format("truncated: {} points of {} values claimed, only {} bytes follow", points,
                                values_per_point, available));
  }
  header->point_size = 0;
  for (PcdField& field : header->fields) {
    if (field.type == 'F') field.size = 8;
    field.offset = header->point_size;
    header->point_size += static_cast<int64_t>(field.size) * field.count;
  }
  std::vector<char> records;
  AllocateRecords(points * header->point_size, *header, file, &records);
  TextCursor cursor(std::string_view(bytes).substr(header->data_offset), file, header->data_line);
  // Values separated by blanks (spaces or tabs) or by commas (PDAL's utm17_comma.pcd).
  cursor.set_separator(',');
  for (int64_t i = 0; i < points; ++i) {
    cursor.SkipEmptyLines();
    if (cursor.AtEnd()) cursor.Fail("", fmt::format("truncated: {} points claimed, found {}", points, i));
    for (const PcdField& field : header->fields) {
      for (int k = 0; k < field.count; ++k) {
        char* out = records.data() + i * header->point_size + field.offset + k * field.size;
        const double value = cursor.Number<double>(field.name, /*allow_nonfinite=*/true);
        if (field.type == 'F') {
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
  return records;
}

// The point records in AoS layout (one record after the other), whatever the file used, and the points they
// hold.
struct PcdRecords {
  const PcdHeader& header;
  const std::string& file;
  std::vector<char> bytes;
  bool organized = false;
  int fx = -1, fy = -1, fz = -1;

  const char* Record(int64_t cell) const { return bytes.data() + cell * header.point_size; }
  double Value(int64_t cell, int field) const {
    return LoadValue(Record(cell) + header.fields[field].offset, header.fields[field]);
  }
  // The point of a cell as the file holds it (world frame); false for a missing point (NaN; (0, 0, 0) in an
  // organized cloud, the grid's no-return convention).
  bool Point(int64_t cell, Eigen::Vector3d* point) const {
    *point = Eigen::Vector3d(Value(cell, fx), Value(cell, fy), Value(cell, fz));
    if (!point->allFinite()) return false;
    for (int axis = 0; axis < 3; ++axis) {
      if (!(std::abs((*point)[axis]) <= kMaxCoordinateM)) {
        ThrowInputError(file, fmt::format("point {}", cell), header.fields[std::array{fx, fy, fz}[axis]].name,
                        fmt::format("{} is not a coordinate within {} m", (*point)[axis], kMaxCoordinateM));
      }
    }
    return !(organized && point->isZero());
  }
};

// Which fields beside x, y, z the file has, and how their values scale into a scan's channels.
struct PcdChannels {
  int packed_color = -1;  // rgb / rgba, packed as PCL does
  // PDAL writes colour as three fields Red Green Blue (16-bit); PCL packs it into one rgb/rgba field.
  int red = -1, green = -1, blue = -1;
  bool split_color = false;
  double split_color_scale = 1.0;
  int intensity = -1;
  double intensity_scale = 1.0;
  int label = -1, normal_x = -1, normal_y = -1, normal_z = -1, curvature = -1;
  int synthesized = -1, true_range = -1, from_station = -1;

  bool color() const { return packed_color >= 0 || split_color; }
  bool normals() const { return normal_x >= 0 && normal_y >= 0 && normal_z >= 0; }
};

PcdChannels FindChannels(const PcdRecords& records) {
  const PcdHeader& header = records.header;
  PcdChannels channels;
  channels.packed_color = header.Find("rgba");
  if (channels.packed_color < 0) channels.packed_color = header.Find("rgb");
  channels.red = header.Find("red");
  channels.green = header.Find("green");
  channels.blue = header.Find("blue");
  channels.split_color =
      channels.packed_color < 0 && channels.red >= 0 && channels.green >= 0 && channels.blue >= 0;
  if (channels.split_color) {
    double highest = 0;
    for (int64_t cell = 0; cell < header.points; ++cell) {
      for (int field : {channels.red, channels.green, channels.blue})
        highest = std::max(highest, records.Value(cell, field));
    }
    if (highest > 255) channels.split_color_scale = 1.0 / 257.0;  // 16-bit colour, 65535 -> 255
  }
  channels.intensity = header.Find("intensity");
  // Integer intensities (PDAL writes LAS's 16-bit ones) are scaled by their type's range to [0, 1].
  if (channels.intensity >= 0 && header.fields[channels.intensity].type != 'F') {
    const PcdField& field = header.fields[channels.intensity];
    const int bits = 8 * field.size - (field.type == 'I' ? 1 : 0);
    channels.intensity_scale = 1.0 / (std::ldexp(1.0, bits) - 1.0);
  }
  channels.label = header.Find("label");
  channels.normal_x = header.Find("normal_x");
  channels.normal_y = header.Find("normal_y");
  channels.normal_z = header.Find("normal_z");
  channels.curvature = header.Find("curvature");
  channels.synthesized = header.Find("synthesized");
  channels.true_range = header.Find("true_range");
  channels.from_station = header.Find("from_station");
  return channels;
}

// The file's numbers are the points in the world frame; VIEWPOINT is the sensor's pose in that frame (PCL's
// sensor_origin_ / sensor_orientation_, which PCL, Open3D and CloudCompare do not apply to the points). The
// scan keeps both: WorldPointOfCell gives the file's numbers, world_from_scanner the pose.
Scan UnorganizedPcdScan(const PcdRecords& records, const PcdChannels& channels,
                        std::vector<std::string>* warnings) {
  const PcdHeader& header = records.header;
  std::vector<Eigen::Vector3d> world(static_cast<size_t>(header.points));
  std::vector<uint8_t> valid(static_cast<size_t>(header.points), 0);
  for (int64_t cell = 0; cell < header.points; ++cell)
    valid[cell] = records.Point(cell, &world[cell]) ? 1 : 0;
  const Eigen::Matrix4d preferred =
      header.has_scanner_pose ? header.world_from_scanner : Viewpoint(header, records.file);
  Scan scan =
      io_internal::UnorganizedScan(world, valid, channels.color(), channels.intensity >= 0, preferred);
  // Worth a word only when the file gives a sensor pose (an identity VIEWPOINT is PCL's "unknown").
  if (warnings != nullptr && !header.has_scanner_pose && !preferred.isIdentity() &&
      !scan.world_from_scanner.topRightCorner<3, 1>().isApprox(preferred.topRightCorner<3, 1>())) {
    warnings->push_back(
        fmt::format("{}: the points lie more than {} m from the VIEWPOINT position; the scan's origin is "
                    "moved near them "
                    "so that floats keep 0.1 mm (the points are unchanged)",
                    records.file, io_internal::kCloudFloatSafeM));
  }
  return scan;
}

// An organized cloud is a camera image: the sensor frame is an optical frame, x right, y down, z forward (PCL),
// or the OpenGL one, y up and z backward, which a VIEWPOINT turned half a turn about x gives (PCL's stereo
// data). The points lie in front of the camera: when most lie behind the optical frame the sensor frame is
// the OpenGL one. Either way row 0 is the top of the image, as scans have it.
Eigen::Matrix4d OrganizedWorldFromScanner(const PcdRecords& records) {
  const PcdHeader& header = records.header;
  if (header.has_scanner_pose) return WorldFromScanner(header, records.file);
  const Eigen::Matrix4d file_from_viewpoint = Viewpoint(header, records.file).inverse();
  int64_t front = 0, behind = 0;
  for (int64_t cell = 0; cell < header.points; ++cell) {
    Eigen::Vector3d point;
    if (!records.Point(cell, &point)) continue;
    const double depth = file_from_viewpoint.row(2).head<3>().dot(point) + file_from_viewpoint(2, 3);
    (depth < 0 ? behind : front) += 1;
  }
  if (behind > 9 * front) {
    Eigen::Matrix4d flip = Eigen::Matrix4d::Identity();  // OpenGL from optical: half a turn about x
    flip(1, 1) = flip(2, 2) = -1;
    return Viewpoint(header, records.file) * flip * CameraFromScanner();
  }
  return WorldFromScanner(header, records.file);
}

// The organized cloud's points in the sensor frame; points beyond kScanRangeKeptM of the sensor are read
// relative to a local origin held in the pose (io_common.h).
Scan OrganizedPcdScan(const PcdRecords& records, const PcdChannels& channels,
                      std::vector<std::string>* warnings) {
  const PcdHeader& header = records.header;
  const int rows = static_cast<int>(header.height), cols = static_cast<int>(header.width);
  Scan scan = MakeScan(rows, cols, channels.color(), channels.intensity >= 0);
  scan.world_from_scanner = OrganizedWorldFromScanner(records);
  const Eigen::Matrix4d scanner_from_world = scan.world_from_scanner.inverse();
  const Eigen::Matrix3d rotate = scanner_from_world.topLeftCorner<3, 3>();
  const Eigen::Vector3d shift = scanner_from_world.topRightCorner<3, 1>();
  std::vector<Eigen::Vector3d> in_scanner(static_cast<size_t>(header.points));
  std::vector<uint8_t> valid(static_cast<size_t>(header.points), 0);
  Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), high = -low;
  for (int64_t cell = 0; cell < header.points; ++cell) {
    Eigen::Vector3d point;
    if (!records.Point(cell, &point)) continue;
    valid[cell] = 1;
    in_scanner[cell] = rotate * point + shift;
    low = low.cwiseMin(in_scanner[cell]);
    high = high.cwiseMax(in_scanner[cell]);
  }
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  if ((low.array() <= high.array()).all()) origin = io_internal::FarScanOrigin(low, high);
  if (!origin.isZero()) {
    origin = io_internal::OriginClearOfPoints(origin, in_scanner, valid);
    scan.world_from_scanner.topRightCorner<3, 1>() += scan.world_from_scanner.topLeftCorner<3, 3>() * origin;
    if (warnings != nullptr) {
      warnings->push_back(fmt::format(
          "{}: the points lie more than {} m from the sensor (VIEWPOINT): they are not read as its rays "
          "but "
          "relative to a local origin, so that floats keep 0.1 mm; the directions are from that origin",
          records.file, io_internal::kScanRangeKeptM));
    }
  }
  for (int64_t cell = 0; cell < header.points; ++cell) {
    if (!valid[cell]) continue;
    const Eigen::Vector3f p = (in_scanner[cell] - origin).cast<float>();
    scan.valid.at<uint8_t>(static_cast<int>(cell / cols), static_cast<int>(cell % cols)) = kValid;
    scan.point.at<cv::Vec3f>(static_cast<int>(cell / cols), static_cast<int>(cell % cols)) =
        cv::Vec3f(p.x(), p.y(), p.z());
  }
  return scan;
}

// Colour, intensity, labels, normals (turned into the sensor frame) and lidarshop's own channels of every
// cell with a return.
void ReadChannels(const PcdRecords& records, const PcdChannels& channels, Scan* scan) {
  const PcdHeader& header = records.header;
  const int rows = static_cast<int>(header.height), cols = static_cast<int>(header.width);
  if (channels.label >= 0) scan->label = cv::Mat(rows, cols, CV_32S, cv::Scalar(kNoLabel));
  if (channels.normals()) scan->normal = cv::Mat(rows, cols, CV_32FC3, cv::Scalar::all(0));
  if (channels.curvature >= 0) scan->curvature = cv::Mat(rows, cols, CV_32F, cv::Scalar(NAN));
  if (channels.synthesized >= 0) scan->synthesized = cv::Mat(rows, cols, CV_8U, cv::Scalar(0));
  if (channels.true_range >= 0) scan->true_range = cv::Mat(rows, cols, CV_32F, cv::Scalar(0));
  if (channels.from_station >= 0) scan->from_station = cv::Mat(rows, cols, CV_8U, cv::Scalar(0));
  const Eigen::Matrix3d scanner_from_world_rotation =
      scan->world_from_scanner.topLeftCorner<3, 3>().transpose();
  for (int row = 0; row < rows; ++row) {
    for (int col = 0; col < cols; ++col) {
      if (!scan->valid.at<uint8_t>(row, col)) continue;
      const int64_t cell = static_cast<int64_t>(row) * cols + col;
      if (channels.packed_color >= 0) {
        const PcdField& field = header.fields[channels.packed_color];
        const uint32_t bits = PackedColor(records.Record(cell) + field.offset, field);
        scan->color.at<cv::Vec3b>(row, col) = cv::Vec3b((bits >> 16) & 0xff, (bits >> 8) & 0xff, bits & 0xff);
      } else if (channels.split_color) {
        cv::Vec3b& color = scan->color.at<cv::Vec3b>(row, col);
        const int fields[3] = {channels.red, channels.green, channels.blue};
        for (int c = 0; c < 3; ++c) {
          const double value = records.Value(cell, fields[c]) * channels.split_color_scale;
          color[c] = static_cast<uint8_t>(std::clamp(std::round(value), 0.0, 255.0));
        }
      }
      if (channels.intensity >= 0) {
        const double value = records.Value(cell, channels.intensity) * channels.intensity_scale;
        if (std::isfinite(value)) scan->intensity.at<float>(row, col) = static_cast<float>(value);
      }
      if (channels.label >= 0) {
        scan->label.at<int32_t>(row, col) =
            io_internal::ToInt32(records.Value(cell, channels.label), kNoLabel);
      }
      if (channels.normals()) {
        const Eigen::Vector3d n(records.Value(cell, channels.normal_x),
                                records.Value(cell, channels.normal_y),
                                records.Value(cell, channels.normal_z));
        if (n.allFinite()) {
          const Eigen::Vector3f m = (scanner_from_world_rotation * n).cast<float>();
          scan->normal.at<cv::Vec3f>(row, col) = cv::Vec3f(m.x(), m.y(), m.z());
        }
      }
      if (channels.curvature >= 0) {
        scan->curvature.at<float>(row, col) = static_cast<float>(records.Value(cell, channels.curvature));
      }
      if (channels.synthesized >= 0 && records.Value(cell, channels.synthesized) != 0) {
        scan->synthesized.at<uint8_t>(row, col) = kValid;
      }
      if (channels.true_range >= 0)
        scan->true_range.at<float>(row, col) = records.Value(cell, channels.true_range);
      if (channels.from_station >= 0) {
        const double from = records.Value(cell, channels.from_station);
        scan->from_station.at<uint8_t>(row, col) =
            std::isfinite(from) ? static_cast<uint8_t>(std::clamp(from, 0.0, 255.0)) : 0;
      }
    }
  }
  // Pictures show integer intensities in the file's units (render/render.h).
  if (channels.intensity_scale != 1.0)
    scan->source_metadata["intensity.file_maximum"] = fmt::format("{}", 1.0 / channels.intensity_scale);
}

}  // namespace

Scan ParsePcd(const std::string& bytes, const std::string& file, std::vector<std::string>* warnings) {
  if (bytes.empty()) ThrowInputError(file, "byte 0", "", "the file is empty");
  PcdHeader header = ParseHeader(bytes, file);
  std::vector<char> record_bytes = header.data == "binary" ? BinaryRecords(bytes, file, header)
                                   : header.data == "binary_compressed"
                                       ? CompressedRecords(bytes, file, header)
                                       : AsciiRecords(bytes, file, &header);
  PcdRecords records{header, file, std::move(record_bytes)};
  records.organized = header.height > 1;
  records.fx = header.Find("x");
  records.fy = header.Find("y");
  records.fz = header.Find("z");
  const PcdChannels channels = FindChannels(records);
  Scan scan = records.organized ? OrganizedPcdScan(records, channels, warnings)
                                : UnorganizedPcdScan(records, channels, warnings);
  ReadChannels(records, channels, &scan);
  io_internal::FinishScan(&scan, /*fit_grid=*/records.organized);
  return scan;
}

Scan ReadPcd(const std::string& path, std::vector<std::string>* warnings) {
  return ParsePcd(io_internal::ReadFileToString(path), path, warnings);
}

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
  if (header.Find("from_station") >= 0) scan.channels.push_back("from_station");
  file.scans.push_back(scan);
  return file;
}

bool PcdNeedsDoubleCoordinates(const Scan& scan) {
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) {
      if (!scan.valid.at<uint8_t>(row, col)) continue;
      if (WorldPointOfCell(scan, row, col).cwiseAbs().maxCoeff() > io_internal::kCloudFloatSafeM) return true;
    }
  }
  return false;
}

void WritePcd(const std::string& path, const Scan& scan) {
  CheckScan(scan);
  const Eigen::Matrix4d& world_from_scanner = scan.world_from_scanner;
  const Eigen::Matrix3d rotate = world_from_scanner.topLeftCorner<3, 3>();
  const Eigen::Vector3d shift = world_from_scanner.topRightCorner<3, 1>();
  // Far from the origin (georeferenced scans) floats would lose precision: doubles then (pcd.h).
  const bool far = PcdNeedsDoubleCoordinates(scan);
  // VIEWPOINT: the sensor's pose; an organized scan's sensor frame as PCL's optical frame (pcd.h).
  const Eigen::Matrix4d viewpoint = scan.rows > 1
                                        ? Eigen::Matrix4d(world_from_scanner * CameraFromScanner().inverse())
                                        : world_from_scanner;
  const Eigen::Quaterniond orientation(Eigen::Matrix3d(viewpoint.topLeftCorner<3, 3>()));
  std::string viewpoint_text;
  for (double value : {viewpoint(0, 3), viewpoint(1, 3), viewpoint(2, 3), orientation.w(), orientation.x(),
                       orientation.y(), orientation.z()}) {
    if (!viewpoint_text.empty()) viewpoint_text += ' ';
    io_internal::AppendNumber(&viewpoint_text, value);
  }

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
  if (!scan.from_station.empty()) add("from_station", "1", "U");
  std::string pose;
  for (int i = 0; i < 16; ++i) {
    pose += ' ';
    io_internal::AppendNumber(&pose, world_from_scanner(i / 4, i % 4));
  }
  std::string out = fmt::format(
      "# .PCD v0.7 - Point Cloud Data file format (written by lidarshop)\n# frame world\n# {}{}\n"
      "VERSION 0.7\nFIELDS {}\nSIZE {}\nTYPE {}\nCOUNT {}\nWIDTH {}\nHEIGHT {}\nVIEWPOINT {}\n"
      "POINTS {}\nDATA binary\n",
      kPoseComment, pose, fields, sizes, types, counts, scan.cols, scan.rows, viewpoint_text,
      scan.num_cells());
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
      if (!scan.from_station.empty()) put(static_cast<uint8_t>(scan.from_station.at<uint8_t>(row, col)));
    }
  }
  WriteFileAtomically(path, [&](std::ostream& stream) { stream.write(out.data(), out.size()); });
}

}  // namespace lidarshop
