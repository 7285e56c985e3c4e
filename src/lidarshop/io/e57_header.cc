// The E57 header reader (io/scan_header.h): the 48-byte file header and the XML section, read page by page
// with their CRCs checked; no binary section is touched, so an 8-million-ray file answers in milliseconds.
// The numbers are read as e57_reader.cc reads them (same element names, same pose convention, same limits).
#include <charconv>
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <Eigen/Geometry>
#include <pugixml.hpp>

#include "lidarshop/io/e57.h"
#include "lidarshop/io/e57_format.h"
#include "lidarshop/io/io_common.h"
#include "lidarshop/io/scan_header.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/input_file.h"

namespace lidarshop {
namespace {

using namespace e57;  // NOLINT: the format's constants and helpers

struct Xml {
  const std::string& path;

  [[noreturn]] void Fail(pugi::xml_node node, const std::string& message) const {
    ThrowInputError(path, "XML section", ElementPath(node), message);
  }

  template <typename T>
  T Parse(pugi::xml_node node, const char* text, const char* what) const {
    std::string_view s(text);
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
    if (s.empty()) return T{0};
    if (s.front() == '+') s.remove_prefix(1);
    T v{};
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (ec != std::errc() || end != s.data() + s.size()) {
      Fail(node, fmt::format("not {}: '{}'", what, std::string(s.substr(0, 40))));
    }
    return v;
  }

  // An Integer, ScaledInteger or Float element's value; `fallback` when absent.
  double Number(pugi::xml_node node, double fallback) const {
    if (!node) return fallback;
    const std::string type = node.attribute("type").value();
    if (type == "Integer") return static_cast<double>(Parse<int64_t>(node, node.text().get(), "an integer"));
    if (type == "Float") return Parse<double>(node, node.text().get(), "a number");
    if (type == "ScaledInteger") {
      const double scale =
          node.attribute("scale") ? Parse<double>(node, node.attribute("scale").value(), "a number") : 1.0;
      const double offset =
          node.attribute("offset") ? Parse<double>(node, node.attribute("offset").value(), "a number") : 0.0;
      return static_cast<double>(Parse<int64_t>(node, node.text().get(), "an integer")) * scale + offset;
    }
    Fail(node, fmt::format("expected a number element, found type '{}'", type));
  }

  int64_t Bounded(pugi::xml_node node, int64_t fallback, int64_t lo, int64_t hi) const {
    if (!node) return fallback;
    const double v = Number(node, static_cast<double>(fallback));
    if (!(v >= static_cast<double>(lo) && v <= static_cast<double>(hi))) {
      Fail(node, fmt::format("value {} is outside [{}, {}]", v, lo, hi));
    }
    return static_cast<int64_t>(v);
  }

  // As e57_reader.cc's PoseOf: unnormalized quaternions are normalized, a zero one is an error.
  Eigen::Matrix4d Pose(pugi::xml_node pose) const {
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    if (!pose) return m;
    const pugi::xml_node r = pose.child("rotation");
    const pugi::xml_node t = pose.child("translation");
    if (r) {
      Eigen::Quaterniond q(Number(r.child("w"), 1.0), Number(r.child("x"), 0.0), Number(r.child("y"), 0.0),
                           Number(r.child("z"), 0.0));
      const double norm = q.norm();
      if (!std::isfinite(norm) || norm < 1e-12) Fail(r, "rotation quaternion is zero or not finite");
      q.coeffs() /= norm;
      m.topLeftCorner<3, 3>() = q.toRotationMatrix();
    }
    if (t) {
      m(0, 3) = Number(t.child("x"), 0.0);
      m(1, 3) = Number(t.child("y"), 0.0);
      m(2, 3) = Number(t.child("z"), 0.0);
      if (!m.topRightCorner<3, 1>().allFinite()) Fail(t, "translation is not finite");
    }
    return m;
  }

  // A DateTime structure's dateTimeValue (GPS seconds); NaN when absent.
  double GpsSeconds(pugi::xml_node date_time) const {
    if (!date_time || !date_time.child("dateTimeValue")) return std::numeric_limits<double>::quiet_NaN();
    return Number(date_time.child("dateTimeValue"), std::numeric_limits<double>::quiet_NaN());
  }

