#include "lidarshop/io/scan_write_plan.h"

#include <algorithm>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "lidarshop/io/formats.h"
#include "lidarshop/io/io_common.h"
#include "lidarshop/io/pcd.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

const ScanFormatInfo& HoldsFor(const std::string& path) {
  CheckScanFileFormat(path);  // the reader's own message for unknown or refused extensions
  return *FindScanFormat(FileExtension(path));
}

}  // namespace

ScanWritePlan PlanScanWrite(const std::string& path, const std::vector<Scan>& scans, size_t images,
                            size_t scans_with_second_returns, const LasWriteOptions* las) {
  const ScanFormatInfo& holds = HoldsFor(path);
  auto any = [&](auto has) { return std::any_of(scans.begin(), scans.end(), has); };
  ScanWritePlan plan;
  plan.channels.push_back("xyz");

  if (!holds.grid) {
    const auto organized =
        std::find_if(scans.begin(), scans.end(), [](const Scan& scan) { return scan.rows > 1; });
    if (organized != scans.end()) {
      plan.dropped.push_back(fmt::format(
          "{}: the grid ({} rows x {} columns) and the scanner pose are not kept: {} holds an unorganized "
          "cloud of points in the world frame",
          path, organized->rows, organized->cols, holds.name));
    }
  }

  const bool has_intensity = any([](const Scan& s) { return s.has_intensity(); });
  if (has_intensity) {
    plan.channels.push_back("intensity");
  } else if (holds.intensity_required && !scans.empty()) {
    plan.channels.push_back("intensity=0.5");
    plan.dropped.push_back(fmt::format(
        "{}: the input has no intensity, but {} requires an intensity column: written as 0.5, the format's "
        "no-information value",
        path, holds.name));
  }

  // The optional channels: written (under the target's name) or dropped with a sentence.
  struct Optional {
    bool present;
    const char* channel;  // our name
    const char* plural;   // in the sentence
    ChannelHeld target;
  };
  const Optional optional[] = {
      {any([](const Scan& s) { return s.has_color(); }), "rgb", "colours", holds.color},
      {any([](const Scan& s) { return !s.label.empty(); }), "label", "labels", holds.label},
      {any([](const Scan& s) { return !s.normal.empty(); }), "normal", "normals", holds.normal},
      {any([](const Scan& s) { return !s.true_range.empty(); }), "true_range", "true ranges",
       holds.true_range},
      {any([](const Scan& s) { return !s.synthesized.empty(); }), "synthesized", "synthesized flags",
       holds.synthesized},
      {any([](const Scan& s) { return !s.from_station.empty(); }), "from_station", "from-station marks",
       holds.from_station},
  };
  for (const Optional& channel : optional) {
    if (!channel.present) continue;
    if (!channel.target.held && std::string(channel.channel) == "synthesized") {
      int64_t synthesized = 0;
      for (const Scan& scan : scans) {
        if (!scan.synthesized.empty()) synthesized += cv::countNonZero(scan.synthesized & scan.valid);
      }
      if (synthesized > 0) {
        plan.dropped.push_back(
            fmt::format("{}: {} synthesized point{} written without {} flag ({} cannot mark them; convert "
                        "--drop-synthesized leaves them out, --synthesized-mask M.png records them)",
                        path, WithThousandsSeparators(synthesized), synthesized == 1 ? " is" : "s are",
                        synthesized == 1 ? "its" : "their", holds.name));
      }
    } else if (!channel.target.held && std::string(channel.channel) == "from_station") {
      int64_t taken = 0;
      for (const Scan& scan : scans) {
        if (!scan.from_station.empty()) taken += cv::countNonZero(scan.from_station & scan.valid);
      }
      if (taken > 0) {
        plan.dropped.push_back(
            fmt::format("{}: {} point{} filled from other stations {} written without the from_station "
                        "channel ({} cannot "
                        "hold it: write .e57 or .las to keep it; --from-stations-mask M.png records them)",
                        path, WithThousandsSeparators(taken), taken == 1 ? "" : "s",
                        taken == 1 ? "is" : "are", holds.name));
      }
    } else if (!channel.target.held) {
      plan.dropped.push_back(fmt::format("{}: {} are not written ({} has no {} field)", path, channel.plural,
                                         holds.name, channel.channel));
    } else if (channel.target.name.empty()) {
      plan.channels.push_back(channel.channel);
    } else {
      plan.channels.push_back(fmt::format("{}→{}", channel.channel, channel.target.name));
    }
  }

  if (images > 0 && !holds.images) {
    plan.dropped.push_back(fmt::format("{}: {} image{} (E57 images2D) not written: {} holds no photos", path,
                                       images, images == 1 ? "" : "s", holds.name));
  }
  if (holds.extension == "pcd" && scans.size() == 1 && PcdNeedsDoubleCoordinates(scans[0])) {
    plan.dropped.push_back(
        fmt::format("{}: coordinates beyond {} m from the origin are written as doubles (F 8) to keep 0.1 "
                    "mm; some readers "
                    "(Open3D 0.16) read such PCD coordinates as zeros: write .ply, .las or .e57 for them",
                    path, io_internal::kCloudFloatSafeM));
  }
  // Carried attributes (Scan::attributes): LAS holds its own; every other writer drops them.
  std::vector<std::string> attributes;
  for (const Scan& scan : scans) {
    for (const auto& [name, values] : scan.attributes) {
      if (std::find(attributes.begin(), attributes.end(), name) == attributes.end())
        attributes.push_back(name);
    }
  }
  if (!attributes.empty()) {
    if (holds.extension == "las") {
      const LasWriteOptions options = las != nullptr ? *las : LasWriteOptions{};
      const int format = ChooseLasPointFormat(scans, options);
      const std::vector<std::string> lost = LasAttributesNotHeld(scans, format);
      for (const std::string& name : attributes) {
        if (std::find(lost.begin(), lost.end(), name) == lost.end()) plan.channels.push_back(name);
      }
      if (!lost.empty()) {
        plan.dropped.push_back(
            fmt::format("{}: point format {} does not hold {}", path, format, fmt::join(lost, ", ")));
      }
    } else {
      plan.dropped.push_back(fmt::format("{}: the attributes {} are not written ({} has no fields for them)",
                                         path, fmt::join(attributes, ", "), holds.name));
    }
  }
  const bool records = std::any_of(scans.begin(), scans.end(), [](const Scan& scan) {
    return std::any_of(scan.source_records.begin(), scan.source_records.end(),
                       [](const SourceRecord& record) { return record.user_id == "LASF_Projection"; });
  });
  if (records && holds.extension != "las") {
    plan.dropped.push_back(
        fmt::format("{}: the coordinate reference system (LAS GeoTIFF / WKT records) is not written ({} has "
                    "no field for it)",
                    path, holds.name));
  }
  if (scans_with_second_returns > 0) {
    plan.dropped.push_back(
        fmt::format("{}: the second returns of {} scan{} are not written (only first returns are converted)",
                    path, scans_with_second_returns, scans_with_second_returns == 1 ? "" : "s"));
  }
  return plan;
}

