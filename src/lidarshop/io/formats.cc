#include "lidarshop/io/formats.h"

#include <fmt/format.h>

namespace lidarshop {
namespace {

constexpr ChannelHeld kNo{};
constexpr ChannelHeld kYes{true, ""};
constexpr ChannelHeld As(std::string_view name) { return {true, name}; }

// Keep in step with the writers: scan_write_plan_test and scan_layers_test write every channel to every format
// and read it back.
constexpr ScanFormatInfo kFormats[] = {
    {.extension = "ptx",
     .name = "PTX",
     .description = "Leica ASCII, one or several organized scans",
     .read = true,
     .write = true,
     .grid = true,
     .scans = ScansPerFile::kSeveral,
     .intensity_required = true,
     .intensity = kYes,
     .color = kYes,
     .layer_behind_how = "PTX cannot hold two returns per cell",
     .precision = "decimal text in the scanner frame, read as doubles"},
    {.extension = "e57",
     .name = "E57",
     .description = "ASTM E2807: organized and unstructured scans with their poses, and photos",
     .read = true,
     .write = true,
     .grid = true,
     .scans = ScansPerFile::kSeveral,
     .intensity = kYes,
     .color = kYes,
     .synthesized = As("lidarshop:synthesized"),
     .from_station = As("lidarshop:fromStation"),
     .images = true,
     .layer_behind = true,
     .layer_behind_how = "second returns of the same cells (returnIndex 1, lidarshop:synthesized 1)",
     .precision = "float64, or scaled integers (--e57-precision-m)"},
    {.extension = "ply",
     .name = "PLY",
     .description = "points with any fields; lidarshop keeps the grid in row/col/scan fields",
     .read = true,
     .write = true,
     .grid = true,
     .scans = ScansPerFile::kSeveral,
     .intensity = kYes,
     .color = kYes,
     .label = kYes,
     .normal = kYes,
     .true_range = kYes,
     .synthesized = kYes,
     .from_station = kYes,
     .layer_behind = true,
     .layer_behind_how = "two scans of one grid, the one behind synthesized",
     .precision = "float32 world coordinates, float64 beyond 1 km"},
    {.extension = "pcd",
     .name = "PCD",
     .description = "PCL, one organized or unorganized cloud (ascii, binary, binary_compressed)",
     .read = true,
     .write = true,
     .grid = true,
     .scans = ScansPerFile::kOne,
     .intensity = kYes,
     .color = kYes,
     .label = kYes,
     .normal = kYes,
     .true_range = kYes,
     .synthesized = kYes,
     .from_station = kYes,
     .layer_behind = true,
     .layer_behind_how = "one unorganized cloud of both layers, the one behind synthesized",
     .precision = "float32 world coordinates (F 4), float64 beyond 1 km (F 8)"},
    {.extension = "las",
     .name = "LAS",
     .description = "ASPRS LAS 1.0-1.4, one cloud in the world frame",
     .read = true,
     .write = true,
     .scans = ScansPerFile::kMerged,
     .intensity = kYes,
     .color = kYes,
     .label = As("classification"),
     .synthesized = As("synthetic"),
     .from_station = As("user data"),
     .layer_behind = true,
     .layer_behind_how = "one cloud of both layers, the one behind with the synthetic flag",
     .precision = "scaled 32-bit integers (0.1 mm by default, --las-scale)"},
    {.extension = "laz",
     .name = "LAZ",
     .description = "LAS compressed by LASzip (and COPC), read as LAS",
     .read = true,
     .write_refusal =
         "LAZ is not written: lidarshop reads LAZ but has no LASzip compressor; write .las instead "
         "(the same points uncompressed; laszip -i out.las -o out.laz compresses it)",
     .scans = ScansPerFile::kMerged,
     .intensity = kYes,
     .color = kYes,
     .label = As("classification"),
     .synthesized = As("synthetic"),
     .precision = "scaled 32-bit integers (the file's scale)"},
    {.extension = "xyz",
     .name = "XYZ",
     .description = "ASCII \"x y z [intensity] [r g b]\", one cloud in the world frame",
     .read = true,
     .write = true,
     .scans = ScansPerFile::kMerged,
     .intensity = kYes,
     .color = kYes,
     .layer_behind_how = "XYZ cannot mark the synthesized layer behind the object",
     .precision = "decimal text in the world frame, read as doubles"},
    {.extension = "pts",
     .name = "PTS",
     .description = "Leica PTS: a point count line, then as XYZ",
     .read = true,
     .write = true,
     .scans = ScansPerFile::kMerged,
     .intensity = kYes,
     .color = kYes,
     .layer_behind_how = "PTS cannot mark the synthesized layer behind the object",
     .precision = "decimal text in the world frame, read as doubles"},
};

std::string Cell(const ChannelHeld& channel) {
  if (!channel.held) return "-";
  return channel.name.empty() ? "yes" : fmt::format("as `{}`", channel.name);
}

std::string_view ScansCell(ScansPerFile scans) {
  switch (scans) {
    case ScansPerFile::kOne:
      return "one";
    case ScansPerFile::kSeveral:
      return "several";
    case ScansPerFile::kMerged:
      return "merged";
  }
  return "";
}

}  // namespace

std::span<const ScanFormatInfo> ScanFormats() { return kFormats; }

const ScanFormatInfo* FindScanFormat(std::string_view extension) {
  for (const ScanFormatInfo& format : kFormats) {
    if (format.extension == extension) return &format;
  }
  return nullptr;
}

std::string LayerBehindRefusal(const ScanFormatInfo& format) {
  return fmt::format("{}; write {}", format.layer_behind_how,
                     FormatNamesWhere([](const ScanFormatInfo& f) { return f.write && f.layer_behind; }));
}

std::vector<ScanFormatSummary> SummarizeScanFormats() {
  auto channel = [](const ChannelHeld& held) -> nlohmann::ordered_json {
    if (!held.held) return false;
    if (held.name.empty()) return true;
    return std::string(held.name);
  };
  std::vector<ScanFormatSummary> formats;
  for (const ScanFormatInfo& f : kFormats) {
    formats.push_back({.extension = std::string(f.extension),
                       .name = std::string(f.name),
                       .description = std::string(f.description),
                       .read = f.read,
                       .write = f.write,
                       .grid = f.grid,
                       .scans = std::string(ScansCell(f.scans)),
                       .write_refusal = f.write ? "" : std::string(f.write_refusal),
                       .intensity_required = f.intensity_required,
                       .intensity = channel(f.intensity),
                       .color = channel(f.color),
                       .label = channel(f.label),
                       .normal = channel(f.normal),
                       .true_range = channel(f.true_range),
                       .synthesized = channel(f.synthesized),
                       .from_station = channel(f.from_station),
                       .images = f.images,
                       .layer_behind = f.layer_behind,
                       .layer_behind_how = std::string(f.layer_behind_how),
                       .precision = std::string(f.precision)});
  }
  return formats;
}

std::string ScanFormatsMarkdown() {
  std::string out =
      "| format | read | write | grid and pose | scans | intensity | colour | label | normal | true range | "
      "synthesized | photos | layer behind | coordinates |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const ScanFormatInfo& f : kFormats) {
    out += fmt::format("| `.{}` | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
                       f.extension, f.read ? "yes" : "-", f.write ? "yes" : "refused", f.grid ? "yes" : "-",
                       ScansCell(f.scans),
                       f.intensity_required ? "required (0.5 when missing)" : Cell(f.intensity),
                       Cell(f.color), Cell(f.label), Cell(f.normal), Cell(f.true_range), Cell(f.synthesized),
                       f.images ? "yes" : "-", f.layer_behind ? "yes" : "-", f.precision);
  }
  return out;
}

}  // namespace lidarshop
