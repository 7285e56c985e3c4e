// What a LAS file's coordinate reference system records say, for `info`: the OGC WKT (LASF_Projection
// 2112, or liblas's copy of it) and the GeoTIFF keys (LASF_Projection 34735 with its ASCII params 34737),
// read from the GeoTIFF 1.0 key directory layout: a header of four uint16 (version, revision, minor
// revision, number of keys), then per key (key ID, TIFF tag location, count, value or offset).
#include <cstring>

#include <fmt/format.h>

#include "lidarshop/io/las.h"
#include "lidarshop/io/text_cursor.h"

namespace lidarshop {
namespace {

constexpr int kGeographicTypeGeoKey = 2048;
constexpr int kProjectedCsTypeGeoKey = 3072;
constexpr int kVerticalCsTypeGeoKey = 4096;
constexpr int kGtCitationGeoKey = 1026;
constexpr int kProjLinearUnitsGeoKey = 3076;
constexpr int kGeoAsciiParamsTag = 34737;

// JSON needs UTF-8; the records are ASCII by the specification, so anything else becomes '?'.
std::string AsciiText(const std::string& text) {
  const std::string_view terminated(text.c_str());  // NUL-terminated in the file
  return io_internal::Printable(terminated, terminated.size());
}

const SourceRecord* Find(const std::vector<SourceRecord>& records, const char* user, int id) {
  for (const SourceRecord& record : records) {
    if (record.format == "las" && record.user_id == user && record.record_id == id) return &record;
  }
  return nullptr;
}

}  // namespace

nlohmann::ordered_json LasCrsJson(const std::vector<SourceRecord>& records) {
  nlohmann::ordered_json crs = nlohmann::ordered_json::object();
  const SourceRecord* wkt = Find(records, "LASF_Projection", 2112);
  if (wkt == nullptr) wkt = Find(records, "liblas", 2112);
  if (wkt != nullptr) {
    crs["wkt"] = AsciiText(wkt->payload);
  }
  const SourceRecord* keys = Find(records, "LASF_Projection", 34735);
  const SourceRecord* ascii = Find(records, "LASF_Projection", kGeoAsciiParamsTag);
  if (keys != nullptr && keys->payload.size() >= 8) {
    auto u16 = [&](size_t index) {
      uint16_t value;
      std::memcpy(&value, keys->payload.data() + 2 * index, 2);
      return value;
    };
    const size_t available = keys->payload.size() / 2;
    const size_t count = std::min<size_t>(u16(3), (available - 4) / 4);
    nlohmann::ordered_json geotiff = nlohmann::ordered_json::object();
    for (size_t k = 0; k < count; ++k) {
      const uint16_t id = u16(4 + 4 * k), location = u16(5 + 4 * k), length = u16(6 + 4 * k),
                     value = u16(7 + 4 * k);
      if (location == 0) {
        if (id == kProjectedCsTypeGeoKey) geotiff["projected_epsg"] = value;
        if (id == kGeographicTypeGeoKey) geotiff["geographic_epsg"] = value;
        if (id == kVerticalCsTypeGeoKey) geotiff["vertical_epsg"] = value;
        if (id == kProjLinearUnitsGeoKey) geotiff["linear_units_code"] = value;
      } else if (location == kGeoAsciiParamsTag && id == kGtCitationGeoKey && ascii != nullptr &&
                 static_cast<size_t>(value) + length <= ascii->payload.size()) {
        std::string text = AsciiText(ascii->payload.substr(value, length));
        while (!text.empty() && text.back() == '|') text.pop_back();
        geotiff["citation"] = text;
      }
    }
    geotiff["keys"] = count;
    crs["geotiff"] = geotiff;
  }
  return crs;
}

}  // namespace lidarshop
