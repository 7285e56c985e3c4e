// E57 reader: pages -> XML (pugixml) -> data3D scans and images2D photos. See io/e57.h and e57_format.h.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <tuple>
#include <unordered_map>

#include <Eigen/Geometry>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <pugixml.hpp>

#include "lidarshop/io/e57.h"
#include "lidarshop/io/e57_format.h"
#include "lidarshop/io/image_io.h"
#include "lidarshop/io/io_common.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/scan/ray_directions.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/input_file.h"
#include "lidarshop/util/memory_budget.h"

namespace lidarshop {
namespace e57 {

// The largest record count / grid a file may claim; lowered by the fuzzer to keep its memory bounded.
int64_t g_max_cells = kMaxScanCells;

namespace {

struct Context {
  const std::string& path;
  const LogicalBytes& logical;
};

// What the reader holds per record while it places a scan's records (coordinates 12, state and layer 2,
// cell 8, one decoded field 8 and the bytestream it came from, up to 8, a claimed cell 1) on top of the scan's
// own channels: 39; the budget check keeps its earlier, larger bound.
constexpr int64_t kReaderBytesPerRecord = 64;

[[noreturn]] void XmlError(const Context& ctx, pugi::xml_node node, const std::string& message) {
  ThrowInputError(ctx.path, "XML section", ElementPath(node), message);
}

int64_t ParseInt(const Context& ctx, pugi::xml_node node, const char* text) {
  std::string_view s(text);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  if (s.empty()) return 0;
  if (s.front() == '+') s.remove_prefix(1);
  int64_t v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size()) {
    XmlError(ctx, node, fmt::format("not an integer: '{}'", std::string(s.substr(0, 40))));
  }
  return v;
}

double ParseDouble(const Context& ctx, pugi::xml_node node, const char* text) {
  std::string_view s(text);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  if (s.empty()) return 0.0;
  if (s.front() == '+') s.remove_prefix(1);
  double v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size()) {
    XmlError(ctx, node, fmt::format("not a number: '{}'", std::string(s.substr(0, 40))));
  }
  return v;
}

std::string TypeOf(pugi::xml_node node) { return node.attribute("type").value(); }

// The numeric value of an Integer, ScaledInteger or Float element; `fallback` when the element is absent.
double NumberValue(const Context& ctx, pugi::xml_node node, double fallback) {
  if (!node) return fallback;
  const std::string type = TypeOf(node);
  if (type == "Integer") return static_cast<double>(ParseInt(ctx, node, node.text().get()));
  if (type == "Float") return ParseDouble(ctx, node, node.text().get());
  if (type == "ScaledInteger") {
    const double scale =
        node.attribute("scale") ? ParseDouble(ctx, node, node.attribute("scale").value()) : 1.0;
    const double offset =
        node.attribute("offset") ? ParseDouble(ctx, node, node.attribute("offset").value()) : 0.0;
    return static_cast<double>(ParseInt(ctx, node, node.text().get())) * scale + offset;
  }
  XmlError(ctx, node, fmt::format("expected a number element, found type '{}'", type));
}

// An integral value in [lo, hi] (indices, image sizes); `fallback` when absent.
int64_t BoundedInteger(const Context& ctx, pugi::xml_node node, int64_t fallback, int64_t lo, int64_t hi) {
  if (!node) return fallback;
  const double v = NumberValue(ctx, node, static_cast<double>(fallback));
  if (!(v >= static_cast<double>(lo) && v <= static_cast<double>(hi))) {
    XmlError(ctx, node, fmt::format("value {} is outside [{}, {}]", v, lo, hi));
  }
  return static_cast<int64_t>(v);
}

std::string StringValue(pugi::xml_node node) { return node ? std::string(node.text().get()) : std::string(); }

Eigen::Matrix4d PoseOf(const Context& ctx, pugi::xml_node pose) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  if (!pose) return m;
  const pugi::xml_node r = pose.child("rotation");
  const pugi::xml_node t = pose.child("translation");
  if (r) {
    Eigen::Quaterniond q(NumberValue(ctx, r.child("w"), 1.0), NumberValue(ctx, r.child("x"), 0.0),
                         NumberValue(ctx, r.child("y"), 0.0), NumberValue(ctx, r.child("z"), 0.0));
    const double norm = q.norm();
    if (!std::isfinite(norm) || norm < 1e-12) XmlError(ctx, r, "rotation quaternion is zero or not finite");
    q.coeffs() /= norm;  // some writers store unnormalized quaternions
    m.topLeftCorner<3, 3>() = q.toRotationMatrix();
  }
  if (t) {
    m(0, 3) = NumberValue(ctx, t.child("x"), 0.0);
    m(1, 3) = NumberValue(ctx, t.child("y"), 0.0);
    m(2, 3) = NumberValue(ctx, t.child("z"), 0.0);
    if (!m.topRightCorner<3, 1>().allFinite()) XmlError(ctx, t, "translation is not finite");
  }
  return m;
}

// Terminal fields of a prototype, depth first (the order of the bytestreams).
void CollectFields(const Context& ctx, pugi::xml_node node, const std::string& prefix,
                   std::vector<Field>* fields, int depth = 0) {
  if (depth > 32) XmlError(ctx, node, "prototype nested more than 32 levels deep");
  for (pugi::xml_node child : node.children()) {
    if (child.type() != pugi::node_element) continue;
    const std::string type = TypeOf(child);
    const std::string name = prefix.empty() ? child.name() : prefix + "/" + child.name();
    if (type == "Structure" || type == "Vector") {
      CollectFields(ctx, child, name, fields, depth + 1);
      continue;
    }
    Field f;
    f.name = name;
    if (type == "Integer" || type == "ScaledInteger") {
      f.type = type == "Integer" ? Field::Type::kInteger : Field::Type::kScaledInteger;
      f.minimum = child.attribute("minimum") ? ParseInt(ctx, child, child.attribute("minimum").value())
                                             : std::numeric_limits<int64_t>::min();
      f.maximum = child.attribute("maximum") ? ParseInt(ctx, child, child.attribute("maximum").value())
                                             : std::numeric_limits<int64_t>::max();
      if (f.maximum < f.minimum) {
        XmlError(ctx, child, fmt::format("maximum {} < minimum {}", f.maximum, f.minimum));
      }
      if (f.type == Field::Type::kScaledInteger) {
        f.scale = child.attribute("scale") ? ParseDouble(ctx, child, child.attribute("scale").value()) : 1.0;
        f.offset =
            child.attribute("offset") ? ParseDouble(ctx, child, child.attribute("offset").value()) : 0.0;
        if (!std::isfinite(f.scale) || !std::isfinite(f.offset) || f.scale == 0.0) {
          XmlError(ctx, child, "scale must be finite and non-zero, offset finite");
        }
      }
      f.bits = BitsForRange(f.minimum, f.maximum);
    } else if (type == "Float") {
      const std::string precision = child.attribute("precision").value();
      f.type = precision == "single" ? Field::Type::kFloat : Field::Type::kDouble;
      f.bits = precision == "single" ? 32 : 64;
    } else {
      XmlError(ctx, child,
               fmt::format("prototype field type '{}' is not supported (expected Integer, "
                           "ScaledInteger or Float)",
                           type));
    }
    fields->push_back(f);
    if (fields->size() > static_cast<size_t>(kMaxPrototypeFields)) {
      XmlError(ctx, node, fmt::format("more than {} prototype fields", kMaxPrototypeFields));
    }
  }
}

// Logical offset of a physical offset found in the XML; rejects offsets outside the file or inside a
// checksum.
uint64_t LogicalOffset(const Context& ctx, pugi::xml_node node, uint64_t physical) {
  if (physical % kPageSize >= kPagePayload) {
    XmlError(ctx, node, fmt::format("fileOffset {} points into a page checksum", physical));
  }
  const uint64_t logical = LogicalFromPhysical(physical);
  if (logical >= ctx.logical.size()) {
    XmlError(ctx, node, fmt::format("fileOffset {} is beyond the end of the file", physical));
  }
  return logical;
}

uint64_t OffsetAttribute(const Context& ctx, pugi::xml_node node, const char* name) {
  if (!node.attribute(name)) XmlError(ctx, node, fmt::format("attribute '{}' is missing", name));
  const int64_t v = ParseInt(ctx, node, node.attribute(name).value());
  if (v < 0) XmlError(ctx, node, fmt::format("attribute '{}' is negative: {}", name, v));
  return static_cast<uint64_t>(v);
}

