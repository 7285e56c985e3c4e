#include "lidarshop/cli/demo_page.h"

#include <stdexcept>

#include <fmt/format.h>
#include <kainjow/mustache.hpp>

#include "lidarshop/verify/sweep.h"

namespace lidarshop::cli {

// The template's text (generated from data/demo/index.html.mustache by this folder's CMakeLists.txt).
const char* DemoPageTemplate();

namespace {

using nlohmann::json;

constexpr const char* kPassColor = "#d8f0d8";
constexpr const char* kFailColor = "#f6d5d5";

// A JSON value as the template's data: objects and arrays as sections, strings as they are, numbers as JSON writes
// them (the page formats its numbers before they get here).
kainjow::mustache::data ToTemplateData(const json& value) {
  using kainjow::mustache::data;
  if (value.is_object()) {
    data object(data::type::object);
    for (const auto& [key, item] : value.items()) object.set(key, ToTemplateData(item));
    return object;
  }
  if (value.is_array()) {
    data list(data::type::list);
    for (const json& item : value) list.push_back(ToTemplateData(item));
    return list;
  }
  if (value.is_boolean()) return data(value.get<bool>());
  if (value.is_string()) return data(value.get<std::string>());
  return data(value.dump());
}

std::string Fixed(const json& value, int decimals) {
  if (value.is_null()) return "—";
  return fmt::format("{:.{}f}", value.get<double>(), decimals);
}

std::string Percent(const json& value, int decimals) {
  return fmt::format("{:.{}f}", 100 * value.get<double>(), decimals);
}

}  // namespace

// Every file the demo writes (index.html aside), with what it holds; the index links them all.
std::vector<std::pair<std::string, std::string>> DemoFiles(const json& summary) {
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
  if (summary.contains("sweep")) {
    files.insert(files.end(),
                 {{"sweep_consistency.png", "sweep: best consistency over headings, per position"},
                  {"sweep_confidence.png", "sweep: best confidence over headings, per position"},
                  {"sweep.csv", "sweep: every pose evaluated"}});
  }
  if (summary.contains("segment")) {
    files.insert(files.end(), {{"segment_overlay.png", "segmentation: the cut over the scan's colour"},
                               {"segment_mask.png", "segmentation: the object's cells (white)"},
                               {"segment_strokes.png", "segmentation: the automatic strokes"}});
  }
  if (summary.contains("stations")) {
    files.insert(
        files.end(),
        {{"stations.e57", "station 0 of the site with the object removed, filled from station 2 first"},
         {"stations_view_scan.png", "35° aside: station 0 with the object"},
         {"stations_view_filled.png",
          "35° aside: filled from station 2 (cyan: its real points; magenta: synthesized)"},
         {"stations_rays.png", "the ray picture of the same (cyan: from station 2; magenta: synthesized)"}});
  }
  if (summary.contains("remove")) {
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

std::string DemoPage(const std::string& scene_name, const json& summary) {
  const SweepOptions thresholds;
  json page = {{"scene", scene_name},
               {"min_consistency", fmt::format("{:.2f}", thresholds.min_consistency)},
               {"min_confidence", fmt::format("{:.2f}", thresholds.min_confidence)},
               {"pass_color", kPassColor},
               {"fail_color", kFailColor},
               {"verify", json::array()},
               {"files", json::array()},
               {"summary", summary.dump(2)}};
  for (const json& entry : summary.at("verify")) {
    const bool consistent =
        !entry.at("consistency").is_null() && entry["consistency"].get<double>() > thresholds.min_consistency;
    const bool confident = entry.at("confidence").get<double>() > thresholds.min_confidence;
    page["verify"].push_back({{"object", entry.at("object")},
                              {"pose", entry.at("pose")},
                              {"consistency", Fixed(entry["consistency"], 3)},
                              {"consistent", consistent},
                              {"confidence", Fixed(entry["confidence"], 3)},
                              {"confident", confident},
                              {"icp_cost", Fixed(entry.at("icp_cost"), 3)},
                              {"row_color", consistent && confident ? kPassColor : kFailColor},
                              {"verdict", consistent && confident ? "pass" : "fail"}});
  }
  if (summary.contains("sweep")) {
    const json& sweep = summary["sweep"];
    page["sweep"] = {{"model", sweep.at("model")},
                     {"poses", std::to_string(sweep.at("poses").get<size_t>())},
                     {"detections", std::to_string(sweep.at("detections").size())},
                     {"min_consistency", page["min_consistency"]},
                     {"min_confidence", page["min_confidence"]},
                     {"true_x", Fixed(sweep.at("true_position").at(0), 2)},
                     {"true_y", Fixed(sweep.at("true_position").at(1), 2)}};
  }
  if (summary.contains("segment")) {
    const json& segment = summary["segment"];
    page["segment"] = {{"object", segment.at("object")},
                       {"iou", Fixed(segment.at("iou"), 3)},
                       {"precision", Fixed(segment.at("precision"), 3)},
                       {"recall", Fixed(segment.at("recall"), 3)}};
  }
  if (summary.contains("remove")) {
    const json& remove = summary["remove"];
    page["remove"] = {{"hole_cells", std::to_string(remove.at("hole_cells").get<int64_t>())},
                      {"synthesized_points", std::to_string(remove.at("synthesized_points").get<int64_t>())},
                      {"range_rmse_mm", Fixed(remove.at("range_rmse_mm"), 1)},
                      {"within_20mm_percent", Percent(remove.at("within_20mm"), 1)},
                      {"floating_percent", Percent(remove.at("floating_points"), 2)},
                      {"return_accuracy_percent", Percent(remove.at("return_accuracy"), 1)},
                      {"color_psnr_db", Fixed(remove.at("color_psnr_db"), 1)},
                      {"seconds", Fixed(remove.at("seconds"), 2)}};
  }
  if (summary.contains("stations")) {
    const json& stations = summary["stations"];
    page["stations"] = {
        {"site", stations.at("site")},
        {"hole_cells", std::to_string(stations.at("hole_cells").get<int64_t>())},
        {"from_station_cells", std::to_string(stations.at("from_station_cells").get<int64_t>())},
        {"from_station_rmse_mm", Fixed(stations.at("from_station_rmse_mm"), 1)},
        {"synthesized_cells", std::to_string(stations.at("synthesized_cells").get<int64_t>())},
        {"range_rmse_mm", Fixed(stations.at("range_rmse_mm"), 1)},
        {"seconds", Fixed(stations.at("seconds"), 2)}};
  }
  for (const auto& [file, what] : DemoFiles(summary))
    page["files"].push_back({{"file", file}, {"what", what}});

  kainjow::mustache::mustache page_template(DemoPageTemplate());
  if (!page_template.is_valid()) {
    throw std::logic_error("data/demo/index.html.mustache: " + page_template.error_message());
  }
  const std::string html = page_template.render(ToTemplateData(page));
  if (!page_template.is_valid()) {
    throw std::logic_error("data/demo/index.html.mustache: " + page_template.error_message());
  }
  return html;
}

}  // namespace lidarshop::cli
