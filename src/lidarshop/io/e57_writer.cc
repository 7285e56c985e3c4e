// E57 writer: one compressed-vector section per scan, then the XML section, then pages with CRC-32C.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <limits>
#include <optional>
#include <sstream>

#include <Eigen/Geometry>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <pugixml.hpp>

#include "lidarshop/geometry/transform.h"
#include "lidarshop/io/e57.h"
#include "lidarshop/io/e57_format.h"
#include "lidarshop/io/image_io.h"
#include "lidarshop/scan/ray_directions.h"
#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"

namespace lidarshop {
namespace e57 {
namespace {

std::string Num(double v) { return fmt::format("{}", v); }

pugi::xml_node AddTyped(pugi::xml_node parent, const char* name, const char* type) {
  pugi::xml_node n = parent.append_child(name);
  n.append_attribute("type") = type;
  return n;
}
void AddFloat(pugi::xml_node parent, const char* name, double v) {
  AddTyped(parent, name, "Float").text() = Num(v).c_str();
}
void AddInteger(pugi::xml_node parent, const char* name, int64_t v) {
  AddTyped(parent, name, "Integer").text() = std::to_string(v).c_str();
}
void AddString(pugi::xml_node parent, const char* name, const std::string& v) {
  AddTyped(parent, name, "String").append_child(pugi::node_cdata).set_value(v.c_str());
}

void AddPrototypeField(pugi::xml_node prototype, const Field& f) {
  switch (f.type) {
    case Field::Type::kInteger: {
      pugi::xml_node n = AddTyped(prototype, f.name.c_str(), "Integer");
      n.append_attribute("minimum") = std::to_string(f.minimum).c_str();
      n.append_attribute("maximum") = std::to_string(f.maximum).c_str();
      break;
    }
    case Field::Type::kScaledInteger: {
      pugi::xml_node n = AddTyped(prototype, f.name.c_str(), "ScaledInteger");
      n.append_attribute("minimum") = std::to_string(f.minimum).c_str();
      n.append_attribute("maximum") = std::to_string(f.maximum).c_str();
      n.append_attribute("scale") = Num(f.scale).c_str();
      if (f.offset != 0.0) n.append_attribute("offset") = Num(f.offset).c_str();
      break;
    }
    case Field::Type::kFloat:
      AddTyped(prototype, f.name.c_str(), "Float").append_attribute("precision") = "single";
      break;
    case Field::Type::kDouble:
      AddTyped(prototype, f.name.c_str(), "Float").append_attribute("precision") = "double";
      break;
  }
}

// One record of a compressed vector: a cell of the front scan (layer 0) or of the layer behind it (layer 1).
struct Record {
  int64_t cell = 0;   // row * cols + col, image orientation
  uint8_t state = 0;  // cartesianInvalidState: 0 = a return, 2 = no return (zero coordinates)
  uint8_t layer = 0;  // returnIndex
};

// The records of a scan and its second layer in file order, made one at a time (a station has tens of
// millions): the valid cells and after each cell its second return. A cell without a return has no record
// (as scanners write them: readers that ignore cartesianInvalidState see no junk), except before a second
// return, where a record at zero coordinates with cartesianInvalidState 2 keeps the cell's first return index.
class RecordCursor {
 public:
  RecordCursor(const Scan& scan, const uint8_t* behind_valid) : scan_(&scan), behind_valid_(behind_valid) {}
  // The next record; call only while records remain.
  Record Next() {
    while (head_ == size_) {
      head_ = size_ = 0;
      const int64_t c = cell_++;
      const bool has_second = behind_valid_ != nullptr && behind_valid_[c];
      if (scan_->valid.at<uint8_t>(static_cast<int>(c / scan_->cols), static_cast<int>(c % scan_->cols))) {
        queue_[size_++] = {c, 0, 0};
      } else if (has_second) {
        queue_[size_++] = {c, 2, 0};
      }
      if (has_second) queue_[size_++] = {c, 0, 1};
    }
    return queue_[head_++];
  }