  E57Metadata Metadata(pugi::xml_node entry, const char* start, const char* end) const {
    auto text = [&](const char* name) { return std::string(entry.child(name).text().get()); };
    E57Metadata m;
    m.guid = text("guid");
    m.description = text("description");
    m.sensor_vendor = text("sensorVendor");
    m.sensor_model = text("sensorModel");
    m.sensor_serial_number = text("sensorSerialNumber");
    m.sensor_hardware_version = text("sensorHardwareVersion");
    m.sensor_software_version = text("sensorSoftwareVersion");
    m.sensor_firmware_version = text("sensorFirmwareVersion");
    m.acquisition_start_gps_s = GpsSeconds(entry.child(start));
    m.acquisition_start_utc = UtcFromGpsSeconds(m.acquisition_start_gps_s);
    if (end != nullptr) {
      m.acquisition_end_gps_s = GpsSeconds(entry.child(end));
      m.acquisition_end_utc = UtcFromGpsSeconds(m.acquisition_end_gps_s);
    }
    return m;
  }
};

// The logical bytes [logical_begin, logical_begin + size) of the file, reading only their pages and checking
// each page's CRC (errors name the page as the full reader does).
std::string ReadLogical(const std::string& path, uint64_t logical_begin, uint64_t size, const char* what) {
  const uint64_t first_page = logical_begin / kPagePayload;
  const uint64_t last_page = size == 0 ? first_page : (logical_begin + size - 1) / kPagePayload;
  const std::string pages =
      io_internal::ReadFileRange(path, static_cast<int64_t>(first_page * kPageSize),
                                 static_cast<int64_t>((last_page - first_page + 1) * kPageSize), what);
  std::string logical;
  logical.reserve((last_page - first_page + 1) * kPagePayload);
  for (uint64_t p = first_page; p <= last_page; ++p) {
    const auto* page = reinterpret_cast<const uint8_t*>(pages.data() + (p - first_page) * kPageSize);
    CheckPageCrc(path, page, p);
    logical.append(reinterpret_cast<const char*>(page), kPagePayload);
  }
  return logical.substr(logical_begin - first_page * kPagePayload, size);
}

// The channels a data3D prototype declares, as ChannelNames names them.
std::vector<std::string> PrototypeChannels(pugi::xml_node prototype, const std::string& synthesized_field) {
  auto has = [&](const char* name) { return static_cast<bool>(prototype.child(name)); };
  std::vector<std::string> channels = {"xyz", "range"};
  if (has("intensity")) channels.push_back("intensity");
  channels.insert(channels.end(), {"valid", "direction"});
  if (has("colorRed") && has("colorGreen") && has("colorBlue")) channels.push_back("rgb");
  if (!synthesized_field.empty() && prototype.child(synthesized_field.c_str()))
    channels.push_back("synthesized");
  if (!synthesized_field.empty()) {
    const std::string from_station_field =
        synthesized_field.substr(0, synthesized_field.find(':') + 1) + kFromStationLocalName;
    if (prototype.child(from_station_field.c_str())) channels.push_back("from_station");
  }
  return channels;
}

}  // namespace

ScanFileHeader io_internal::ReadE57Header(const std::string& path) {
  const int64_t size = CheckRegularFile(path);
  if (size < static_cast<int64_t>(kPageSize) || size % static_cast<int64_t>(kPageSize) != 0) {
    ThrowInputError(
        path, fmt::format("file size {} bytes", size), "",
        fmt::format("not a whole number of {}-byte E57 pages (truncated or not an E57 file)", kPageSize));
  }
  const std::string first = ReadLogical(path, 0, kHeaderSize, "header");
  const Header header = ParseHeader(path, std::vector<uint8_t>(first.begin(), first.end()));
  if (header.file_physical_length != static_cast<uint64_t>(size)) {
    ThrowInputError(path, "byte offset 16", "filePhysicalLength",
                    fmt::format("header says {} bytes, the file has {} (truncated or padded)",
                                header.file_physical_length, size));
  }
  if (header.xml_physical_offset % kPageSize >= kPagePayload) {
    ThrowInputError(path, "byte offset 24", "xmlPhysicalOffset", "points into a page checksum");
  }
  const uint64_t logical_size = static_cast<uint64_t>(size) / kPageSize * kPagePayload;
  const uint64_t xml_start = LogicalFromPhysical(header.xml_physical_offset);
  if (xml_start > logical_size || header.xml_logical_length > logical_size - xml_start) {
    ThrowInputError(path, "byte offset 24", "xmlPhysicalOffset",
                    fmt::format("XML section ({} bytes at {}) runs past the end of the file",
                                header.xml_logical_length, header.xml_physical_offset));
  }
  const std::string xml_text = ReadLogical(path, xml_start, header.xml_logical_length, "XML section");
  CheckXmlUtf8(path, xml_text.data(), xml_text.size());
  pugi::xml_document doc;
  const pugi::xml_parse_result parsed =
      doc.load_buffer(xml_text.data(), xml_text.size(), pugi::parse_default, pugi::encoding_utf8);
  if (!parsed) {
    ThrowInputError(path, fmt::format("XML section, byte {} of {}", parsed.offset, header.xml_logical_length),
                    "", fmt::format("malformed XML: {}", parsed.description()));
  }
  const pugi::xml_node root = doc.child("e57Root");
  if (!root) ThrowInputError(path, "XML section", "e57Root", "missing: not an E57 file");
  const Xml xml{path};

  std::string synthesized_field;
  for (const pugi::xml_attribute attribute : root.attributes()) {
    const std::string_view name = attribute.name();
    if (name.rfind("xmlns:", 0) == 0 && std::string_view(attribute.value()) == kLidarshopE57Namespace) {
      synthesized_field = std::string(name.substr(6)) + ":" + kSynthesizedLocalName;
    }
  }

  ScanFileHeader file;
  file.format_version = fmt::format("E57 {}.{}", header.major_version, header.minor_version);
  file.guid = root.child("guid").text().get();
  file.creation_utc = UtcFromGpsSeconds(xml.GpsSeconds(root.child("creationDateTime")));
  for (pugi::xml_node child : root.child("data3D").children()) {
    if (child.type() != pugi::node_element) continue;
    ScanHeader scan;
    scan.name = child.child("name").text().get();
    scan.e57 = xml.Metadata(child, "acquisitionStart", "acquisitionEnd");
    scan.world_from_scanner = xml.Pose(child.child("pose"));
    const pugi::xml_node points = child.child("points");
    if (!points) xml.Fail(child, "data3D entry has no 'points'");
    if (std::string(points.attribute("type").value()) != "CompressedVector")
      xml.Fail(points, "'points' is not a CompressedVector");
    if (!points.attribute("recordCount")) xml.Fail(points, "attribute 'recordCount' is missing");
    scan.points = xml.Parse<int64_t>(points, points.attribute("recordCount").value(), "an integer");
    if (scan.points < 0 || scan.points > g_max_cells) {
      xml.Fail(points, fmt::format("recordCount {} is outside [0, {}]", scan.points, g_max_cells));
    }
    const pugi::xml_node prototype = points.child("prototype");
    const bool cartesian =
        prototype.child("cartesianX") && prototype.child("cartesianY") && prototype.child("cartesianZ");
    const bool spherical = prototype.child("sphericalRange") && prototype.child("sphericalAzimuth") &&
                           prototype.child("sphericalElevation");
    if (!cartesian && !spherical && scan.points > 0) {
      xml.Fail(points, "prototype has neither cartesianX/Y/Z nor sphericalRange/Azimuth/Elevation");
    }
    scan.coordinates = cartesian ? "cartesian" : spherical ? "spherical" : "";
    scan.channels = PrototypeChannels(prototype, synthesized_field);
    scan.organized = prototype.child("rowIndex") && prototype.child("columnIndex");
    if (!scan.organized) {
      scan.rows = scan.points > 0 ? 1 : 0;
      scan.cols = scan.points;
    } else if (const pugi::xml_node bounds = child.child("indexBounds");
               bounds && bounds.child("rowMaximum") && bounds.child("columnMaximum")) {
      // The full reader takes the larger of indexBounds and the largest index in the data: the same for
      // every writer that fills indexBounds in.
      scan.rows = xml.Bounded(bounds.child("rowMaximum"), -1, -1, 2147483646) + 1;
      scan.cols = xml.Bounded(bounds.child("columnMaximum"), -1, -1, 2147483646) + 1;
    }
    file.scans.push_back(std::move(scan));
  }
  static const std::pair<const char*, const char*> kRepresentations[] = {
      {"pinholeRepresentation", "pinhole"},
      {"sphericalRepresentation", "spherical"},
      {"cylindricalRepresentation", "cylindrical"},
      {"visualReferenceRepresentation", "visual"}};
  for (pugi::xml_node child : root.child("images2D").children()) {
    if (child.type() != pugi::node_element) continue;
    for (const auto& [element, projection] : kRepresentations) {
      const pugi::xml_node rep = child.child(element);
      if (!rep) continue;
      pugi::xml_node blob = rep.child("jpegImage");
      if (!blob) blob = rep.child("pngImage");
      if (!blob) xml.Fail(rep, "has neither jpegImage nor pngImage");
      ScanImageHeader image;
      image.name = child.child("name").text().get();
      image.projection = projection;
      image.encoding = std::string(blob.name()) == "jpegImage" ? "jpeg" : "png";
      image.width_px = static_cast<int>(xml.Bounded(rep.child("imageWidth"), 0, 0, 1 << 30));
      image.height_px = static_cast<int>(xml.Bounded(rep.child("imageHeight"), 0, 0, 1 << 30));
      image.encoded_bytes = xml.Parse<int64_t>(blob, blob.attribute("length").value(), "an integer");
      image.world_from_camera = xml.Pose(child.child("pose"));
      image.e57 = xml.Metadata(child, "acquisitionDateTime", nullptr);
      const std::string scan_guid = child.child("associatedData3DGuid").text().get();
      for (size_t i = 0; i < file.scans.size() && !scan_guid.empty(); ++i) {
        if (file.scans[i].e57.guid == scan_guid) image.scan_index = static_cast<int>(i);
      }
      file.images.push_back(std::move(image));
      break;
    }
  }
  return file;
}

}  // namespace lidarshop