// Where each bytestream of a compressed vector section lies: per stream, its chunks over the data packets as
// (logical offset, length). Fields are decoded a block of records at a time straight from these chunks, so
// the reader never holds a field's whole stream nor its decoded values (on a station, 20 bytes and more a
// record beside the scan).
struct Bytestreams {
  std::vector<std::vector<std::pair<uint64_t, uint32_t>>> chunks;  // one list per stream
  std::vector<std::vector<uint64_t>> starts;                       // each chunk's offset in its stream
  std::vector<uint64_t> sizes;                                     // bytes per stream, summed over its chunks

  // Bytes [begin, end) of stream `i` (end <= sizes[i]) into `out`.
  void Gather(const LogicalBytes& logical, size_t i, uint64_t begin, uint64_t end,
              std::vector<uint8_t>* out) const {
    out->resize(end - begin);
    const std::vector<uint64_t>& at = starts[i];
    size_t k = std::upper_bound(at.begin(), at.end(), begin) - at.begin();
    k = k == 0 ? 0 : k - 1;
    for (; k < chunks[i].size() && at[k] < end; ++k) {
      const auto [offset, length] = chunks[i][k];
      const uint64_t from = std::max(begin, at[k]) - at[k];
      const uint64_t to = std::min<uint64_t>(end - at[k], length);
      if (to > from) logical.Read(offset + from, to - from, out->data() + (at[k] + from - begin));
    }
  }
};

// Locates the bytestreams of a compressed vector section over its data packets, checking every packet. Stops
// once every stream holds `needed_bytes[i]`.
Bytestreams LocateBytestreams(const Context& ctx, pugi::xml_node cv_node,
                              const std::vector<uint64_t>& needed_bytes) {
  const size_t n = needed_bytes.size();
  Bytestreams located;
  located.chunks.resize(n);
  located.starts.resize(n);
  located.sizes.assign(n, 0);
  std::vector<uint64_t>& sizes = located.sizes;
  const LogicalBytes& L = ctx.logical;
  const uint64_t phys = OffsetAttribute(ctx, cv_node, "fileOffset");
  const uint64_t start = LogicalOffset(ctx, cv_node, phys);
  auto where = [&](uint64_t logical) {
    return fmt::format("compressed vector '{}' at byte offset {}", ElementPath(cv_node),
                       PhysicalFromLogical(logical));
  };
  if (start + 32 > L.size()) ThrowInputError(ctx.path, where(start), "section header", "truncated");
  if (const uint8_t section_id = L.Load<uint8_t>(start); section_id != 1) {
    ThrowInputError(ctx.path, where(start), "sectionId",
                    fmt::format("{} is not a compressed vector section (expected 1)", int{section_id}));
  }
  const uint64_t section_length = L.Load<uint64_t>(start + 8);
  const uint64_t data_physical = L.Load<uint64_t>(start + 16);
  if (section_length < 32 || section_length > L.size() - start) {
    ThrowInputError(ctx.path, where(start), "sectionLogicalLength",
                    fmt::format("{} does not fit in the file", section_length));
  }
  const uint64_t end = start + section_length;
  auto done = [&] {
    for (size_t i = 0; i < n; ++i) {
      if (sizes[i] < needed_bytes[i]) return false;
    }
    return true;
  };
  // Data packets past the records recordCount counts mean the count disagrees with the data (a file that
  // would otherwise read as an empty or partial scan).
  auto refuse_more_data = [&](uint64_t at) {
    while (at + 6 <= end) {
      const uint64_t length = uint64_t{L.Load<uint16_t>(at + 2)} + 1;
      if (L.Load<uint8_t>(at) == 1) {
        const size_t count = std::min<size_t>(L.Load<uint16_t>(at + 4), (end - at - 6) / 2);
        for (size_t i = 0; i < count; ++i) {
          if (L.Load<uint16_t>(at + 6 + 2 * i) > 0) {
            ThrowInputError(ctx.path, where(at), "recordCount",
                            "the section holds more data than recordCount records (wrong count?)");
          }
        }
      } else if (const uint8_t type = L.Load<uint8_t>(at); type != 0 && type != 2) {
        return;
      }
      at += length;
    }
  };
  if (done()) {
    if (data_physical % kPageSize < kPagePayload) {
      const uint64_t first = LogicalFromPhysical(data_physical);
      if (first >= start + 32 && first <= end) refuse_more_data(first);
    }
    return located;
  }
  if (data_physical % kPageSize >= kPagePayload) {
    ThrowInputError(ctx.path, where(start), "dataPhysicalOffset", "points into a page checksum");
  }
  uint64_t pos = LogicalFromPhysical(data_physical);
  if (pos < start + 32 || pos > end) {
    ThrowInputError(ctx.path, where(start), "dataPhysicalOffset",
                    fmt::format("{} is outside its section", data_physical));
  }
  std::vector<size_t> lengths(n);
  int64_t packets = 0;
  while (!done()) {
    ++packets;
    if (pos + 4 > end) {
      ThrowInputError(ctx.path, where(pos), "packet",
                      "the section ends before every bytestream holds its records (truncated data)");
    }
    const uint8_t type = L.Load<uint8_t>(pos);
    const uint64_t length = uint64_t{L.Load<uint16_t>(pos + 2)} + 1;
    if (length > end - pos) {
      ThrowInputError(ctx.path, where(pos), "packetLogicalLengthMinus1",
                      fmt::format("packet of {} bytes runs past the end of its section", length));
    }
    if (type == 1) {
      if (length < 6) ThrowInputError(ctx.path, where(pos), "data packet", "shorter than its header");
      const size_t count = L.Load<uint16_t>(pos + 4);
      if (count != n) {
        ThrowInputError(ctx.path, where(pos), "bytestreamCount",
                        fmt::format("{} bytestreams, the prototype has {} fields", count, n));
      }
      uint64_t at = pos + 6 + 2 * uint64_t{count};
      if (at > pos + length)
        ThrowInputError(ctx.path, where(pos), "data packet", "header longer than the packet");
      const std::vector<uint8_t> header = L.Bytes(pos + 6, 2 * n);  // one read for the packet's lengths
      for (size_t i = 0; i < n; ++i) lengths[i] = LoadLe<uint16_t>(header.data() + 2 * i);
      for (size_t i = 0; i < n; ++i) {
        if (lengths[i] > pos + length - at) {
          ThrowInputError(ctx.path, where(pos), fmt::format("bytestream {}", i),
                          "buffer lengths exceed the packet length");
        }
        if (lengths[i] > 0) {
          located.chunks[i].emplace_back(at, static_cast<uint32_t>(lengths[i]));
          located.starts[i].push_back(sizes[i]);
        }
        sizes[i] += lengths[i];
        at += lengths[i];
      }
    } else if (type != 0 && type != 2) {
      ThrowInputError(ctx.path, where(pos), "packetType",
                      fmt::format("unknown packet type {} (expected 0 index, 1 data or 2 empty)", int{type}));
    }
    pos += length;
  }
  refuse_more_data(pos);
  // A writer may round each packet's bytestreams up to whole bytes; more than that is records recordCount
  // does not count.
  for (size_t i = 0; i < n; ++i) {
    if (sizes[i] > needed_bytes[i] + static_cast<uint64_t>(packets) + 8) {
      ThrowInputError(ctx.path, where(start), "recordCount",
                      fmt::format("bytestream {} holds {} bytes, recordCount needs {} (wrong count?)", i,
                                  sizes[i], needed_bytes[i]));
    }
  }
  return located;
}

struct Limits {
  double minimum = 0, maximum = 0;
  bool known = false;
};

Limits LimitsFrom(const Context& ctx, pugi::xml_node limits, const char* min_name, const char* max_name,
                  const Field* field) {
  Limits l;
  if (limits && (limits.child(min_name) || limits.child(max_name))) {
    l.minimum = NumberValue(ctx, limits.child(min_name), 0.0);
    l.maximum = NumberValue(ctx, limits.child(max_name), 0.0);
    l.known = true;
  } else if (field && field->type == Field::Type::kInteger) {
    l = {static_cast<double>(field->minimum), static_cast<double>(field->maximum), true};
  } else if (field && field->type == Field::Type::kScaledInteger) {
    l = {field->minimum * field->scale + field->offset, field->maximum * field->scale + field->offset, true};
    if (l.maximum < l.minimum) std::swap(l.minimum, l.maximum);
  }
  return l;
}

struct GridOrientation {
  bool flip_rows = false, flip_cols = false;
};