 private:
  const Scan* scan_;
  const uint8_t* behind_valid_;
  int64_t cell_ = 0;
  Record queue_[2];
  int head_ = 0, size_ = 0;
};

// A stream of one value per record, packed as the packets take it: `value(record, writer)` puts one value.
template <typename PutValue>
StreamSource RecordStream(Field field, const Scan& scan, const uint8_t* behind_valid, PutValue put_value) {
  RecordCursor cursor(scan, behind_valid);
  return {std::move(field), [cursor, put_value](int64_t, int64_t count, BitWriter* writer) mutable {
            for (int64_t i = 0; i < count; ++i) put_value(cursor.Next(), writer);
          }};
}

// The E57 pose (unit quaternion with w >= 0, translation) of `transform` under `parent`.
void AddPose(pugi::xml_node parent, const Eigen::Matrix4d& transform);

// lidarshop's extension element `lidarshop:angularGrid` under a data3D entry (e57.h): the azimuth of every
// columnIndex and the elevation of every rowIndex in lidarshop's scanner frame, radians, as Vectors of double
// Floats written in their shortest exact form, and whether the grid was fitted to measured points.
void AddAngularGrid(pugi::xml_node child, const ScanGrid& grid) {
  pugi::xml_node extension = AddTyped(child, kAngularGridField, "Structure");
  for (const auto& [name, angles] :
       {std::pair<const char*, const std::vector<double>*>{"azimuth", &grid.azimuth_rad},
        {"elevation", &grid.elevation_rad}}) {
    pugi::xml_node vector = AddTyped(extension, name, "Vector");
    vector.append_attribute("allowHeterogeneousChildren") = "0";
    for (const double angle : *angles) AddFloat(vector, "value", angle);
  }
  AddInteger(extension, "fitted", grid.fitted ? 1 : 0);
}

// lidarshop's extension element `lidarshop:noReturnDirections` under a data3D entry (`child`): a Structure
// holding a `points` CompressedVector of one record per cell without a return (`cells`, row-major image
// order): rowIndex, columnIndex as in the scan's points, and the cell's unit ray as cartesianX/Y/Z in single
// floats (bit-exact). Readers that do not know the namespace skip it.
void AppendNoReturnDirections(const Scan& scan, const RayDirections& rays,
                              const std::function<bool(int64_t)>& has_direction, int64_t m, LogicalSink* sink,
                              pugi::xml_node child) {
  // Each stream walks the cells that have a direction, in order.
  auto cell_stream = [&](Field field, auto put_value) {
    int64_t next = 0;
    return StreamSource{std::move(field), [&scan, &has_direction, next, put_value](
                                              int64_t, int64_t count, BitWriter* writer) mutable {
                          for (int64_t i = 0; i < count; ++i) {
                            while (!has_direction(next)) ++next;
                            put_value(next++, writer);
                          }
                        }};
  };
  std::vector<StreamSource> streams;
  streams.push_back(cell_stream(IntegerField("rowIndex", 0, std::max(scan.rows - 1, 0)),
                                [&scan](int64_t c, BitWriter* w) { w->PutInteger(c / scan.cols, 0); }));
  streams.push_back(cell_stream(IntegerField("columnIndex", 0, std::max(scan.cols - 1, 0)),
                                [&scan](int64_t c, BitWriter* w) { w->PutInteger(c % scan.cols, 0); }));
  const char* axis_names[3] = {"cartesianX", "cartesianY", "cartesianZ"};
  for (int axis = 0; axis < 3; ++axis) {
    Field field;
    field.name = axis_names[axis];
    field.type = Field::Type::kFloat;
    field.bits = 32;
    streams.push_back(
        cell_stream(field, [&rays, axis](int64_t c, BitWriter* w) { w->PutFloat(rays.At(c)[axis]); }));
  }
  const uint64_t offset = AppendCompressedVector(streams, m, sink);
  pugi::xml_node extension = AddTyped(child, kNoReturnDirectionsField, "Structure");
  pugi::xml_node points = AddTyped(extension, "points", "CompressedVector");
  points.append_attribute("fileOffset") = std::to_string(offset).c_str();
  points.append_attribute("recordCount") = std::to_string(m).c_str();
  pugi::xml_node prototype = AddTyped(points, "prototype", "Structure");
  for (const StreamSource& s : streams) AddPrototypeField(prototype, s.field);
  AddTyped(points, "codecs", "Vector").append_attribute("allowHeterogeneousChildren") = "1";
}

// Appends one data3D entry; `behind` (may be null) is a second layer of the same grid whose valid cells
// become second returns. Returns whether lidarshop's extension (namespace) is used.
bool AppendScan(const Scan& scan, const Scan* behind, int index, const E57WriteOptions& options,
                LogicalSink* sink, pugi::xml_node data3d) {
  CheckScan(scan);
  if (!IsRigid(scan.world_from_scanner, 1e-6)) {
    throw InputError(
        fmt::format("scan {} ('{}'): world_from_scanner is not rigid; E57 stores a rotation and a "
                    "translation only",
                    index, scan.name));
  }
  if (behind != nullptr) {
    CheckScan(*behind);
    LIDARSHOP_CHECK(behind->rows == scan.rows && behind->cols == scan.cols);
  }
  // One pass over the records (RecordCursor's order) for what the prototype and the XML need before the
  // streams are made: their count, the valid points' bounds, whether any record is a placeholder.
  const uint8_t* behind_valid = behind != nullptr ? behind->valid.ptr<uint8_t>() : nullptr;
  int64_t n = 0, direction_count = 0;
  bool any_invalid = false;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  double lo[3] = {kInf, kInf, kInf},
         hi[3] = {-kInf, -kInf, -kInf};  // over valid points; 0 when there are none
  auto extend = [&](const cv::Vec3f& p) {
    for (int axis = 0; axis < 3; ++axis) {
      lo[axis] = std::min(lo[axis], static_cast<double>(p[axis]));
      hi[axis] = std::max(hi[axis], static_cast<double>(p[axis]));
    }
  };
  // The grid goes to lidarshop's extension when complete (unless the file is to hold no ray: then readers fit
  // it); the rays of no-return cells that are the grid's bit for bit need no record beside it, the others go
  // to lidarshop's extension too (below).
  const bool write_grid = options.write_no_return_directions && HasCompleteGrid(scan) && scan.num_cells() > 0;
  std::optional<RayDirections> rays, grid_rays;
  if (HasRayDirections(scan)) rays.emplace(scan);
  if (write_grid) grid_rays.emplace(scan.grid);
  const std::function<bool(int64_t)> has_direction = [&scan, &options, &rays, &grid_rays](int64_t c) {
    if (scan.valid.ptr<uint8_t>()[c] || !options.write_no_return_directions || !rays) return false;
    if (grid_rays && rays->from_grid()) return false;
    const cv::Vec3f d = rays->At(c);
    if (grid_rays) {
      const cv::Vec3f g = grid_rays->At(c);
      if (std::memcmp(&d, &g, sizeof(d)) == 0) return false;
    }
    return d.dot(d) > 0.0f && std::isfinite(d.dot(d));
  };
  for (int64_t c = 0; c < scan.num_cells(); ++c) {
    const int r = static_cast<int>(c / scan.cols), k = static_cast<int>(c % scan.cols);
    const bool has_second = behind_valid != nullptr && behind_valid[c];
    if (scan.valid.at<uint8_t>(r, k)) {
      ++n;
      extend(scan.point.ptr<cv::Vec3f>()[c]);
    } else {
      direction_count += has_direction(c);
      if (has_second) ++n, any_invalid = true;
    }
    if (has_second) ++n, extend(behind->point.ptr<cv::Vec3f>()[c]);
  }
  auto layer_of = [&scan, behind](const Record& record) -> const Scan& {
    return record.layer == 0 ? scan : *behind;
  };
  auto xyz_of = [layer_of](const Record& record, int axis) {
    return record.state == 0 ? layer_of(record).point.ptr<cv::Vec3f>()[record.cell][axis] : 0.0f;
  };

  std::vector<StreamSource> streams;
  auto add = [&](Field field, auto put_value) {
    streams.push_back(RecordStream(std::move(field), scan, behind_valid, put_value));
  };
  const char* axis_names[3] = {"cartesianX", "cartesianY", "cartesianZ"};
  for (int axis = 0; axis < 3; ++axis) {
    Field field;
    field.name = axis_names[axis];
    if (options.coordinate_scale_m > 0) {
      const double step = options.coordinate_scale_m;
      int64_t raw_min = 0, raw_max = 0;
      RecordCursor cursor(scan, behind_valid);
      for (int64_t i = 0; i < n; ++i) {
        const double v = xyz_of(cursor.Next(), axis);
        if (!std::isfinite(v) || std::abs(v / step) > 4e18) {
          throw InputError(fmt::format("scan {}: coordinate {} does not fit a scaled integer", index, v));
        }
        const int64_t raw = std::llround(v / step);
        raw_min = i == 0 ? raw : std::min(raw_min, raw);
        raw_max = i == 0 ? raw : std::max(raw_max, raw);
      }
      field.type = Field::Type::kScaledInteger;
      field.scale = step;
      field.minimum = raw_min;
      field.maximum = raw_max;
      field.bits = BitsForRange(raw_min, raw_max);
      add(field, [xyz_of, axis, step, raw_min](const Record& record, BitWriter* w) {
        w->PutInteger(std::llround(xyz_of(record, axis) / step), raw_min);
      });
    } else {
      field.type = Field::Type::kFloat;
      field.bits = 32;
      add(field, [xyz_of, axis](const Record& record, BitWriter* w) { w->PutFloat(xyz_of(record, axis)); });
    }
  }
  if (scan.has_intensity()) {  // no intensity field for a scan without intensity
    Field field;
    field.name = "intensity";
    field.type = Field::Type::kFloat;
    field.bits = 32;
    add(field, [layer_of](const Record& record, BitWriter* w) {
      const Scan& from = layer_of(record);  // a layer without intensity gets the no-information value
      w->PutFloat(from.has_intensity() ? from.intensity.ptr<float>()[record.cell] : 0.5f);
    });
  }
  if (scan.has_color()) {
    const char* names[3] = {"colorRed", "colorGreen", "colorBlue"};
    for (int ch = 0; ch < 3; ++ch) {
      add(IntegerField(names[ch], 0, 255), [layer_of, ch](const Record& record, BitWriter* w) {
        const Scan& from = layer_of(record);  // a layer without colour is written black
        w->PutInteger(from.has_color() ? from.color.ptr<uint8_t>()[3 * record.cell + ch] : 0, 0);
      });
    }
  }
  const int64_t cols = scan.cols;
  add(IntegerField("rowIndex", 0, std::max(scan.rows - 1, 0)),
      [cols](const Record& record, BitWriter* w) { w->PutInteger(record.cell / cols, 0); });
  add(IntegerField("columnIndex", 0, std::max(scan.cols - 1, 0)),
      [cols](const Record& record, BitWriter* w) { w->PutInteger(record.cell % cols, 0); });
  add(IntegerField("cartesianInvalidState", 0, any_invalid ? 2 : 0),
      [](const Record& record, BitWriter* w) { w->PutInteger(record.state, 0); });
  if (behind != nullptr) {
    // Only files with a second layer carry return fields, so single-layer files stay as they were.
    add(IntegerField("returnIndex", 0, 1),
        [](const Record& record, BitWriter* w) { w->PutInteger(record.layer, 0); });
    add(IntegerField("returnCount", 1, 2), [behind_valid](const Record& record, BitWriter* w) {
      w->PutInteger(behind_valid[record.cell] ? 2 : 1, 1);
    });
  }
  const bool write_synthesized = behind != nullptr || !scan.synthesized.empty();
  if (write_synthesized) {
    // The front scan says per cell; the second layer too when it has the channel, else it is synthesized by
    // definition (the layer behind a kept object).
    const uint8_t* flags = scan.synthesized.empty() ? nullptr : scan.synthesized.ptr<uint8_t>();
    const uint8_t* behind_flags =
        behind == nullptr || behind->synthesized.empty() ? nullptr : behind->synthesized.ptr<uint8_t>();
    add(IntegerField(kSynthesizedField, 0, 1), [flags, behind_flags](const Record& record, BitWriter* w) {
      const int64_t c = record.cell;
      const bool synthesized = record.layer == 1 ? (behind_flags == nullptr || behind_flags[c] != 0)
                                                 : (flags != nullptr && flags[c] != 0);
      w->PutInteger(synthesized ? 1 : 0, 0);
    });
  }
  // The cells taken from another station's measurement (site/from_stations.h), per layer when it has them.
  const bool write_from_station =
      !scan.from_station.empty() || (behind != nullptr && !behind->from_station.empty());
  if (write_from_station) {
    add(IntegerField(kFromStationField, 0, 255), [layer_of](const Record& record, BitWriter* w) {
      const Scan& from = layer_of(record);
      w->PutInteger(from.from_station.empty() ? 0 : from.from_station.ptr<uint8_t>()[record.cell], 0);
    });
  }

  for (int axis = 0; axis < 3; ++axis) {
    if (lo[axis] > hi[axis]) lo[axis] = hi[axis] = 0.0;
  }
  const uint64_t offset = AppendCompressedVector(streams, n, sink);

  pugi::xml_node child = AddTyped(data3d, "vectorChild", "Structure");
  const auto kept = [&scan](const char* key) {
    const auto found = scan.source_metadata.find(key);
    return found == scan.source_metadata.end() ? std::string() : found->second;
  };
  // The guid the scan was read with (an edited scan is still that scan), else one made from its bytes.
  const std::string guid = kept("e57.guid");
  AddString(
      child, "guid",
      !guid.empty() ? guid : fmt::format("{{lidarshop-scan-{:04d}-{:08x}}}", index, sink->TailCrc(4096)));
  AddString(child, "name", scan.name.empty() ? fmt::format("scan{:03d}", index) : scan.name);
  AddString(child, "description", "written by lidarshop");
  for (const auto& [element, key] : kE57MetadataStrings) {
    if (std::string(element) != "guid" && !kept(key).empty()) AddString(child, element, kept(key));
  }
  for (const auto& [element, key] : kE57MetadataTimes) {
    const std::string text = kept(key);
    char* end = nullptr;
    const double gps_s = text.empty() ? 0.0 : std::strtod(text.c_str(), &end);
    if (text.empty() || *end != '\0' || !std::isfinite(gps_s)) continue;  // not a time lidarshop read
    pugi::xml_node time = AddTyped(child, element, "Structure");
    AddFloat(time, "dateTimeValue", gps_s);
    AddInteger(time, "isAtomicClockReferenced", 0);
  }
  AddPose(child, scan.world_from_scanner);
  {
    pugi::xml_node b = AddTyped(child, "indexBounds", "Structure");
    AddInteger(b, "rowMinimum", 0);
    AddInteger(b, "rowMaximum", std::max(scan.rows - 1, 0));
    AddInteger(b, "columnMinimum", 0);
    AddInteger(b, "columnMaximum", std::max(scan.cols - 1, 0));
    AddInteger(b, "returnMinimum", 0);
    AddInteger(b, "returnMaximum", behind != nullptr ? 1 : 0);
  }
  {
    pugi::xml_node b = AddTyped(child, "cartesianBounds", "Structure");
    AddFloat(b, "xMinimum", lo[0]);
    AddFloat(b, "xMaximum", hi[0]);
    AddFloat(b, "yMinimum", lo[1]);
    AddFloat(b, "yMaximum", hi[1]);
    AddFloat(b, "zMinimum", lo[2]);
    AddFloat(b, "zMaximum", hi[2]);
  }
  if (scan.has_intensity()) {
    pugi::xml_node l = AddTyped(child, "intensityLimits", "Structure");
    AddFloat(l, "intensityMinimum", 0.0);
    AddFloat(l, "intensityMaximum", 1.0);
  }
  if (scan.has_color()) {
    pugi::xml_node l = AddTyped(child, "colorLimits", "Structure");
    AddInteger(l, "colorRedMinimum", 0);
    AddInteger(l, "colorRedMaximum", 255);
    AddInteger(l, "colorGreenMinimum", 0);
    AddInteger(l, "colorGreenMaximum", 255);
    AddInteger(l, "colorBlueMinimum", 0);
    AddInteger(l, "colorBlueMaximum", 255);
  }
  pugi::xml_node points = AddTyped(child, "points", "CompressedVector");
  points.append_attribute("fileOffset") = std::to_string(offset).c_str();
  points.append_attribute("recordCount") = std::to_string(n).c_str();
  pugi::xml_node prototype = AddTyped(points, "prototype", "Structure");
  for (const StreamSource& s : streams) AddPrototypeField(prototype, s.field);
  pugi::xml_node codecs = AddTyped(points, "codecs", "Vector");
  codecs.append_attribute("allowHeterogeneousChildren") = "1";
  if (write_grid) AddAngularGrid(child, scan.grid);
  if (direction_count > 0) AppendNoReturnDirections(scan, *rays, has_direction, direction_count, sink, child);
  return write_grid || direction_count > 0 || write_synthesized || write_from_station;
}

void AddPose(pugi::xml_node parent, const Eigen::Matrix4d& transform) {
  Eigen::Quaterniond q(Eigen::Matrix3d(transform.topLeftCorner<3, 3>()));
  q.normalize();
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  pugi::xml_node pose = AddTyped(parent, "pose", "Structure");
  pugi::xml_node r = AddTyped(pose, "rotation", "Structure");
  AddFloat(r, "w", q.w());
  AddFloat(r, "x", q.x());
  AddFloat(r, "y", q.y());
  AddFloat(r, "z", q.z());
  pugi::xml_node t = AddTyped(pose, "translation", "Structure");
  AddFloat(t, "x", transform(0, 3));
  AddFloat(t, "y", transform(1, 3));
  AddFloat(t, "z", transform(2, 3));
}

// Appends a blob section holding `bytes` and returns its logical offset.
uint64_t AppendBlob(const std::vector<uint8_t>& bytes, LogicalSink* sink) {
  sink->AlignTo8();
  const uint64_t start = sink->size();
  uint8_t header[16] = {};  // sectionId 0 (blob), reserved, sectionLogicalLength
  const uint64_t section_length = 16 + bytes.size();
  std::memcpy(header + 8, &section_length, 8);
  sink->Append(header, sizeof(header));
  sink->Append(bytes.data(), bytes.size());
  return start;
}

void AddBlob(pugi::xml_node parent, const char* name, const std::vector<uint8_t>& bytes, LogicalSink* sink) {
  const uint64_t start = AppendBlob(bytes, sink);
  pugi::xml_node blob = AddTyped(parent, name, "Blob");
  blob.append_attribute("fileOffset") = std::to_string(PhysicalFromLogical(start)).c_str();
  blob.append_attribute("length") = std::to_string(bytes.size()).c_str();
}

// Appends one images2D entry: blob sections with the photo's bytes (and its mask's) and its XML element.
// `scan_guids` are the guids of the data3D entries written (associatedData3DGuid).
void AppendImage(const E57Image& image, int index, const std::vector<std::string>& scan_guids,
                 LogicalSink* sink, pugi::xml_node images2d) {
  std::vector<uint8_t> bytes = image.encoded;
  std::string encoding = image.encoding;
  if (bytes.empty()) {
    if (image.image.empty()) return;
    cv::Mat bgr;
    cv::cvtColor(image.image, bgr, cv::COLOR_RGB2BGR);
    CvImEncode(".png", bgr, &bytes);
    encoding = "png";
  }
  static const std::pair<const char*, const char*> kRepresentations[] = {
      {"pinhole", "pinholeRepresentation"},
      {"spherical", "sphericalRepresentation"},
      {"cylindrical", "cylindricalRepresentation"},
      {"visual", "visualReferenceRepresentation"}};
  const char* element = "visualReferenceRepresentation";
  for (const auto& [projection, name] : kRepresentations) {
    if (image.projection == projection) element = name;
  }
  pugi::xml_node child = AddTyped(images2d, "vectorChild", "Structure");
  AddString(child, "guid",
            !image.guid.empty() ? image.guid
                                : fmt::format("{{lidarshop-image-{:04d}-{:08x}}}", index,
                                              Crc32c(bytes.data(), bytes.size())));
  AddString(child, "name", image.name.empty() ? fmt::format("image{:03d}", index) : image.name);
  if (!image.description.empty()) AddString(child, "description", image.description);
  if (image.associated_scan >= 0 && image.associated_scan < static_cast<int>(scan_guids.size()))
    AddString(child, "associatedData3DGuid", scan_guids[image.associated_scan]);
  AddPose(child, image.world_from_camera);
  pugi::xml_node rep = AddTyped(child, element, "Structure");
  AddBlob(rep, encoding == "jpeg" ? "jpegImage" : "pngImage", bytes, sink);
  if (!image.mask_encoded.empty()) AddBlob(rep, "imageMask", image.mask_encoded, sink);
  AddInteger(rep, "imageWidth", image.width_px ? image.width_px : image.image.cols);
  AddInteger(rep, "imageHeight", image.height_px ? image.height_px : image.image.rows);
  if (image.projection == "pinhole") {
    AddFloat(rep, "focalLength", image.focal_length_m);
    AddFloat(rep, "pixelWidth", image.pixel_width_m);
    AddFloat(rep, "pixelHeight", image.pixel_height_m);
    AddFloat(rep, "principalPointX", image.principal_x_px);
    AddFloat(rep, "principalPointY", image.principal_y_px);
  } else if (image.projection == "spherical") {
    AddFloat(rep, "pixelWidth", image.pixel_width_rad > 0 ? image.pixel_width_rad : image.pixel_width_m);
    AddFloat(rep, "pixelHeight", image.pixel_height_rad > 0 ? image.pixel_height_rad : image.pixel_height_m);
  } else if (image.projection == "cylindrical") {
    AddFloat(rep, "pixelWidth", image.pixel_width_rad > 0 ? image.pixel_width_rad : image.pixel_width_m);
    AddFloat(rep, "pixelHeight", image.pixel_height_m);
    AddFloat(rep, "radius", image.radius_m);
    AddFloat(rep, "principalPointY", image.principal_y_px);
  }
}

}  // namespace
}  // namespace e57

void E57WriteOptions::Check() const { Validate(*this); }

namespace e57 {
namespace {

// The file of `scans` and `image_list` into `sink`; `behind` (may be null, else one per scan, 0 x 0 = none)
// holds the second layer of each scan.
void EncodeTo(const std::vector<Scan>& scans, const std::vector<const Scan*>* behind,
              const std::vector<E57Image>& image_list, const E57WriteOptions& options, LogicalSink* sink) {
  options.Check();
  sink->AppendZeros(kHeaderSize);
  pugi::xml_document doc;
  pugi::xml_node decl = doc.append_child(pugi::node_declaration);
  decl.append_attribute("version") = "1.0";
  decl.append_attribute("encoding") = "UTF-8";
  pugi::xml_node root = AddTyped(doc, "e57Root", "Structure");
  root.append_attribute("xmlns") = "http://www.astm.org/COMMIT/E57/2010-e57-v1.0";
  AddString(root, "formatName", "ASTM E57 3D Imaging Data File");
  AddInteger(root, "versionMajor", 1);
  AddInteger(root, "versionMinor", 0);
  AddString(root, "e57LibraryVersion", "lidarshop");
  pugi::xml_node data3d = AddTyped(root, "data3D", "Vector");
  data3d.append_attribute("allowHeterogeneousChildren") = "1";
  bool extension = false;
  for (size_t i = 0; i < scans.size(); ++i) {
    const Scan* layer = behind != nullptr ? (*behind)[i] : nullptr;
    if (layer != nullptr && layer->num_cells() == 0) layer = nullptr;
    extension |= AppendScan(scans[i], layer, static_cast<int>(i), options, sink, data3d);
  }
  // E2807 declares extensions by an XML namespace on e57Root; readers that do not know it skip its fields.
  if (extension) root.append_attribute(kExtensionXmlns) = kLidarshopE57Namespace;
  pugi::xml_node images = AddTyped(root, "images2D", "Vector");
  images.append_attribute("allowHeterogeneousChildren") = "1";
  std::vector<std::string> scan_guids;
  for (pugi::xml_node scan : root.child("data3D").children("vectorChild"))
    scan_guids.push_back(scan.child("guid").text().get());
  for (size_t i = 0; i < image_list.size(); ++i)
    AppendImage(image_list[i], static_cast<int>(i), scan_guids, sink, images);
  // The file guid: a checksum of the binary sections, so that the same scans give the same bytes.
  pugi::xml_node guid = AddTyped(root, "guid", "String");
  guid.append_child(pugi::node_cdata)
      .set_value(fmt::format("{{lidarshop-{:08x}-{:016x}}}", sink->crc(), sink->size()).c_str());
  root.insert_move_after(guid, root.child("formatName"));

  std::ostringstream xml;
  doc.save(xml, "  ", pugi::format_default, pugi::encoding_utf8);
  const std::string text = xml.str();
  sink->AlignTo8();
  Header header;
  header.xml_physical_offset = PhysicalFromLogical(sink->size());
  header.xml_logical_length = text.size();
  sink->Append(reinterpret_cast<const uint8_t*>(text.data()), text.size());
  const uint64_t pages = (sink->size() + kPagePayload - 1) / kPagePayload;
  header.file_physical_length = pages * kPageSize;
  sink->StoreFileHeader(header);
  sink->Finish();
}

std::vector<uint8_t> Encode(const std::vector<Scan>& scans, const std::vector<const Scan*>* behind,
                            const std::vector<E57Image>& image_list, const E57WriteOptions& options) {
  std::vector<uint8_t> logical;
  LogicalSink sink(&logical);
  EncodeTo(scans, behind, image_list, options, &sink);
  return PagesFromLogical(logical);
}

// Writes the file's pages as they are made: neither the file nor its bytestreams are held whole.
void WriteFile(const std::string& path, const std::vector<Scan>& scans,
               const std::vector<const Scan*>* behind, const std::vector<E57Image>& image_list,
               const E57WriteOptions& options) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    LogicalSink sink(&out);
    EncodeTo(scans, behind, image_list, options, &sink);
  });
}

}  // namespace
}  // namespace e57