std::string WithThousandsSeparators(int64_t value) {
  const std::string digits = std::to_string(value < 0 ? -value : value);
  std::string out;
  for (size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out += ',';
    out += digits[i];
  }
  return value < 0 ? "-" + out : out;
}

std::string WrittenSummary(const std::string& path, const std::vector<Scan>& scans, size_t images_written,
                           const ScanWritePlan& plan) {
  int64_t points = 0;
  for (const Scan& scan : scans) points += scan.CountValid();
  std::string images;
  if (images_written > 0)
    images = fmt::format(", {} image{}", images_written, images_written == 1 ? "" : "s");
  return fmt::format("wrote {}: {} scan{}, {} point{}{}, channels {}", path, scans.size(),
                     scans.size() == 1 ? "" : "s", WithThousandsSeparators(points), points == 1 ? "" : "s",
                     images, fmt::join(plan.channels, " "));
}

ScanWriteSummary SummarizeScanWrite(const std::string& input, const std::string& output,
                                    const std::vector<Scan>& scans, size_t images_written,
                                    const ScanWritePlan& plan) {
  ScanWriteSummary summary;
  summary.input = input;
  summary.output = output;
  summary.format = FileExtension(output);
  summary.scans = static_cast<int64_t>(scans.size());
  for (const Scan& scan : scans) summary.returns += scan.CountValid();
  summary.images = static_cast<int64_t>(images_written);
  summary.channels = plan.channels;
  summary.dropped = plan.dropped;
  return summary;
}

}  // namespace lidarshop