// Votes over neighbouring valid cells: does elevation fall with the row index (image order) and does our
// azimuth (from +y, positive to the right) rise with the column index? A flip needs a 75 % majority, so that
// grids without angular structure (synthetic data, a few points) keep the file's order.
GridOrientation OrientationOf(const Scan& scan) {
  // Without trigonometry: elevation rises with z / range; our azimuth rises from a to b when the xy cross
  // product a x b is negative (clockwise seen from above).
  int64_t rows_up = 0, rows_down = 0, cols_up = 0, cols_down = 0;
  for (int r = 0; r < scan.rows; ++r) {
    const uint8_t* v = scan.valid.ptr<uint8_t>(r);
    const uint8_t* v_next = r + 1 < scan.rows ? scan.valid.ptr<uint8_t>(r + 1) : nullptr;
    const cv::Vec3f* p = scan.point.ptr<cv::Vec3f>(r);
    const cv::Vec3f* p_next = r + 1 < scan.rows ? scan.point.ptr<cv::Vec3f>(r + 1) : nullptr;
    const float* range = scan.range.ptr<float>(r);
    const float* range_next = r + 1 < scan.rows ? scan.range.ptr<float>(r + 1) : nullptr;
    for (int c = 0; c < scan.cols; ++c) {
      if (!v[c]) continue;
      if (v_next && v_next[c]) {
        const float d = p_next[c][2] / range_next[c] - p[c][2] / range[c];
        rows_up += d > 0, rows_down += d < 0;
      }
      if (c + 1 < scan.cols && v[c + 1]) {
        const float cross = p[c][0] * p[c + 1][1] - p[c][1] * p[c + 1][0];
        cols_up += cross<0, cols_down += cross> 0;
      }
    }
  }
  GridOrientation o;
  o.flip_rows = rows_up > 3 * rows_down && rows_up >= 8;
  o.flip_cols = cols_down > 3 * cols_up && cols_down >= 8;
  return o;
}

// The points CompressedVector of one data3D entry: its prototype's fields and their bytestreams, read after
// checking that recordCount fits the file.
struct PointRecords {
  PointRecords(const Context& context, pugi::xml_node points_node) : ctx(context), points(points_node) {}
  const Context& ctx;
  pugi::xml_node points;
  int64_t count = 0;  // recordCount
  std::vector<Field> fields;
  std::unordered_map<std::string, int> field_index;
  Bytestreams streams;  // one per field
  std::string where;    // "file: data3D/.../points", for decoding errors
  bool cartesian = false, spherical = false, structured = false;

  const Field* Find(const char* name) const {
    const auto it = field_index.find(name);
    return it == field_index.end() ? nullptr : &fields[it->second];
  }
  // Calls visit(first, n, values) for the records of `field` (not null) a block at a time, in order: values
  // holds records [first, first + n), valid during the call. Throws InputError (naming `where`) first when the
  // field's stream holds fewer than `count` values.
  template <typename Visit>
  void ForEachBlock(const Field* field, Visit&& visit) const {
    LIDARSHOP_CHECK(field != nullptr);
    CheckHolds(field);
    std::vector<uint8_t> bytes;
    std::vector<double> values;
    for (int64_t first = 0; first < count; first += kRecordsPerBlock) {
      const int64_t n = std::min(kRecordsPerBlock, count - first);
      DecodeBlock(field, first, n, &bytes, &values);
      visit(first, n, values.data());
    }
  }
  // The whole stream of `field` is checked before its first block, with the message decoding it whole gave.
  void CheckHolds(const Field* field) const {
    CheckStreamHolds(*field, streams.sizes[field - fields.data()], count, where);
  }
  // Records [first, first + n) of `field` into `values` (`bytes`: scratch); `first` is a multiple of
  // kRecordsPerBlock, a multiple of 8, so every block starts on a whole byte.
  void DecodeBlock(const Field* field, int64_t first, int64_t n, std::vector<uint8_t>* bytes,
                   std::vector<double>* values) const {
    const size_t index = field - fields.data();
    const uint64_t bits = static_cast<uint64_t>(field->bits);
    const uint64_t begin = static_cast<uint64_t>(first) * bits / 8;
    const uint64_t end = std::min(streams.sizes[index], (static_cast<uint64_t>(first + n) * bits + 7) / 8);
    streams.Gather(ctx.logical, index, begin, end, bytes);
    values->resize(n);
    DecodeField(*field, bytes->data(), bytes->size(), n, values->data(), where);
  }
  static constexpr int64_t kRecordsPerBlock = int64_t{1} << 16;
};

PointRecords ReadPointRecords(const Context& ctx, pugi::xml_node child) {
  PointRecords records{ctx, child.child("points")};
  const pugi::xml_node points = records.points;
  if (!points) XmlError(ctx, child, "data3D entry has no 'points'");
  if (TypeOf(points) != "CompressedVector") XmlError(ctx, points, "'points' is not a CompressedVector");
  if (!points.attribute("recordCount")) XmlError(ctx, points, "attribute 'recordCount' is missing");
  const int64_t record_count = ParseInt(ctx, points, points.attribute("recordCount").value());
  if (record_count < 0 || record_count > g_max_cells) {
    XmlError(ctx, points, fmt::format("recordCount {} is outside [0, {}]", record_count, g_max_cells));
  }
  records.count = record_count;
  CollectFields(ctx, points.child("prototype"), "", &records.fields);
  const std::vector<Field>& fields = records.fields;
  for (size_t i = 0; i < fields.size(); ++i) records.field_index.emplace(fields[i].name, static_cast<int>(i));
  records.cartesian = records.Find("cartesianX") && records.Find("cartesianY") && records.Find("cartesianZ");
  records.spherical = records.Find("sphericalRange") && records.Find("sphericalAzimuth") &&
                      records.Find("sphericalElevation");
  records.structured = records.Find("rowIndex") && records.Find("columnIndex");
  if (!records.cartesian && !records.spherical && record_count > 0) {
    XmlError(ctx, points, "prototype has neither cartesianX/Y/Z nor sphericalRange/Azimuth/Elevation");
  }

  // Refuse before allocating: every field's bytestream must be able to hold recordCount values, and the
  // section cannot hold more bytes than the file.
  std::vector<uint64_t> needed(fields.size());
  uint64_t needed_total = 0;
  for (size_t i = 0; i < fields.size(); ++i) {
    needed[i] = (static_cast<uint64_t>(record_count) * static_cast<uint64_t>(fields[i].bits) + 7) / 8;
    needed_total += needed[i];
  }
  if (needed_total > ctx.logical.size()) {
    XmlError(ctx, points,
             fmt::format("recordCount {} needs {} bytes of bytestreams, the file has {}", record_count,
                         needed_total, ctx.logical.size()));
  }
  if (record_count > 0 || points.attribute("fileOffset")) {
    records.streams = LocateBytestreams(ctx, points, needed);
  } else {
    records.streams.chunks.resize(fields.size());
    records.streams.starts.resize(fields.size());
    records.streams.sizes.assign(fields.size(), 0);
  }
  records.where = fmt::format("{}: {}", ctx.path, ElementPath(points));
  return records;
}

// The grid of a data3D entry: rows x cols and each record's cell (row * cols + col). Structured scans take
// it from rowIndex / columnIndex (and indexBounds); unstructured ones are one row of records.
struct RecordGrid {
  int64_t rows = 0, cols = 0;
  // Per record; set to -1 below for records that give the scan nothing. 32 bits: a scan has at most
  // kMaxScanCells cells.
  std::vector<int32_t> cell;
};
static_assert(kMaxScanCells <= std::numeric_limits<int32_t>::max());

RecordGrid ReadRecordGrid(const Context& ctx, pugi::xml_node child, const PointRecords& records) {
  const int64_t record_count = records.count;
  const pugi::xml_node points = records.points;
  RecordGrid grid;
  grid.cell.resize(record_count);
  if (!records.structured) {
    grid.rows = record_count > 0 ? 1 : 0;
    grid.cols = record_count;
    for (int64_t i = 0; i < record_count; ++i) grid.cell[i] = static_cast<int32_t>(i);
    return grid;
  }
  // grid.cell holds each record's row until the columns are known; the column indices are decoded twice
  // rather than held.
  int64_t max_row = -1, max_col = -1;
  records.ForEachBlock(records.Find("rowIndex"), [&](int64_t first, int64_t n, const double* r) {
    for (int64_t j = 0; j < n; ++j) {
      if (!(r[j] >= 0 && r[j] < 2147483647.0)) {
        XmlError(ctx, points, fmt::format("record {}: rowIndex {} is out of range", first + j, r[j]));
      }
      grid.cell[first + j] = static_cast<int32_t>(r[j]);
      max_row = std::max<int64_t>(max_row, grid.cell[first + j]);
    }
  });
  const Field* column_field = records.Find("columnIndex");
  records.ForEachBlock(column_field, [&](int64_t first, int64_t n, const double* c) {
    for (int64_t j = 0; j < n; ++j) {
      if (!(c[j] >= 0 && c[j] < 2147483647.0)) {
        XmlError(ctx, points, fmt::format("record {}: columnIndex {} is out of range", first + j, c[j]));
      }
      max_col = std::max(max_col, static_cast<int64_t>(c[j]));
    }
  });
  const pugi::xml_node bounds = child.child("indexBounds");
  if (bounds) {
    max_row = std::max(max_row, BoundedInteger(ctx, bounds.child("rowMaximum"), -1, -1, 2147483646));
    max_col = std::max(max_col, BoundedInteger(ctx, bounds.child("columnMaximum"), -1, -1, 2147483646));
  }
  const int64_t rows = max_row + 1, cols = max_col + 1;
  if (rows > 2147483647 || cols > 2147483647 || (rows > 0 && cols > g_max_cells / rows)) {
    XmlError(ctx, points,
             fmt::format("grid of {} x {} cells exceeds the limit of {} cells", rows, cols, g_max_cells));
  }
  io_internal::CheckGridFromData(rows, cols, static_cast<int64_t>(ctx.logical.size()), ctx.path,
                                 "data3D points");
  records.ForEachBlock(column_field, [&](int64_t first, int64_t n, const double* c) {
    for (int64_t j = 0; j < n; ++j) {
      grid.cell[first + j] = static_cast<int32_t>(grid.cell[first + j] * cols + static_cast<int64_t>(c[j]));
    }
  });
  grid.rows = rows;
  grid.cols = cols;
  return grid;
}