namespace e57 {
namespace {

// The second layers the writer takes (one per scan, null = none), and the scans they are made of.
struct Layers {
  std::vector<Scan> scans;
  std::vector<const Scan*> of_scan;
};

// `behind` as the layer of `front`: every second return is synthesized here (the contract).
Layers SynthesizedLayer(const Scan& behind) {
  Layers layers;
  layers.scans.push_back(behind);  // shares the buffers
  layers.scans[0].synthesized = cv::Mat();
  layers.of_scan = {&layers.scans[0]};
  return layers;
}

// The second returns of `file`, each scan's own.
Layers SecondReturns(const E57File& file) {
  Layers layers;
  layers.scans.resize(file.scans.size());  // share the file's buffers
  layers.of_scan.assign(file.scans.size(), nullptr);
  for (size_t i = 0; i < file.scans.size() && i < file.second_returns.size(); ++i) {
    Scan& second = layers.scans[i] = file.second_returns[i];
    if (second.num_cells() == 0) continue;
    if (second.rows != file.scans[i].rows || second.cols != file.scans[i].cols) {
      throw std::logic_error("EncodeE57: a scan's second returns differ from it in size");
    }
    // A file without lidarshop's flag measured its second returns.
    if (second.synthesized.empty())
      second.synthesized = cv::Mat(second.rows, second.cols, CV_8U, cv::Scalar(0));
    layers.of_scan[i] = &second;
  }
  return layers;
}

}  // namespace
}  // namespace e57

