// The scan formats and what each holds: one table that the readers' and writers' dispatch (io/scan_io.h),
// `convert`'s plan of what it drops (io/scan_write_plan.h), the commands' refusals ("PTX cannot hold two
// returns per cell"), the server's /api/formats, `lidarshop formats` and docs/file-formats.md all query. A
// format or a capability added here appears in all of them; scan_io.cc's reader table must have a row for
// every format read here (formats_test checks both ways).
#pragma once

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

// How a file of the format holds several scans.
enum class ScansPerFile {
  kOne,      // one scan (PCD)
  kSeveral,  // a list of scans, each with its own grid and pose (PTX, E57, PLY)
  kMerged,   // one cloud: several scans are written as their union in the world frame (LAS, XYZ, PTS)
};

// How a format holds one of our channels: not at all, under our name, or under its own (`name`).
struct ChannelHeld {
  bool held = false;
  std::string_view name;  // the target's name when it differs from ours ("classification" for labels)
};

struct ScanFormatInfo {
  std::string_view extension;    // lower case, no dot: "ptx"
  std::string_view name;         // "PTX"
  std::string_view description;  // one line for help texts and the docs
  bool read = false;
  bool write = false;
  // For a format read but not written: why, and what to write instead.
  std::string_view write_refusal;
  bool grid = false;  // rows x columns and the scanner pose (an organized scan)
  ScansPerFile scans = ScansPerFile::kOne;
  // The file needs an intensity column: a scan without one is written with the format's no-information value.
  bool intensity_required = false;
  ChannelHeld intensity, color, label, normal, true_range, synthesized;
  // Scan::from_station: the cells filled from another station's measurement (site/from_stations.h).
  ChannelHeld from_station;
  bool images = false;  // photos with their poses (E57 images2D)
  // A second layer of cells behind the first (remove --keep-object): WriteScanWithLayer.
  bool layer_behind = false;
  std::string_view layer_behind_how;  // how the layer is kept, or why it cannot be
  // What the coordinates are stored as.
  std::string_view precision;
};

// Every scan format, in the order file dialogs and help texts list them.
std::span<const ScanFormatInfo> ScanFormats();

// The format of `extension` (lower case, no dot), or nullptr.
const ScanFormatInfo* FindScanFormat(std::string_view extension);

// "E57, PLY, PCD or LAS": the names of the formats for which `holds` is true, joined for a sentence with
// `conjunction` before the last.
template <typename Holds>
std::string FormatNamesWhere(Holds holds, std::string_view conjunction = "or");

// Why `format` cannot hold a layer behind the object, with the formats that can:
// "PTX cannot hold two returns per cell; write E57, PLY, PCD or LAS".
std::string LayerBehindRefusal(const ScanFormatInfo& format);

// The table as Markdown (docs/file-formats.md holds it; formats_test checks that it is current).
std::string ScanFormatsMarkdown();

// One format of the table as `lidarshop formats --json` and the server's /api/formats write it: the fields
// of ScanFormatInfo under the same names, a channel false, true or the format's name for it.
struct ScanFormatSummary {
  std::string extension, name, description;
  bool read = false, write = false;
  bool grid = false;
  std::string scans;          // one, several or merged
  std::string write_refusal;  // left out when the format is written
  bool intensity_required = false;
  nlohmann::ordered_json intensity, color, label, normal, true_range, synthesized, from_station;
  bool images = false, layer_behind = false;
  std::string layer_behind_how;  // left out when ""
  std::string precision;
};
template <>
const StructInfo& InfoOf<ScanFormatSummary>();

// `lidarshop formats --json`.
struct ScanFormatsSummary {
  std::vector<ScanFormatSummary> formats;
};
template <>
const StructInfo& InfoOf<ScanFormatsSummary>();

// The table, one summary per format in ScanFormats' order.
std::vector<ScanFormatSummary> SummarizeScanFormats();

// ---- implementation of the template ----

template <typename Holds>
std::string FormatNamesWhere(Holds holds, std::string_view conjunction) {
  std::string names;
  std::string_view last;
  for (const ScanFormatInfo& format : ScanFormats()) {
    if (!holds(format)) continue;
    if (!last.empty()) names += names.empty() ? std::string(last) : ", " + std::string(last);
    last = format.name;
  }
  if (names.empty()) return std::string(last);
  return names + " " + std::string(conjunction) + " " + std::string(last);
}

}  // namespace lidarshop