// The layer of each record of a structured scan from its returnIndex: 0 (first return) goes to the scan, 1
// to the layer behind, 2 (third and later returns) is left out. Empty (all 0) without returnIndex.
std::vector<uint8_t> ReadReturnLayers(const PointRecords& records) {
  std::vector<uint8_t> layer;
  if (records.structured && records.Find("returnIndex") != nullptr) {
    layer.resize(records.count);
    records.ForEachBlock(records.Find("returnIndex"), [&](int64_t first, int64_t n, const double* v) {
      for (int64_t j = 0; j < n; ++j) layer[first + j] = v[j] <= 0.0 ? 0 : v[j] == 1.0 ? 1 : 2;
    });
  }
  return layer;
}

// One block of records' coordinates as floats, x y z per record; spherical ones converted to cartesian. A
// spherical record at range 0 or of state 1 gives its unit direction; a "valid" one at range 0 gets state 2.
// `state` holds the block's invalid states (0 = valid point, 1 = direction only, 2 = nothing meaningful).
class CoordinateBlocks {
 public:
  explicit CoordinateBlocks(const PointRecords& records) : records_(records) {
    const char* names[3] = {"cartesianX", "cartesianY", "cartesianZ"};
    if (!records.cartesian)
      names[0] = "sphericalRange", names[1] = "sphericalAzimuth", names[2] = "sphericalElevation";
    for (int k = 0; k < 3; ++k) fields_[k] = records.Find(names[k]);
    state_field_ =
        records.cartesian ? records.Find("cartesianInvalidState") : records.Find("sphericalInvalidState");
  }

  // Calls visit(first, n, xyz, state) for every block of records, in order.
  template <typename Visit>
  void ForEachBlock(Visit&& visit) {
    const int64_t count = records_.count;
    if (count == 0) return;  // else cartesian || spherical (checked by ReadPointRecords)
    // The whole streams are checked first, in the order decoding them whole did.
    if (state_field_) records_.CheckHolds(state_field_);
    for (const Field* field : fields_) records_.CheckHolds(field);
    for (int64_t first = 0; first < count; first += PointRecords::kRecordsPerBlock) {
      const int64_t n = std::min(PointRecords::kRecordsPerBlock, count - first);
      state_.assign(n, 0);
      if (state_field_) {
        records_.DecodeBlock(state_field_, first, n, &bytes_, &values_[0]);
        for (int64_t j = 0; j < n; ++j) state_[j] = values_[0][j] == 0.0 ? 0 : values_[0][j] == 1.0 ? 1 : 2;
      }
      for (int k = 0; k < 3; ++k) records_.DecodeBlock(fields_[k], first, n, &bytes_, &values_[k]);
      xyz_.resize(3 * n);
      for (int64_t j = 0; j < n; ++j) {
        if (records_.cartesian) {
          for (int k = 0; k < 3; ++k) xyz_[3 * j + k] = static_cast<float>(values_[k][j]);
          continue;
        }
        double x, y, z;
        // E57 spherical: azimuth counter-clockwise from +x in the xy plane, elevation up from the xy plane.
        const double r = values_[0][j], az = values_[1][j], el = values_[2][j];
        if (state_[j] == 1 || r == 0.0) {
          x = std::cos(el) * std::cos(az), y = std::cos(el) * std::sin(az), z = std::sin(el);
          if (state_[j] == 0) state_[j] = 2;  // a valid point at range 0 is no return
        } else {
          x = r * std::cos(el) * std::cos(az), y = r * std::cos(el) * std::sin(az), z = r * std::sin(el);
        }
        xyz_[3 * j] = static_cast<float>(x), xyz_[3 * j + 1] = static_cast<float>(y),
                 xyz_[3 * j + 2] = static_cast<float>(z);
      }
      visit(first, n, xyz_.data(), state_.data());
    }
  }

 private:
  const PointRecords& records_;
  const Field* fields_[3] = {nullptr, nullptr, nullptr};
  const Field* state_field_ = nullptr;
  std::vector<double> values_[3];
  std::vector<uint8_t> bytes_;
  std::vector<uint8_t> state_;
  std::vector<float> xyz_;
};

// A ray the file stored for a cell without a return (16 bytes), kept aside until the scan's grid is known.
struct StoredRay {
  int32_t cell;  // < kMaxScanCells
  cv::Vec3f direction;
};

// What PlaceRecords left out, for the warnings, and the rays of structured scans' no-return cells (a
// structured scan holds no direction image while it is read: its rays are its grid's, ray_directions.h).
struct PlacedRecords {
  int64_t duplicates = 0;              // records repeating a return of a cell that already has one
  int64_t later_returns = 0;           // records with returnIndex >= 2
  std::vector<StoredRay> stored_rays;  // in record order; a later one of a cell wins
};

// The first record before record `before` whose grid indices name `cell`, for the message on a corrupt grid.
int64_t FirstRecordOfCell(const PointRecords& records, int64_t cols, int64_t cell, int64_t before) {
  std::vector<int64_t> rows_seen;
  int64_t found = -1;
  records.ForEachBlock(records.Find("rowIndex"), [&](int64_t first, int64_t n, const double* r) {
    if (first >= before) return;
    for (int64_t j = 0; j < n; ++j) rows_seen.push_back(static_cast<int64_t>(r[j]));
  });
  records.ForEachBlock(records.Find("columnIndex"), [&](int64_t first, int64_t n, const double* c) {
    for (int64_t j = 0; j < n && found < 0 && first + j < before; ++j) {
      if (rows_seen[first + j] * cols + static_cast<int64_t>(c[j]) == cell) found = first + j;
    }
  });
  return found;
}