std::vector<uint8_t> EncodeE57(const std::vector<Scan>& scans, const E57WriteOptions& options) {
  return e57::Encode(scans, nullptr, {}, options);
}

std::vector<uint8_t> EncodeE57(const std::vector<Scan>& scans, const std::vector<E57Image>& images,
                               const E57WriteOptions& options) {
  return e57::Encode(scans, nullptr, images, options);
}

std::vector<uint8_t> EncodeE57WithLayer(const Scan& front, const Scan& behind,
                                        const E57WriteOptions& options) {
  const e57::Layers layers = e57::SynthesizedLayer(behind);
  return e57::Encode({front}, &layers.of_scan, {}, options);
}

void WriteE57WithLayer(const std::string& path, const Scan& front, const Scan& behind,
                       const E57WriteOptions& options) {
  const e57::Layers layers = e57::SynthesizedLayer(behind);
  e57::WriteFile(path, {front}, &layers.of_scan, {}, options);
}

void WriteE57(const std::string& path, const std::vector<Scan>& scans, const E57WriteOptions& options) {
  e57::WriteFile(path, scans, nullptr, {}, options);
}

void WriteE57(const std::string& path, const std::vector<Scan>& scans) { WriteE57(path, scans, {}); }

void WriteE57(const std::string& path, const std::vector<Scan>& scans, const std::vector<E57Image>& images,
              const E57WriteOptions& options) {
  e57::WriteFile(path, scans, nullptr, images, options);
}

std::vector<uint8_t> EncodeE57(const E57File& file, const E57WriteOptions& options) {
  const e57::Layers layers = e57::SecondReturns(file);
  return e57::Encode(file.scans, &layers.of_scan, file.images, options);
}

void WriteE57(const std::string& path, const E57File& file, const E57WriteOptions& options) {
  const e57::Layers layers = e57::SecondReturns(file);
  e57::WriteFile(path, file.scans, &layers.of_scan, file.images, options);
}

}  // namespace lidarshop
