#include "lidarshop/cli/demo_page.h"

#include <cmath>
#include <stdexcept>

#include <fmt/format.h>
#include <kainjow/mustache.hpp>

#include "lidarshop/util/options.h"
#include "lidarshop/verify/sweep.h"

namespace lidarshop::cli {

// The template's text (generated from data/demo/index.html.mustache by this folder's CMakeLists.txt).
const char* DemoPageTemplate();

namespace {

constexpr const char* kPassColor = "#d8f0d8";
constexpr const char* kFailColor = "#f6d5d5";

// The template's data (data/demo/index.html.mustache): the summary's numbers formatted for people.
struct PageVerifyRow {
  std::string object, pose;
  std::string consistency;  // 3 decimals, "—" when none
  bool consistent = false;  // consistency above the sweep's default threshold
  std::string confidence;
  bool confident = false;
  std::string icp_cost;  // metres, 3 decimals, "—" when none
  std::string row_color, verdict;
};

struct PageSweep {
  std::string model, poses, detections, min_consistency, min_confidence, true_x, true_y;
};

struct PageSegment {
  std::string object, iou, precision, recall;
};

struct PageRemove {
  std::string hole_cells, synthesized_points, range_rmse_mm, within_20mm_percent, floating_percent,
      return_accuracy_percent, color_psnr_db, seconds;
};

struct PageStations {
  std::string site, hole_cells, from_station_cells, from_station_rmse_mm, synthesized_cells, range_rmse_mm,
      seconds;
};

struct PageFile {
  std::string file, what;
};

struct PageData {
  std::string scene, min_consistency, min_confidence, pass_color, fail_color;
  std::vector<PageVerifyRow> verify;
  std::vector<PageFile> files;
  std::string summary;  // summary.json's text
  std::optional<PageSweep> sweep;
  std::optional<PageSegment> segment;
  std::optional<PageRemove> remove;
  std::optional<PageStations> stations;
};

}  // namespace
}  // namespace lidarshop::cli