// Puts the records' points into `scan` (first returns) and `second` (returnIndex 1; a rows x cols scan when
// any record has it, else untouched). Records that give no cell a point get grid->cell[i] = -1, so that
// their intensity and colour are skipped. Throws InputError when two records claim one cell of a scan
// without returnIndex (the grid indices are corrupt).
PlacedRecords PlaceRecords(const Context& ctx, const PointRecords& records, const std::vector<uint8_t>& layer,
                           RecordGrid* grid, Scan* scan, Scan* second) {
  const int64_t rows = grid->rows, cols = grid->cols;
  std::vector<int32_t>& cell = grid->cell;
  PlacedRecords placed;
  if (std::find(layer.begin(), layer.end(), 1) != layer.end()) {
    const bool has_color =
        records.Find("colorRed") && records.Find("colorGreen") && records.Find("colorBlue");
    *second = MakeScan(static_cast<int>(rows), static_cast<int>(cols), has_color,
                       /*with_intensity=*/records.Find("intensity") != nullptr);
    second->name = scan->name;
    second->world_from_scanner = scan->world_from_scanner;
  }
  // Several records of one grid cell are several returns of one ray, which E57 marks with returnIndex.
  // Without it, two records claiming the same rowIndex/columnIndex contradict the grid: the file is corrupt
  // (e.g. zeroed compressed-vector data), and guessing which record to keep would be a silent wrong answer.
  // A byte per cell marks the cells a record claimed.
  const bool has_return_index = records.Find("returnIndex") != nullptr;
  std::vector<uint8_t> claimed;
  if (records.structured && !has_return_index) claimed.assign(static_cast<size_t>(rows * cols), 0);
  CoordinateBlocks coordinates(records);
  coordinates.ForEachBlock([&](int64_t first, int64_t n, const float* xyz, const uint8_t* state) {
    for (int64_t j = 0; j < n; ++j) {
      const int64_t i = first + j;
      const int64_t c = cell[i];
      if (!claimed.empty()) {
        if (claimed[c] != 0) {
          XmlError(ctx, records.points,
                   fmt::format("records {} and {} both claim row {}, column {} and the prototype has no "
                               "returnIndex: the grid indices are corrupt",
                               FirstRecordOfCell(records, cols, c, i), i, c / std::max<int64_t>(cols, 1),
                               c % std::max<int64_t>(cols, 1)));
        }
        claimed[c] = 1;
      }
      const int r = static_cast<int>(c / std::max<int64_t>(cols, 1));
      const int k = static_cast<int>(c % std::max<int64_t>(cols, 1));
      const cv::Vec3f p(xyz[3 * j], xyz[3 * j + 1], xyz[3 * j + 2]);
      const float range = static_cast<float>(cv::norm(p));
      const bool finite = std::isfinite(range);
      const uint8_t record_layer = layer.empty() ? 0 : layer[i];
      if (record_layer > 1) {
        ++placed.later_returns;
        cell[i] = -1;
        continue;
      }
      if (record_layer == 1) {
        // A second return: a point of the layer behind; its ray is the cell's (set from the grid later).
        Scan& behind = *second;
        if (state[j] == 0 && finite && range > 0.0f && behind.valid.at<uint8_t>(r, k) != kValid) {
          behind.valid.at<uint8_t>(r, k) = kValid;
          behind.point.at<cv::Vec3f>(r, k) = p;
          behind.range.at<float>(r, k) = range;
        } else {
          placed.duplicates += behind.valid.at<uint8_t>(r, k) == kValid;
          cell[i] = -1;
        }
        continue;
      }
      if (scan->valid.at<uint8_t>(r, k) == kValid) {  // a later return of the same cell: keep the first
        ++placed.duplicates;
        cell[i] = -1;
        continue;
      }
      if (state[j] == 0 && finite && range > 0.0f) {
        scan->valid.at<uint8_t>(r, k) = kValid;
        scan->point.at<cv::Vec3f>(r, k) = p;
        scan->range.at<float>(r, k) = range;
        if (!scan->direction.empty()) scan->direction.at<cv::Vec3f>(r, k) = p / range;
      } else {
        if (state[j] != 2 && finite && range > 0.0f) {
          // Keep a stored unit direction bit for bit (renormalizing would change its last bits).
          const cv::Vec3f ray = std::abs(range - 1.0f) < 1e-6f ? p : p / range;
          if (scan->direction.empty()) {
            placed.stored_rays.push_back({static_cast<int32_t>(c), ray});
          } else {
            scan->direction.at<cv::Vec3f>(r, k) = ray;
          }
        }
        cell[i] = -1;  // no return: intensity and colour stay at their no-return values
      }
    }
  });
  return placed;
}

// lidarshop's extension `<prefix>:noReturnDirections` of a data3D entry (`field_name`, "" when the file
// does not declare the namespace): the rays of the cells without a return, as rowIndex / columnIndex and a
// unit vector in cartesianX/Y/Z, kept bit for bit in `stored_rays`. Files written before it carried
// these rays as records of state 1 instead (PlaceRecords reads those).
void ReadNoReturnDirections(const Context& ctx, pugi::xml_node child, const std::string& field_name,
                            const RecordGrid& grid, const Scan& scan, std::vector<StoredRay>* stored_rays) {
  const pugi::xml_node extension = field_name.empty() ? pugi::xml_node() : child.child(field_name.c_str());
  if (!extension) return;
  const PointRecords records = ReadPointRecords(ctx, extension);
  if (records.count == 0) return;
  if (!records.structured || !records.cartesian) {
    XmlError(ctx, records.points, "needs rowIndex, columnIndex and cartesianX/Y/Z");
  }
  std::vector<int64_t> cells(records.count);
  for (const char* name : {"rowIndex", "columnIndex"}) {
    const int64_t bound = name[0] == 'r' ? grid.rows : grid.cols;
    records.ForEachBlock(records.Find(name), [&](int64_t first, int64_t n, const double* v) {
      for (int64_t j = 0; j < n; ++j) {
        const int64_t i = first + j;
        if (!(v[j] >= 0 && v[j] < static_cast<double>(bound))) {
          XmlError(ctx, records.points,
                   fmt::format("record {}: {} {} is outside the scan's {} x {} grid", i, name, v[j],
                               grid.rows, grid.cols));
        }
        cells[i] =
            name[0] == 'r' ? static_cast<int64_t>(v[j]) * grid.cols : cells[i] + static_cast<int64_t>(v[j]);
      }
    });
  }
  std::vector<cv::Vec3f> rays(static_cast<size_t>(records.count));
  const uint8_t* valid = scan.valid.ptr<uint8_t>();
  for (int axis = 0; axis < 3; ++axis) {
    const Field* field = records.Find(axis == 0 ? "cartesianX" : axis == 1 ? "cartesianY" : "cartesianZ");
    records.ForEachBlock(field, [&](int64_t first, int64_t n, const double* v) {
      for (int64_t j = 0; j < n; ++j) rays[first + j][axis] = static_cast<float>(v[j]);
    });
  }
  stored_rays->reserve(stored_rays->size() + rays.size());
  for (int64_t i = 0; i < records.count; ++i) {
    cv::Vec3f& d = rays[i];
    const float norm = static_cast<float>(cv::norm(d));
    if (valid[cells[i]] || !(std::isfinite(norm) && norm > 0.0f)) {
      XmlError(
          ctx, records.points,
          fmt::format("record {} (row {}, column {}): {}", i, cells[i] / grid.cols, cells[i] % grid.cols,
                      valid[cells[i]] ? "the cell has a return" : "the direction is zero or not finite"));
    }
    if (!(std::abs(norm - 1.0f) < 1e-6f)) d /= norm;  // a stored unit vector is kept bit for bit
    stored_rays->push_back({static_cast<int32_t>(cells[i]), d});
  }
}

// lidarshop's extension `<prefix>:angularGrid` of a data3D entry (`field_name`, "" when the file does not
// declare the namespace): the grid the writer's scan had, in the file's column and row order; nullopt when
// absent. Throws InputError when its sizes differ from the scan's or an angle is not finite.
std::optional<ScanGrid> ReadAngularGrid(const Context& ctx, pugi::xml_node child,
                                        const std::string& field_name, const RecordGrid& grid) {
  const pugi::xml_node extension = field_name.empty() ? pugi::xml_node() : child.child(field_name.c_str());
  if (!extension) return std::nullopt;
  ScanGrid result;
  for (const auto& [name, count, angles] :
       {std::tuple<const char*, int64_t, std::vector<double>*>{"azimuth", grid.cols, &result.azimuth_rad},
        {"elevation", grid.rows, &result.elevation_rad}}) {
    const pugi::xml_node vector = extension.child(name);
    if (!vector) XmlError(ctx, extension, fmt::format("has no '{}'", name));
    for (pugi::xml_node value = vector.first_child(); value; value = value.next_sibling()) {
      if (static_cast<int64_t>(angles->size()) == count) {
        XmlError(ctx, vector,
                 fmt::format("holds more than the scan's {} {}", count, name[0] == 'a' ? "columns" : "rows"));
      }
      const double angle = NumberValue(ctx, value, 0.0);
      if (!std::isfinite(angle)) XmlError(ctx, value, "the angle is not finite");
      angles->push_back(angle);
    }
    if (static_cast<int64_t>(angles->size()) != count) {
      XmlError(ctx, vector,
               fmt::format("holds {} angles for the scan's {} {}", angles->size(), count,
                           name[0] == 'a' ? "columns" : "rows"));
    }
  }
  result.fitted = BoundedInteger(ctx, extension.child("fitted"), 0, 0, 1) == 1;
  return result;
}

// The scan of record i's layer (layer empty: every record is a first return).
inline Scan* LayerOf(Scan* const layers[2], const std::vector<uint8_t>& layer, int64_t i) {
  return layers[layer.empty() ? 0 : layer[i]];
}