namespace lidarshop {

// Described only to reach the template through ToJson (not part of the schema's documented structs).
template <>
const StructInfo& InfoOf<cli::PageVerifyRow>() {
  static const StructInfo info = [] {
    StructBuilder<cli::PageVerifyRow> b("DemoPageVerifyRow", "a row of the page's verification table");
    b.Field(&cli::PageVerifyRow::object, "object", "the scene object");
    b.Field(&cli::PageVerifyRow::pose, "pose", "which pose");
    b.Field(&cli::PageVerifyRow::consistency, "consistency", "3 decimals, '—' when none");
    b.Field(&cli::PageVerifyRow::consistent, "consistent", "above the threshold");
    b.Field(&cli::PageVerifyRow::confidence, "confidence", "3 decimals");
    b.Field(&cli::PageVerifyRow::confident, "confident", "above the threshold");
    b.Field(&cli::PageVerifyRow::icp_cost, "icp_cost", "3 decimals, '—' when none").Unit("m");
    b.Field(&cli::PageVerifyRow::row_color, "row_color", "CSS colour of the row");
    b.Field(&cli::PageVerifyRow::verdict, "verdict", "pass or fail");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<cli::PageSweep>() {
  static const StructInfo info = [] {
    StructBuilder<cli::PageSweep> b("DemoPageSweep", "the page's sweep paragraph");
    b.Field(&cli::PageSweep::model, "model", "the swept object");
    b.Field(&cli::PageSweep::poses, "poses", "poses verified");
    b.Field(&cli::PageSweep::detections, "detections", "how many");
    b.Field(&cli::PageSweep::min_consistency, "min_consistency", "2 decimals");
    b.Field(&cli::PageSweep::min_confidence, "min_confidence", "2 decimals");
    b.Field(&cli::PageSweep::true_x, "true_x", "2 decimals").Unit("m");
    b.Field(&cli::PageSweep::true_y, "true_y", "2 decimals").Unit("m");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<cli::PageSegment>() {
  static const StructInfo info = [] {
    StructBuilder<cli::PageSegment> b("DemoPageSegment", "the page's segmentation scores");
    b.Field(&cli::PageSegment::object, "object", "the cut-out object");
    b.Field(&cli::PageSegment::iou, "iou", "3 decimals");
    b.Field(&cli::PageSegment::precision, "precision", "3 decimals");
    b.Field(&cli::PageSegment::recall, "recall", "3 decimals");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<cli::PageRemove>() {
  static const StructInfo info = [] {
    StructBuilder<cli::PageRemove> b("DemoPageRemove", "the page's removal scores");
    b.Field(&cli::PageRemove::hole_cells, "hole_cells", "an integer").Unit("cells");
    b.Field(&cli::PageRemove::synthesized_points, "synthesized_points", "an integer");
    b.Field(&cli::PageRemove::range_rmse_mm, "range_rmse_mm", "1 decimal").Unit("mm");
    b.Field(&cli::PageRemove::within_20mm_percent, "within_20mm_percent", "1 decimal").Unit("%");
    b.Field(&cli::PageRemove::floating_percent, "floating_percent", "2 decimals").Unit("%");
    b.Field(&cli::PageRemove::return_accuracy_percent, "return_accuracy_percent", "1 decimal").Unit("%");
    b.Field(&cli::PageRemove::color_psnr_db, "color_psnr_db", "1 decimal").Unit("dB");
    b.Field(&cli::PageRemove::seconds, "seconds", "2 decimals").Unit("s");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<cli::PageStations>() {
  static const StructInfo info = [] {
    StructBuilder<cli::PageStations> b("DemoPageStations", "the page's fill from another station");
    b.Field(&cli::PageStations::site, "site", "the built-in site");
    b.Field(&cli::PageStations::hole_cells, "hole_cells", "an integer").Unit("cells");
    b.Field(&cli::PageStations::from_station_cells, "from_station_cells", "an integer").Unit("cells");
    b.Field(&cli::PageStations::from_station_rmse_mm, "from_station_rmse_mm", "1 decimal").Unit("mm");
    b.Field(&cli::PageStations::synthesized_cells, "synthesized_cells", "an integer").Unit("cells");
    b.Field(&cli::PageStations::range_rmse_mm, "range_rmse_mm", "1 decimal").Unit("mm");
    b.Field(&cli::PageStations::seconds, "seconds", "2 decimals").Unit("s");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<cli::PageFile>() {
  static const StructInfo info = [] {
    StructBuilder<cli::PageFile> b("DemoPageFile", "a file the demo wrote");
    b.Field(&cli::PageFile::file, "file", "its name in the output folder");
    b.Field(&cli::PageFile::what, "what", "what it holds");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<cli::PageData>() {
  static const StructInfo info = [] {
    StructBuilder<cli::PageData> b("DemoPageData", "what data/demo/index.html.mustache shows");
    b.Field(&cli::PageData::scene, "scene", "the scene's name");
    b.Field(&cli::PageData::min_consistency, "min_consistency", "the threshold, 2 decimals");
    b.Field(&cli::PageData::min_confidence, "min_confidence", "the threshold, 2 decimals");
    b.Field(&cli::PageData::pass_color, "pass_color", "CSS colour of a passing row");
    b.Field(&cli::PageData::fail_color, "fail_color", "CSS colour of a failing row");
    b.Field(&cli::PageData::verify, "verify", "the verification table");
    b.Field(&cli::PageData::files, "files", "every file the demo wrote");
    b.Field(&cli::PageData::summary, "summary", "summary.json's text");
    b.Field(&cli::PageData::sweep, "sweep", "scenes with a sweep");
    b.Field(&cli::PageData::segment, "segment", "scenes with an object cut out");
    b.Field(&cli::PageData::remove, "remove", "the same");
    b.Field(&cli::PageData::stations, "stations", "scenes with a site");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<cli::DemoScanSummary>() {
  static const StructInfo info = [] {
    StructBuilder<cli::DemoScanSummary> b("DemoScanSummary", "the demo's synthetic scan");
    b.Field(&cli::DemoScanSummary::rows, "rows", "scan rows");
    b.Field(&cli::DemoScanSummary::cols, "cols", "scan columns");
    b.Field(&cli::DemoScanSummary::valid, "valid", "cells with a return").Unit("cells");
    b.Field(&cli::DemoScanSummary::triangles, "triangles", "triangles of the scanned scene");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<cli::DemoVerifyEntry>() {
  static const StructInfo info = [] {
    StructBuilder<cli::DemoVerifyEntry> b("DemoVerifyEntry", "one scene object verified at one pose");
    b.Field(&cli::DemoVerifyEntry::object, "object", "the scene object's name");
    b.Field(&cli::DemoVerifyEntry::pose, "pose",
            "true, 1 m towards the scanner or 1 m away from the scanner");
    b.Field(&cli::DemoVerifyEntry::consistency, "consistency",
            "share of comparable pairs that agree; null = none");
    b.Field(&cli::DemoVerifyEntry::comparable_pairs, "comparable_pairs", "scan point / model pairs compared");
    b.Field(&cli::DemoVerifyEntry::confidence, "confidence",
            "information of the model seen by the scan, [0, 1]");
    b.Field(&cli::DemoVerifyEntry::icp_cost, "icp_cost", "trimmed ICP cost; null = no inlier pair").Unit("m");
    b.Field(&cli::DemoVerifyEntry::inlier_fraction, "inlier_fraction",
            "inliers / scene points near the model");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<cli::DemoSweepDetection>() {
  static const StructInfo info = [] {
    StructBuilder<cli::DemoSweepDetection> b("DemoSweepDetection", "a detection of the demo's sweep");
    b.Field(&cli::DemoSweepDetection::x, "x", "world x of the model origin").Unit("m");
    b.Field(&cli::DemoSweepDetection::y, "y", "world y of the model origin").Unit("m");
    b.Field(&cli::DemoSweepDetection::yaw_deg, "yaw_deg", "yaw about +z").Unit("deg");
    b.Field(&cli::DemoSweepDetection::consistency, "consistency", "share of comparable pairs that agree");
    b.Field(&cli::DemoSweepDetection::confidence, "confidence", "information of the model seen, [0, 1]");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<cli::DemoSweepSummary>() {
  static const StructInfo info = [] {
    StructBuilder<cli::DemoSweepSummary> b("DemoSweepSummary", "the demo's sweep of one object's model");
    b.Field(&cli::DemoSweepSummary::model, "model", "the scene object whose mesh is swept");
    b.Field(&cli::DemoSweepSummary::true_position, "true_position", "its world x, y").Unit("m");
    b.Field(&cli::DemoSweepSummary::poses, "poses", "poses verified: the grid's and the refinement's");
    b.Field(&cli::DemoSweepSummary::detections, "detections", "by decreasing confidence");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<cli::DemoSegmentSummary>() {
  static const StructInfo info = [] {
    StructBuilder<cli::DemoSegmentSummary> b(
        "DemoSegmentSummary", "the object cut out from automatic strokes, against the true labels");
    b.Field(&cli::DemoSegmentSummary::object, "object", "the scene object's name");
    b.Field(&cli::DemoSegmentSummary::label, "label", "its label");
    b.Field(&cli::DemoSegmentSummary::iou, "iou", "intersection over union with the true cells");
    b.Field(&cli::DemoSegmentSummary::precision, "precision", "share of the cut that is the object");
    b.Field(&cli::DemoSegmentSummary::recall, "recall", "share of the object that is cut");
    b.Field(&cli::DemoSegmentSummary::object_cells, "object_cells", "cells of the cut").Unit("cells");
    b.Field(&cli::DemoSegmentSummary::seconds, "seconds", "wall time of the segmentation").Unit("s");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<cli::DemoRemoveSummary>() {
  static const StructInfo info = [] {
    StructBuilder<cli::DemoRemoveSummary> b(
        "DemoRemoveSummary", "the object removed and its hole filled, against the scene scanned without it");
    b.Field(&cli::DemoRemoveSummary::object, "object", "the scene object's name");
    b.Field(&cli::DemoRemoveSummary::hole_cells, "hole_cells", "cells of the hole").Unit("cells");
    b.Field(&cli::DemoRemoveSummary::synthesized_points, "synthesized_points", "hole cells given a return");
    b.Field(&cli::DemoRemoveSummary::no_return_cells, "no_return_cells", "hole cells left without a return")
        .Unit("cells");
    b.Field(&cli::DemoRemoveSummary::range_rmse_mm, "range_rmse_mm", "range error against the truth")
        .Unit("mm");
    b.Field(&cli::DemoRemoveSummary::range_mae_mm, "range_mae_mm", "mean absolute range error").Unit("mm");
    b.Field(&cli::DemoRemoveSummary::within_20mm, "within_20mm", "share of compared cells within 20 mm");
    b.Field(&cli::DemoRemoveSummary::floating_points, "floating_points",
            "share of synthesized points floating");
    b.Field(&cli::DemoRemoveSummary::return_accuracy, "return_accuracy",
            "share of hole cells whose return / no-return matches the truth");
    b.Field(&cli::DemoRemoveSummary::color_psnr_db, "color_psnr_db", "RGB PSNR over compared cells")
        .Unit("dB");
    b.Field(&cli::DemoRemoveSummary::seconds, "seconds", "wall time of the fill").Unit("s");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<cli::DemoStationsSummary>() {
  static const StructInfo info = [] {
    StructBuilder<cli::DemoStationsSummary> b(
        "DemoStationsSummary", "the object removed from station 0, filled from station 2 first");
    b.Field(&cli::DemoStationsSummary::object, "object", "the scene object's name");
    b.Field(&cli::DemoStationsSummary::site, "site", "the built-in site");
    b.Field(&cli::DemoStationsSummary::hole_cells, "hole_cells", "cells of the hole").Unit("cells");
    b.Field(&cli::DemoStationsSummary::from_station_cells, "from_station_cells",
            "hole cells station 2 measured")
        .Unit("cells");
    b.Field(&cli::DemoStationsSummary::synthesized_cells, "synthesized_cells", "hole cells synthesized")
        .Unit("cells");
    b.Field(&cli::DemoStationsSummary::no_return_cells, "no_return_cells", "hole cells left without a return")
        .Unit("cells");
    b.Field(&cli::DemoStationsSummary::from_station_rmse_mm, "from_station_rmse_mm",
            "range error of the cells from station 2; 0 when none")
        .Unit("mm");
    b.Field(&cli::DemoStationsSummary::range_rmse_mm, "range_rmse_mm", "range error of the whole fill")
        .Unit("mm");
    b.Field(&cli::DemoStationsSummary::floating_points, "floating_points",
            "share of synthesized points floating");
    b.Field(&cli::DemoStationsSummary::seconds, "seconds", "wall time of the cast and the synthesis")
        .Unit("s");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<cli::DemoSeconds>() {
  static const StructInfo info = [] {
    StructBuilder<cli::DemoSeconds> b("DemoSeconds", "wall time of each of the demo's steps");
    b.Field(&cli::DemoSeconds::load, "load", "loading the scene").Unit("s");
    b.Field(&cli::DemoSeconds::scan, "scan", "scanning it").Unit("s");
    b.Field(&cli::DemoSeconds::write, "write", "writing the scan and its pictures").Unit("s");
    b.Field(&cli::DemoSeconds::verify, "verify", "verifying the objects").Unit("s");
    b.Field(&cli::DemoSeconds::sweep, "sweep", "the sweep").Unit("s");
    b.Field(&cli::DemoSeconds::segment, "segment", "the segmentation").Unit("s");
    b.Field(&cli::DemoSeconds::remove, "remove", "the removal").Unit("s");
    b.Field(&cli::DemoSeconds::stations, "stations", "the fill from another station").Unit("s");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<cli::DemoSummary>() {
  static const StructInfo info = [] {
    StructBuilder<cli::DemoSummary> b("DemoSummary",
                                      "lidarshop demo: summary.json and --json (keys written sorted)");
    b.Field(&cli::DemoSummary::scene, "scene", "the scene's name");
    b.Field(&cli::DemoSummary::scan, "scan", "the synthetic scan");
    b.Field(&cli::DemoSummary::verify, "verify", "every standing object at its true pose and two wrong ones");
    b.Field(&cli::DemoSummary::sweep, "sweep", "scenes with a sweep");
    b.Field(&cli::DemoSummary::segment, "segment", "scenes with an object to cut out");
    b.Field(&cli::DemoSummary::remove, "remove", "the same object removed");
    b.Field(&cli::DemoSummary::stations, "stations", "scenes with a site holding the object");
    b.Field(&cli::DemoSummary::seconds, "seconds", "wall time of each step");
    return b.Build();
  }();
  return info;
}

}  // namespace lidarshop

namespace lidarshop::cli {
namespace {

// "—" for none (NaN), else `decimals` decimals.
std::string FixedOrDash(double value, int decimals) {
  if (!std::isfinite(value)) return "—";
  return fmt::format("{:.{}f}", value, decimals);
}

std::string Fixed(double value, int decimals) { return fmt::format("{:.{}f}", value, decimals); }

std::string Percent(double value, int decimals) { return fmt::format("{:.{}f}", 100 * value, decimals); }

// A JSON value as the template's data: objects and arrays as sections, strings as they are, numbers as JSON
// writes them.
kainjow::mustache::data ToTemplateData(const nlohmann::ordered_json& value) {
  using kainjow::mustache::data;
  if (value.is_object()) {
    data object(data::type::object);
    for (const auto& [key, item] : value.items()) object.set(key, ToTemplateData(item));
    return object;
  }
  if (value.is_array()) {
    data list(data::type::list);
    for (const nlohmann::ordered_json& item : value) list.push_back(ToTemplateData(item));
    return list;
  }
  if (value.is_boolean()) return data(value.get<bool>());
  if (value.is_string()) return data(value.get<std::string>());
  return data(value.dump());
}

}  // namespace

// Every file the demo writes (index.html aside), with what it holds; the index links them all.
std::vector<std::pair<std::string, std::string>> DemoFiles(const DemoSummary& summary) {
  std::vector<std::pair<std::string, std::string>> files = {
      {"scan.ptx", "the synthetic scan, Leica PTX (ASCII)"},
      {"scan.e57", "the synthetic scan, E57"},
      {"labels.png",
       "true object label of every ray, raw 16-bit PNG (65535 = no return); labels_view.png is "
       "its colour picture"},
      {"rgb.png", "the scan's colour"},
      {"range.png", "range in metres"},
      {"range.exr", "range in metres as 32-bit floats, one pixel per ray, NaN = no return"},
      {"intensity.png", "return intensity"},
      {"labels_view.png", "object labels in colour, with the objects' names"},
      {"normals.png", "surface normals, with the key of their colours"},
      {"top_view.png", "the points from above and behind the scanner (a second viewpoint, perspective)"},
      {"verify.json", "the verification table as JSON"}};
  if (summary.sweep) {
    files.insert(files.end(),
                 {{"sweep_consistency.png", "sweep: best consistency over headings, per position"},
                  {"sweep_confidence.png", "sweep: best confidence over headings, per position"},
                  {"sweep.csv", "sweep: every pose evaluated"}});
  }
  if (summary.segment) {
    files.insert(files.end(), {{"segment_overlay.png", "segmentation: the cut over the scan's colour"},
                               {"segment_mask.png", "segmentation: the object's cells (white)"},
                               {"segment_strokes.png", "segmentation: the automatic strokes"}});
  }
  if (summary.stations) {
    files.insert(
        files.end(),
        {{"stations.e57", "station 0 of the site with the object removed, filled from station 2 first"},
         {"stations_view_scan.png", "35° aside: station 0 with the object"},
         {"stations_view_filled.png",
          "35° aside: filled from station 2 (cyan: its real points; magenta: synthesized)"},
         {"stations_rays.png", "the ray picture of the same (cyan: from station 2; magenta: synthesized)"}});
  }
  if (summary.remove) {
    files.insert(files.end(),
                 {{"removed.e57", "the scan with the object removed and the hole filled"},
                  {"remove_range.png", "range after the removal"},
                  {"remove_view_scan.png", "35° aside: the scan with the object"},
                  {"remove_view_truth.png", "35° aside: the scene scanned without the object"},
                  {"remove_view_filled.png", "35° aside: the fill (synthesized points magenta)"}});
  }
  files.push_back({"summary.json", "every number of this page"});
  return files;
}

nlohmann::json DemoSummaryJson(const DemoSummary& summary) { return nlohmann::json(ToJson(summary)); }

std::string DemoPage(const std::string& scene_name, const DemoSummary& summary) {
  const SweepOptions thresholds;
  PageData page{.scene = scene_name,
                .min_consistency = fmt::format("{:.2f}", thresholds.min_consistency),
                .min_confidence = fmt::format("{:.2f}", thresholds.min_confidence),
                .pass_color = kPassColor,
                .fail_color = kFailColor,
                .summary = DemoSummaryJson(summary).dump(2)};
  for (const DemoVerifyEntry& entry : summary.verify) {
    const bool consistent =
        std::isfinite(entry.consistency) && entry.consistency > thresholds.min_consistency;
    const bool confident = entry.confidence > thresholds.min_confidence;
    page.verify.push_back({.object = entry.object,
                           .pose = entry.pose,
                           .consistency = FixedOrDash(entry.consistency, 3),
                           .consistent = consistent,
                           .confidence = Fixed(entry.confidence, 3),
                           .confident = confident,
                           .icp_cost = FixedOrDash(entry.icp_cost, 3),
                           .row_color = consistent && confident ? kPassColor : kFailColor,
                           .verdict = consistent && confident ? "pass" : "fail"});
  }
  if (const auto& sweep = summary.sweep) {
    page.sweep = PageSweep{.model = sweep->model,
                           .poses = std::to_string(sweep->poses),
                           .detections = std::to_string(sweep->detections.size()),
                           .min_consistency = page.min_consistency,
                           .min_confidence = page.min_confidence,
                           .true_x = Fixed(sweep->true_position.at(0), 2),
                           .true_y = Fixed(sweep->true_position.at(1), 2)};
  }
  if (const auto& segment = summary.segment) {
    page.segment = PageSegment{.object = segment->object,
                               .iou = Fixed(segment->iou, 3),
                               .precision = Fixed(segment->precision, 3),
                               .recall = Fixed(segment->recall, 3)};
  }
  if (const auto& remove = summary.remove) {
    page.remove = PageRemove{.hole_cells = std::to_string(remove->hole_cells),
                             .synthesized_points = std::to_string(remove->synthesized_points),
                             .range_rmse_mm = Fixed(remove->range_rmse_mm, 1),
                             .within_20mm_percent = Percent(remove->within_20mm, 1),
                             .floating_percent = Percent(remove->floating_points, 2),
                             .return_accuracy_percent = Percent(remove->return_accuracy, 1),
                             .color_psnr_db = Fixed(remove->color_psnr_db, 1),
                             .seconds = Fixed(remove->seconds, 2)};
  }
  if (const auto& stations = summary.stations) {
    page.stations = PageStations{.site = stations->site,
                                 .hole_cells = std::to_string(stations->hole_cells),
                                 .from_station_cells = std::to_string(stations->from_station_cells),
                                 .from_station_rmse_mm = Fixed(stations->from_station_rmse_mm, 1),
                                 .synthesized_cells = std::to_string(stations->synthesized_cells),
                                 .range_rmse_mm = Fixed(stations->range_rmse_mm, 1),
                                 .seconds = Fixed(stations->seconds, 2)};
  }
  for (const auto& [file, what] : DemoFiles(summary)) page.files.push_back({.file = file, .what = what});

  kainjow::mustache::mustache page_template(DemoPageTemplate());
  if (!page_template.is_valid()) {
    throw std::logic_error("data/demo/index.html.mustache: " + page_template.error_message());
  }
  const std::string html = page_template.render(ToTemplateData(ToJson(page)));
  if (!page_template.is_valid()) {
    throw std::logic_error("data/demo/index.html.mustache: " + page_template.error_message());
  }
  return html;
}

}  // namespace lidarshop::cli