// Intensities of the placed records (grid.cell[i] >= 0), scaled to [0, 1] by intensityLimits (or by the
// returned values when the file gives none).
void ReadIntensity(const Context& ctx, pugi::xml_node child, const PointRecords& records,
                   const RecordGrid& grid, const std::vector<uint8_t>& layer, Scan* const layers[2]) {
  const Field* intensity_field = records.Find("intensity");
  if (!intensity_field) return;
  const std::vector<int32_t>& cell = grid.cell;
  Limits l = LimitsFrom(ctx, child.child("intensityLimits"), "intensityMinimum", "intensityMaximum",
                        intensity_field);
  if (l.known && l.maximum > l.minimum) {
    // Pictures show intensity in the file's units (render/render.h): 0 and 1 stand for the limits.
    for (Scan* scan : {layers[0], layers[1]}) {
      if (scan == nullptr) continue;
      scan->source_metadata["intensity.file_minimum"] = fmt::format("{}", l.minimum);
      scan->source_metadata["intensity.file_maximum"] = fmt::format("{}", l.maximum);
    }
  }
  if (!l.known) {
    // Float intensities without limits: take them as [0, 1] when they are, else stretch the returned range.
    double lo = 0, hi = 1;
    records.ForEachBlock(intensity_field, [&](int64_t first, int64_t n, const double* v) {
      for (int64_t j = 0; j < n; ++j) {
        if (cell[first + j] < 0 || !std::isfinite(v[j])) continue;
        lo = std::min(lo, v[j]);
        hi = std::max(hi, v[j]);
      }
    });
    l = {lo, hi, true};
  }
  const double span = l.maximum - l.minimum;
  records.ForEachBlock(intensity_field, [&](int64_t first, int64_t n, const double* v) {
    for (int64_t j = 0; j < n; ++j) {
      const int64_t i = first + j;
      if (cell[i] < 0) continue;
      const double t = span > 0 ? (v[j] - l.minimum) / span : 0.5;
      LayerOf(layers, layer, i)->intensity.ptr<float>()[cell[i]] =
          std::isfinite(t) ? static_cast<float>(std::clamp(t, 0.0, 1.0)) : 0.5f;
    }
  });
}

// Colours of the placed records, scaled to 0..255 by colorLimits (0..255 when absent). Needs all three of
// colorRed/Green/Blue.
void ReadColor(const Context& ctx, pugi::xml_node child, const PointRecords& records, const RecordGrid& grid,
               const std::vector<uint8_t>& layer, Scan* const layers[2]) {
  const Field* channel_fields[3] = {records.Find("colorRed"), records.Find("colorGreen"),
                                    records.Find("colorBlue")};
  if (!(channel_fields[0] && channel_fields[1] && channel_fields[2])) return;
  const pugi::xml_node limits = child.child("colorLimits");
  const char* min_names[3] = {"colorRedMinimum", "colorGreenMinimum", "colorBlueMinimum"};
  const char* max_names[3] = {"colorRedMaximum", "colorGreenMaximum", "colorBlueMaximum"};
  for (int ch = 0; ch < 3; ++ch) {
    Limits l = LimitsFrom(ctx, limits, min_names[ch], max_names[ch], channel_fields[ch]);
    if (!l.known) l = {0.0, 255.0, true};
    const double span = l.maximum - l.minimum;
    records.ForEachBlock(channel_fields[ch], [&](int64_t first, int64_t n, const double* v) {
      for (int64_t j = 0; j < n; ++j) {
        const int64_t i = first + j;
        if (grid.cell[i] < 0) continue;
        const double t = span > 0 ? (v[j] - l.minimum) / span : 0.0;
        LayerOf(layers, layer, i)->color.ptr<uint8_t>()[3 * int64_t{grid.cell[i]} + ch] =
            std::isfinite(t) ? static_cast<uint8_t>(std::lround(std::clamp(t, 0.0, 1.0) * 255.0)) : 0;
      }
    });
  }
}

// An 8-bit flag channel of both layers (`channel` picks it), 0 everywhere, then `value(v)` of each placed
// record's value of `field` where it is not 0: lidarshop's synthesized and fromStation extension fields.
template <typename Value>
void ReadFlagField(const PointRecords& records, const Field* field, const RecordGrid& grid,
                   const std::vector<uint8_t>& layer, Scan* const layers[2], cv::Mat Scan::*channel,
                   Value&& value) {
  for (int l = 0; l < 2; ++l) {
    Scan* s = layers[l];
    if (s != nullptr && s->num_cells() > 0) s->*channel = cv::Mat(s->rows, s->cols, CV_8U, cv::Scalar(0));
  }
  records.ForEachBlock(field, [&](int64_t first, int64_t n, const double* v) {
    for (int64_t j = 0; j < n; ++j) {
      const int64_t i = first + j;
      const uint8_t flag = grid.cell[i] >= 0 ? value(v[j]) : 0;
      if (flag != 0) (LayerOf(layers, layer, i)->*channel).ptr<uint8_t>()[grid.cell[i]] = flag;
    }
  });
}

// lidarshop's extension field (`synthesized_field`, "" when the file does not declare the namespace) into
// the layers' synthesized channels.
void ReadSynthesized(const PointRecords& records, const std::string& synthesized_field,
                     const RecordGrid& grid, const std::vector<uint8_t>& layer, Scan* const layers[2]) {
  const Field* flag = synthesized_field.empty() ? nullptr : records.Find(synthesized_field.c_str());
  if (!flag) return;
  ReadFlagField(records, flag, grid, layer, layers, &Scan::synthesized,
                [](double v) { return v != 0.0 ? kValid : uint8_t{0}; });
}

// lidarshop's `fromStation` extension field ("" when the file does not declare the namespace) into the layers'
// from_station channels (site/from_stations.h).
void ReadFromStation(const PointRecords& records, const std::string& field_name, const RecordGrid& grid,
                     const std::vector<uint8_t>& layer, Scan* const layers[2]) {
  const Field* field = field_name.empty() ? nullptr : records.Find(field_name.c_str());
  if (!field) return;
  ReadFlagField(records, field, grid, layer, layers, &Scan::from_station, [](double v) {
    return std::isfinite(v) && v > 0.0 ? static_cast<uint8_t>(std::min(v, 255.0)) : uint8_t{0};
  });
}

// E57 does not say which way rowIndex / columnIndex run (pumpA's rowIndex 0 is its bottom row); turns the
// grid of a structured scan (and its second layer) into image orientation (row 0 = highest elevation, our
// azimuth increasing to the right) by the data. The grid is the one lidarshop stored (`file_grid`) or else
// fitted to the points. The scan holds no direction image when every stored ray is its grid ray bit for bit
// (ray_directions.h); else the image is the grid's with the stored rays in place. Returns a warning when the
// stored grid disagrees with the points and was fitted again instead.
std::string OrientStructuredScan(std::vector<StoredRay> stored_rays, std::optional<ScanGrid> file_grid,
                                 Scan* scan, Scan* second) {
  Scan* layers[2] = {scan, second};
  const GridOrientation o = OrientationOf(*scan);
  if (o.flip_rows || o.flip_cols) {
    const int code = o.flip_rows && o.flip_cols ? -1 : o.flip_rows ? 0 : 1;
    for (Scan* s : layers) {
      if (s == nullptr || s->num_cells() == 0) continue;
      for (cv::Mat* m :
           {&s->valid, &s->range, &s->point, &s->intensity, &s->color, &s->synthesized, &s->from_station}) {
        if (!m->empty()) cv::flip(*m, *m, code);
      }
    }
    for (StoredRay& ray : stored_rays) {
      int row = ray.cell / scan->cols, col = ray.cell % scan->cols;
      if (o.flip_rows) row = scan->rows - 1 - row;
      if (o.flip_cols) col = scan->cols - 1 - col;
      ray.cell = row * scan->cols + col;
    }
    if (file_grid) {
      if (o.flip_rows) std::reverse(file_grid->elevation_rad.begin(), file_grid->elevation_rad.end());
      if (o.flip_cols) std::reverse(file_grid->azimuth_rad.begin(), file_grid->azimuth_rad.end());
    }
  }
  std::string warning;
  if (file_grid) {
    // A grid the points do not sit around is not this scan's (the points were changed by a tool that kept the
    // extension): fitted again. The test is the points' mean offset from their rays (under half the grid's step:
    // noise averages out, a grid off by a step does not) and their RMS angle (under ten steps: a dense
    // station's noise across the ray can exceed its step, 1.8 steps in the 100 M-ray parking lot).
    const GridResidual residual = MeasureGridResidual(*scan, *file_grid);
    file_grid->rms_residual_rad = residual.rms_rad;
    file_grid->max_residual_rad = residual.max_rad;
    const auto step_of = [](const std::vector<double>& angles) {
      return angles.size() > 1
                 ? std::abs(angles.back() - angles.front()) / static_cast<double>(angles.size() - 1)
                 : 0.0;
    };
    const double azimuth_step = step_of(file_grid->azimuth_rad),
                 elevation_step = step_of(file_grid->elevation_rad);
    const double step = std::max({azimuth_step, elevation_step, 1e-9});
    if (residual.rms_rad > 10.0 * step ||
        std::abs(residual.mean_east_rad) > 0.5 * std::max(azimuth_step, 1e-9) ||
        std::abs(residual.mean_north_rad) > 0.5 * std::max(elevation_step, 1e-9)) {
      warning = fmt::format(
          "the stored angular grid is not where the points are (mean offset {:.3g} rad across, {:.3g} rad "
          "up, RMS "
          "{:.3g} rad, step {:.3g} rad); fitted again",
          residual.mean_east_rad, residual.mean_north_rad, residual.rms_rad, step);
    } else {
      scan->grid = std::move(*file_grid);
    }
  }
  if (!HasCompleteGrid(*scan) && scan->CountValid() > 0) FitGrid(scan);
  // Rays of cells that returned after all are not stored rays (a later record of the cell).
  const uint8_t* valid = scan->valid.ptr<uint8_t>();
  std::erase_if(stored_rays, [valid](const StoredRay& ray) { return valid[ray.cell] != 0; });
  bool rays_are_grid = HasCompleteGrid(*scan);
  if (rays_are_grid && !stored_rays.empty()) {
    const RayDirections grid_rays(*scan);
    for (const StoredRay& ray : stored_rays) {
      const cv::Vec3f g = grid_rays.At(ray.cell);
      if (std::memcmp(&g, &ray.direction, sizeof(g)) != 0) {
        rays_are_grid = false;
        break;
      }
    }
  }
  if (!rays_are_grid) {
    // The grid's rays (none without a grid: zero) with the stored ones in place.
    scan->direction = HasCompleteGrid(*scan) ? DirectionsFromGrid(scan->grid)
                                             : cv::Mat(scan->rows, scan->cols, CV_32FC3, cv::Scalar::all(0));
    cv::Vec3f* to = scan->direction.ptr<cv::Vec3f>();
    for (const StoredRay& ray : stored_rays) to[ray.cell] = ray.direction;
  }
  if (second->num_cells() > 0) {
    second->direction = scan->direction;  // the same rays (shared: nothing writes them)
    second->grid = scan->grid;
  }
  return warning;
}

// The first returns of one data3D entry; records with returnIndex 1 go to `second` (left 0 x 0 when there are
// none), later ones are counted in `warnings`. `extension_prefix` is the prefix the file binds to lidarshop's
// namespace ("" when the file does not declare it): its fields are `<prefix>:synthesized` and
// `<prefix>:noReturnDirections`.
Scan ReadScan(const Context& ctx, pugi::xml_node child, int index, const std::string& extension_prefix,
              Scan* second, std::vector<std::string>* warnings) {
  const std::string synthesized_field =
      extension_prefix.empty() ? "" : extension_prefix + ":" + kSynthesizedLocalName;
  const PointRecords records = ReadPointRecords(ctx, child);
  RecordGrid grid = ReadRecordGrid(ctx, child, records);
  const bool has_color = records.Find("colorRed") && records.Find("colorGreen") && records.Find("colorBlue");
  // A structured scan's rays are its grid's (ray_directions.h): no direction image while it is read.
  Scan scan =
      records.structured
          ? MakeScanWithoutDirections(static_cast<int>(grid.rows), static_cast<int>(grid.cols), has_color,
                                      /*with_intensity=*/records.Find("intensity") != nullptr)
          : MakeScan(static_cast<int>(grid.rows), static_cast<int>(grid.cols), has_color,
                     /*with_intensity=*/records.Find("intensity") != nullptr);
  scan.name = StringValue(child.child("name"));
  scan.world_from_scanner = PoseOf(ctx, child.child("pose"));
  // The entry's identity and provenance, which a save as E57 writes back (e57_writer.cc): guid, sensor,
  // acquisition times (GPS seconds, shortest round-trip text).
  for (const auto& [element, key] : kE57MetadataStrings) {
    const std::string value = StringValue(child.child(element));
    if (!value.empty()) scan.source_metadata[key] = value;
  }
  for (const auto& [element, key] : kE57MetadataTimes) {
    const pugi::xml_node value = child.child(element).child("dateTimeValue");
    if (value) scan.source_metadata[key] = fmt::format("{}", NumberValue(ctx, value, 0.0));
  }
  PlacedRecords placed;
  {
    // The per-record arrays (each record's cell and layer) end here, before the grid is fitted.
    const std::vector<uint8_t> layer = ReadReturnLayers(records);
    placed = PlaceRecords(ctx, records, layer, &grid, &scan, second);
    ReadNoReturnDirections(
        ctx, child, extension_prefix.empty() ? "" : extension_prefix + ":" + kNoReturnDirectionsLocalName,
        grid, scan, &placed.stored_rays);
    if (placed.duplicates > 0) {
      warnings->push_back(fmt::format(
          "{}: scan {} ('{}'): {} records repeat a return of a cell that already has one; the first is kept",
          ctx.path, index, scan.name, placed.duplicates));
    }
    if (placed.later_returns > 0) {
      warnings->push_back(
          fmt::format("{}: scan {} ('{}'): {} records with returnIndex >= 2 (third and later "
                      "returns) are not kept",
                      ctx.path, index, scan.name, placed.later_returns));
    }
    Scan* const layers[2] = {&scan, second};
    ReadIntensity(ctx, child, records, grid, layer, layers);
    ReadColor(ctx, child, records, grid, layer, layers);
    ReadSynthesized(records, synthesized_field, grid, layer, layers);
    ReadFromStation(records, extension_prefix.empty() ? "" : extension_prefix + ":" + kFromStationLocalName,
                    grid, layer, layers);
    std::vector<int32_t>().swap(grid.cell);
  }
  if (records.structured && scan.num_cells() > 0) {
    std::optional<ScanGrid> file_grid = ReadAngularGrid(
        ctx, child, extension_prefix.empty() ? "" : extension_prefix + ":" + kAngularGridLocalName, grid);
    const std::string warning =
        OrientStructuredScan(std::move(placed.stored_rays), std::move(file_grid), &scan, second);
    if (!warning.empty())
      warnings->push_back(fmt::format("{}: scan {} ('{}'): {}", ctx.path, index, scan.name, warning));
  }
  return scan;
}

// A Blob element: its bytes and where they start in the logical file (the key of ImageCache).
struct Blob {
  std::vector<uint8_t> bytes;
  uint64_t start = 0;
};

Blob BlobBytes(const Context& ctx, pugi::xml_node blob) {
  const uint64_t phys = OffsetAttribute(ctx, blob, "fileOffset");
  const uint64_t length = OffsetAttribute(ctx, blob, "length");
  const uint64_t start = LogicalOffset(ctx, blob, phys);
  const LogicalBytes& L = ctx.logical;
  if (start + 16 > L.size()) XmlError(ctx, blob, "blob section header is truncated");
  if (const uint8_t section_id = L.Load<uint8_t>(start); section_id != 0)
    XmlError(ctx, blob, fmt::format("sectionId {} is not a blob section (expected 0)", int{section_id}));
  const uint64_t section_length = L.Load<uint64_t>(start + 8);
  if (section_length < 16 || section_length > L.size() - start || length > section_length - 16) {
    XmlError(ctx, blob,
             fmt::format("blob of {} bytes does not fit its section of {} bytes in the file", length,
                         section_length));
  }
  return {L.Bytes(start + 16, length), start + 16};
}

// The photos read so far: a blob listed by several images2D entries is decoded once (the entries share the
// decoded pixels), and the stored bytes every entry keeps plus the distinct decoded images stay within the
// memory budget.
struct ImageCache {
  struct Decoded {
    cv::Mat image;
    std::string error;
  };
  std::map<std::pair<uint64_t, size_t>, Decoded> decoded;  // by the blob's place in the file and size
  int64_t bytes = 0;
};

void ReadImage(const Context& ctx, pugi::xml_node child, const std::vector<std::string>& scan_guids,
               ImageCache* cache, std::vector<E57Image>* images) {
  static const std::pair<const char*, const char*> kRepresentations[] = {
      {"pinholeRepresentation", "pinhole"},
      {"sphericalRepresentation", "spherical"},
      {"cylindricalRepresentation", "cylindrical"},
      {"visualReferenceRepresentation", "visual"}};
  for (const auto& [element, projection] : kRepresentations) {
    const pugi::xml_node rep = child.child(element);
    if (!rep) continue;
    pugi::xml_node blob = rep.child("jpegImage");
    if (!blob) blob = rep.child("pngImage");
    if (!blob) XmlError(ctx, rep, "has neither jpegImage nor pngImage");
    E57Image image;
    image.name = StringValue(child.child("name"));
    image.projection = projection;
    image.world_from_camera = PoseOf(ctx, child.child("pose"));
    image.guid = StringValue(child.child("guid"));
    image.description = StringValue(child.child("description"));
    if (const pugi::xml_node associated = child.child("associatedData3DGuid")) {
      const auto found = std::find(scan_guids.begin(), scan_guids.end(), StringValue(associated));
      if (found != scan_guids.end()) image.associated_scan = static_cast<int>(found - scan_guids.begin());
    }
    // pixelWidth / pixelHeight are metres or radians by representation (E2807): pixel_width_m and
    // pixel_height_m keep them as stored whatever the representation (as they always did), the typed fields
    // say which is which.
    image.focal_length_m = NumberValue(ctx, rep.child("focalLength"), 0.0);
    image.pixel_width_m = NumberValue(ctx, rep.child("pixelWidth"), 0.0);
    image.pixel_height_m = NumberValue(ctx, rep.child("pixelHeight"), 0.0);
    image.principal_x_px = NumberValue(ctx, rep.child("principalPointX"), 0.0);
    image.principal_y_px = NumberValue(ctx, rep.child("principalPointY"), 0.0);
    if (image.projection == "spherical") {
      image.pixel_width_rad = image.pixel_width_m;
      image.pixel_height_rad = image.pixel_height_m;
    } else if (image.projection == "cylindrical") {
      image.pixel_width_rad = image.pixel_width_m;
      image.radius_m = NumberValue(ctx, rep.child("radius"), 0.0);
    }
    if (const pugi::xml_node mask = rep.child("imageMask")) {
      // Checked against the file first; its bytes (at most the file's) are counted before they are kept.
      image.mask_encoded = BlobBytes(ctx, mask).bytes;
      cache->bytes += static_cast<int64_t>(image.mask_encoded.size());
      CheckMemoryBudget(cache->bytes, fmt::format("{}: {}: the images2D blobs", ctx.path, ElementPath(mask)));
    }
    image.width_px = static_cast<int>(BoundedInteger(ctx, rep.child("imageWidth"), 0, 0, 1 << 30));
    image.height_px = static_cast<int>(BoundedInteger(ctx, rep.child("imageHeight"), 0, 0, 1 << 30));
    Blob encoded = BlobBytes(ctx, blob);
    image.encoded = std::move(encoded.bytes);
    cache->bytes += static_cast<int64_t>(image.encoded.size());  // at most the file's size per entry
    CheckMemoryBudget(cache->bytes, fmt::format("{}: {}: the images2D blobs", ctx.path, ElementPath(blob)));
    image.encoding = std::string(blob.name()) == "jpegImage" ? "jpeg" : "png";
    const uint8_t* bytes = image.encoded.data();
    const size_t size = image.encoded.size();
    const auto key = std::make_pair(encoded.start, size);
    const auto found = cache->decoded.find(key);
    if (found != cache->decoded.end()) {
      image.image = found->second.image;
      image.decode_error = found->second.error;
    } else {
      // A blob that does not decode (or is too large to) does not make the scans unreadable: keep the entry
      // and say why it is empty. Its size is read from its header (PNG IHDR, JPEG SOF) before decoding.
      try {
        const std::string where = fmt::format("{}-byte {}", size, blob.name());
        ImageHeader header = ReadImageHeader(bytes, size, where);
        header.channels = std::max(header.channels, 3);  // decoded as RGB
        CheckImageHeader(header, where);
        cache->bytes += std::min(header.DecodedBytes(), int64_t{1} << 60);
        CheckMemoryBudget(cache->bytes, fmt::format("{}: the images2D photos", ctx.path));
        image.image = DecodeImage(bytes, size, where, /*color=*/true);
      } catch (const InputError& error) {
        image.decode_error =
            FormatInputError(ctx.path, ElementPath(blob), "",
                             fmt::format("the blob does not decode or is refused: {}", error.what()));
      }
      cache->decoded.emplace(key, ImageCache::Decoded{image.image, image.decode_error});
    }
    images->push_back(std::move(image));
    return;
  }
}

}  // namespace

E57File ReadLogical(const std::string& path, const LogicalBytes& logical) {
  const Header header = ParseHeader(path, logical.Bytes(0, std::min<uint64_t>(logical.size(), kHeaderSize)));
  const Context ctx{path, logical};
  const uint64_t physical_size = logical.size() / kPagePayload * kPageSize;
  if (header.file_physical_length != physical_size) {
    ThrowInputError(path, "byte offset 16", "filePhysicalLength",
                    fmt::format("header says {} bytes, the file has {} (truncated or padded)",
                                header.file_physical_length, physical_size));
  }
  if (header.xml_physical_offset % kPageSize >= kPagePayload) {
    ThrowInputError(path, "byte offset 24", "xmlPhysicalOffset", "points into a page checksum");
  }
  const uint64_t xml_start = LogicalFromPhysical(header.xml_physical_offset);
  if (xml_start > logical.size() || header.xml_logical_length > logical.size() - xml_start) {
    ThrowInputError(path, "byte offset 24", "xmlPhysicalOffset",
                    fmt::format("XML section ({} bytes at {}) runs past the end of the file",
                                header.xml_logical_length, header.xml_physical_offset));
  }
  const std::vector<uint8_t> xml = logical.Bytes(xml_start, header.xml_logical_length);
  CheckXmlUtf8(path, reinterpret_cast<const char*>(xml.data()), xml.size());
  pugi::xml_document doc;
  const pugi::xml_parse_result parsed =
      doc.load_buffer(xml.data(), xml.size(), pugi::parse_default, pugi::encoding_utf8);
  if (!parsed) {
    ThrowInputError(path, fmt::format("XML section, byte {} of {}", parsed.offset, header.xml_logical_length),
                    "", fmt::format("malformed XML: {}", parsed.description()));
  }
  const pugi::xml_node root = doc.child("e57Root");
  if (!root) ThrowInputError(path, "XML section", "e57Root", "missing: not an E57 file");

  // lidarshop's extension fields, under whatever prefix the file binds to its namespace.
  std::string extension_prefix;
  for (const pugi::xml_attribute attribute : root.attributes()) {
    const std::string_view name = attribute.name();
    if (name.rfind("xmlns:", 0) == 0 && std::string_view(attribute.value()) == kLidarshopE57Namespace) {
      extension_prefix = std::string(name.substr(6));
    }
  }
  // A field whose minimum equals its maximum takes no bits, so the bytestreams do not bound recordCount: the
  // records of all scans (kept at once) are bounded together by the file's bytes, as the structured grids
  // are, and by the budget, before any is read.
  int64_t all_records = 0;
  for (pugi::xml_node child : root.child("data3D").children()) {
    const pugi::xml_attribute count = child.child("points").attribute("recordCount");
    if (child.type() != pugi::node_element || !count) continue;
    all_records +=
        std::clamp<int64_t>(ParseInt(ctx, child.child("points"), count.value()), 0, kMaxScanCells + 1);
  }
  io_internal::CheckCellsFromData(all_records, io_internal::kScanBytesPerCell + kReaderBytesPerRecord,
                                  static_cast<int64_t>(logical.size()), path, "XML section: data3D",
                                  "recordCount (records of all scans)");
  E57File file;
  int index = 0;
  for (pugi::xml_node child : root.child("data3D").children()) {
    if (child.type() != pugi::node_element) continue;
    Scan second;
    file.scans.push_back(ReadScan(ctx, child, index++, extension_prefix, &second, &file.warnings));
    file.second_returns.push_back(std::move(second));
  }
  std::vector<std::string> scan_guids;
  for (pugi::xml_node child : root.child("data3D").children()) {
    if (child.type() == pugi::node_element) scan_guids.push_back(StringValue(child.child("guid")));
  }
  ImageCache image_cache;
  for (pugi::xml_node child : root.child("images2D").children()) {
    if (child.type() != pugi::node_element) continue;
    ReadImage(ctx, child, scan_guids, &image_cache, &file.images);
  }
  return file;
}

}  // namespace e57

E57File ReadE57Bytes(const std::vector<uint8_t>& file_bytes, const std::string& name) {
  return e57::ReadLogical(name, e57::LogicalBytes(e57::LogicalFromPages(name, file_bytes)));
}

E57File ReadE57(const std::string& path) {
  CheckRegularFile(path);
  E57File file = e57::ReadLogical(path, e57::LogicalBytes::OpenFile(path));
  // The same number checks as ReadScanFile: `info` and `images` read E57 files here directly.
  for (size_t i = 0; i < file.scans.size(); ++i) {
    io_internal::CheckScanNumbers(file.scans[i], path, fmt::format("scan {}", i));
  }
  return file;
}

}  // namespace lidarshop
