#include "lidarshop/site/from_stations.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "lidarshop/scanner/scanner.h"
#include "lidarshop/scanner/scene.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"

namespace lidarshop {
namespace {

constexpr double kNoiseSigma = 0.004;  // los_noise_sigma of the stations below, metres
constexpr int32_t kHatchback = 3, kLateSedan = 7;

// The built-in site at half its resolution (480 x 280 rays per station), so that the test stays quick.
SceneDescription Site() {
  SceneDescription site =
      LoadScene(std::string(LIDARSHOP_SOURCE_DIR) + "/data/scenes/parking_lot_stations.json");
  for (ScannerOptions& station : site.stations) {
    station.columns = 480;
    station.rows = 280;
  }
  site.scanner = site.stations[0];
  return site;
}

// Station `i` as scanned, or without the objects labelled `without` (the truth behind them).
Scan ScanStation(const SceneDescription& site, int i, int32_t without = -100) {
  SceneDescription at = SceneAtStation(site, i);
  std::erase_if(at.objects, [&](const SceneObject& object) { return object.label == without; });
  return SynthesizeScan(at);
}

const std::vector<Scan>& Stations() {
  static const std::vector<Scan> stations = [] {
    const SceneDescription site = Site();
    std::vector<Scan> scans;
    for (int i = 0; i < 3; ++i) scans.push_back(ScanStation(site, i));
    return scans;
  }();
  return stations;
}

cv::Mat ObjectHole(const Scan& scan, int32_t label) {
  return GrowHole((scan.label == label) & (scan.valid != 0), 2);
}

struct Comparison {
  int64_t compared = 0, far_off = 0, truth_empty = 0;
  double rmse_m = 0;
};

// The cells filled from stations against the truth's noise-free ranges; `far_off` counts errors over 0.3 m.
Comparison CompareWithTruth(const FromStationsResult& result, const Scan& truth) {
  Comparison out;
  double sum = 0;
  for (int r = 0; r < truth.rows; ++r) {
    for (int c = 0; c < truth.cols; ++c) {
      if (result.from_station.at<uint8_t>(r, c) == 0) continue;
      if (truth.valid.at<uint8_t>(r, c) == 0) {
        ++out.truth_empty;
        continue;
      }
      const double error = result.scan.range.at<float>(r, c) - truth.true_range.at<float>(r, c);
      sum += error * error;
      out.far_off += std::abs(error) > 0.3;
      ++out.compared;
    }
  }
  out.rmse_m = std::sqrt(sum / std::max<int64_t>(1, out.compared));
  return out;
}

TEST(FillFromStations, TakesTheSurfaceAStationWithoutTheCarMeasured) {
  const std::vector<Scan>& stations = Stations();
  const Scan truth = ScanStation(Site(), 0, kHatchback);
  const cv::Mat hole = ObjectHole(stations[0], kHatchback);
  const FromStationsResult result = FillFromStations(stations[0], hole, {stations[2]});
  const Comparison compared = CompareWithTruth(result, truth);
  const FillResult alone = FillScan(MaskScan(stations[0], hole == 0), hole);
  std::printf(
      "hole %lld cells: %lld from station 2 (rim %lld, not free %lld), %lld synthesized (alone: %lld); "
      "RMSE %.4f m over %lld, %lld over 0.3 m, %lld where the truth has no return; %.2f + %.2f s\n",
      (long long)result.hole_cells, (long long)result.from_station_cells, (long long)result.rim_cells,
      (long long)result.not_free_cells, (long long)result.synthesized_cells,
      (long long)alone.synthesized_cells, compared.rmse_m, (long long)compared.compared,
      (long long)compared.far_off, (long long)compared.truth_empty, result.stations_seconds,
      result.fill_seconds);
  EXPECT_GT(result.from_station_cells, result.hole_cells * 2 / 5);
  EXPECT_EQ(result.cells_per_station, std::vector<int64_t>{result.from_station_cells});
  EXPECT_LE(compared.rmse_m, 2 * kNoiseSigma);
  EXPECT_EQ(compared.far_off, 0);
  // The synthesized share shrinks to what station 2 did not see (or saw at an edge or grazing).
  EXPECT_LT(result.synthesized_cells, alone.synthesized_cells * 3 / 5);
  // The real cells are marked as such, never as synthesized, and only hole cells changed.
  EXPECT_EQ(cv::countNonZero(result.scan.from_station), result.from_station_cells);
  EXPECT_EQ(cv::countNonZero((result.from_station != 0) & (result.scan.synthesized != 0)), 0);
  EXPECT_EQ(cv::countNonZero((result.from_station != 0) & (hole == 0)), 0);
  EXPECT_EQ(cv::countNonZero((result.scan.synthesized != 0) & (hole == 0)), 0);
  EXPECT_EQ(cv::norm(result.scan.range, stations[0].range, cv::NORM_INF, hole == 0), 0.0);
  // Station 2 saw no hatchback: nothing of it was marked there.
  ASSERT_EQ(result.object_cells.size(), 1u);
  EXPECT_LT(result.object_cells[0], 50);
}

// The hatchback stands at stations 0 and 1: station 1's view of its far side lies behind its front too, and
// must not be painted into station 0.
TEST(FillFromStations, DoesNotTakeTheRemovedCarsFarSideFromAStationWhereItStands) {
  const std::vector<Scan>& stations = Stations();
  const Scan truth = ScanStation(Site(), 0, kHatchback);
  const cv::Mat hole = ObjectHole(stations[0], kHatchback);
  auto car_cells = [&](const FromStationsResult& result) {
    return cv::countNonZero((result.from_station != 0) & (result.scan.label == kHatchback));
  };
  const FromStationsResult result = FillFromStations(stations[0], hole, {stations[1]});
  const Comparison compared = CompareWithTruth(result, truth);
  std::printf(
      "from station 1: %lld cells (rim %lld, not free %lld), %lld of them the car; object marked in %lld "
      "cells of station 1; RMSE %.4f m, %lld over 0.3 m\n",
      (long long)result.from_station_cells, (long long)result.rim_cells, (long long)result.not_free_cells,
      (long long)car_cells(result), (long long)result.object_cells[0], compared.rmse_m,
      (long long)compared.far_off);
  EXPECT_GT(result.object_cells[0], 500);
  EXPECT_EQ(car_cells(result), 0);
  EXPECT_LE(compared.far_off, compared.compared / 100);
  EXPECT_LE(compared.rmse_m, 0.05);
}

// A station behind the hatchback, which sees mostly its far side (none of its cells on station 0's points of
// it, so the car is barely marked there): the free-space check keeps that far side out; without the check and
// the marking it comes through (so the tests above can fail).
TEST(FillFromStations, KeepsOutAFarSideOnlyAnotherStationSaw) {
  const std::vector<Scan>& stations = Stations();
  const cv::Mat hole = ObjectHole(stations[0], kHatchback);
  SceneDescription behind = SceneAtStation(Site(), 0);
  behind.scanner.position = Eigen::Vector3d(3, 18, 1.6);
  behind.scanner.rotate_deg = Eigen::Vector3d(0, 0, 157);  // facing the car
  behind.scanner.seed = 4;
  const Scan far_side = SynthesizeScan(behind);
  auto car_cells = [&](const FromStationsResult& result) {
    return cv::countNonZero((result.from_station != 0) & (result.scan.label == kHatchback));
  };
  const FromStationsResult kept_out = FillFromStations(stations[0], hole, {far_side});
  FromStationsOptions unprotected;
  unprotected.object_min_cells = 1 << 30;
  unprotected.check_free_space = false;
  const FromStationsResult let_in = FillFromStations(stations[0], hole, {far_side}, unprotected);
  std::printf("far side: %lld car cells taken (%lld not free), %lld without the protections\n",
              (long long)car_cells(kept_out), (long long)kept_out.not_free_cells,
              (long long)car_cells(let_in));
  EXPECT_LE(car_cells(kept_out), 10);
  EXPECT_GT(car_cells(let_in), 100);
}

TEST(FillFromStations, RemovesTheSedanOfStationTwoFromStationsZeroAndOne) {
  const std::vector<Scan>& stations = Stations();
  const Scan truth = ScanStation(Site(), 2, kLateSedan);
  const cv::Mat hole = ObjectHole(stations[2], kLateSedan);
  const FromStationsResult result = FillFromStations(stations[2], hole, {stations[0], stations[1]});
  const Comparison compared = CompareWithTruth(result, truth);
  std::printf(
      "sedan: hole %lld, from stations 0 / 1: %lld / %lld, synthesized %lld; RMSE %.4f m, %lld over 0.3 m\n",
      (long long)result.hole_cells, (long long)result.cells_per_station[0],
      (long long)result.cells_per_station[1], (long long)result.synthesized_cells, compared.rmse_m,
      (long long)compared.far_off);
  EXPECT_GT(result.from_station_cells, result.hole_cells / 20);
  EXPECT_LE(compared.rmse_m, 2 * kNoiseSigma);
  EXPECT_LT(result.synthesized_cells, FillScan(MaskScan(stations[2], hole == 0), hole).synthesized_cells);
  EXPECT_EQ(cv::countNonZero((result.from_station != 0) & (result.scan.label == kLateSedan)), 0);
}

// A street corner seen from a station at (x, y) turned yaw_deg, with `extra` objects there.
std::string StreetStation(double x, double y, double yaw_deg, int seed, const std::string& extra) {
  return fmt::format(
      R"({{"scanner": {{"position": [{}, {}, 1.6], "rotate_deg": [0, 0, {}], "azimuth_deg": [-60, 60],
           "elevation_deg": [-30, 25], "columns": 420, "rows": 190, "max_range": 80,
           "los_noise_sigma": 0.004, "orthogonal_noise_sigma": 0.002, "seed": {}}},
          "objects": [
            {{"primitive": "plane", "size": [80, 80], "translate": [0, 20, 0], "label": 0, "texture": "gravel"}},
            {{"primitive": "box", "size": [30, 0.5, 8], "translate": [0, 18, 4], "label": 1, "color": [200, 190, 170]}},
            {{"primitive": "box", "size": [6, 0.3, 0.8], "translate": [-6, 12, 0.4], "label": 2}},
            {{"primitive": "cylinder", "radius": 0.15, "height": 4, "translate": [-3, 7, 2], "label": 4}}{}]}})",
      x, y, yaw_deg, seed, extra);
}

// Sites not tuned on: three stations at places drawn from the seed, one to three boxes of people's and cars'
// sizes at one of them only, removed from that station with the two others, against that station scanned
// without them.
TEST(FillFromStations, HoldsOnRandomSites) {
  double worst_rmse = 0, sum_squares = 0;
  int64_t compared = 0, taken = 0, synthesized = 0, synthesized_alone = 0;
  for (uint32_t seed = 1; seed <= 5; ++seed) {
    std::mt19937 random(seed);
    auto uniform = [&](double lo, double hi) {
      return std::uniform_real_distribution<double>(lo, hi)(random);
    };
    struct Place {
      double x, y, yaw;
    };
    std::vector<Place> places;
    for (int i = 0; i < 3; ++i) places.push_back({uniform(-5, 5), uniform(-1, 3), uniform(-20, 20)});
    const int movers = 1 + static_cast<int>(random() % 3);
    std::vector<std::string> extra(3), mover(movers);
    // Every box stands at the same station: what the other stations measured behind them is the static
    // scene (a box another station saw where the removed one hid the ground would be taken as measured:
    // from_stations.h says it cannot know).
    const int station_of_boxes = static_cast<int>(random() % 3);
    std::vector<int> at(movers);
    for (int m = 0; m < movers; ++m) {
      at[m] = station_of_boxes;
      const double height = uniform(1.0, 1.9);
      mover[m] = fmt::format(
          R"(, {{"primitive": "box", "size": [{:.2f}, {:.2f}, {:.2f}], "translate": [{:.2f}, {:.2f}, {:.3f}],
               "label": {}}})",
          uniform(0.4, 2.0), uniform(0.3, 1.5), height, uniform(-5, 5) + 2.5 * m, uniform(7, 14), height / 2,
          10 + m);
      extra[at[m]] += mover[m];
    }
    auto scan_station = [&](int i, const std::string& objects) {
      return SynthesizeScan(ParseScene(
          StreetStation(places[i].x, places[i].y, places[i].yaw, static_cast<int>(10 * seed) + i, objects),
          "random site", "."));
    };
    std::vector<Scan> scans;
    for (int i = 0; i < 3; ++i) scans.push_back(scan_station(i, extra[i]));
    // All the boxes removed at once (what clean does), against the station scanned without any.
    const int i = station_of_boxes;
    cv::Mat hole = cv::Mat::zeros(scans[i].rows, scans[i].cols, CV_8U);
    for (int m = 0; m < movers; ++m) hole |= ObjectHole(scans[i], 10 + m);
    if (cv::countNonZero(hole) < 50) continue;  // out of view
    const Scan truth = scan_station(i, "");
    std::vector<Scan> others;
    for (int j = 0; j < 3; ++j)
      if (j != i) others.push_back(scans[j]);
    const FromStationsResult result = FillFromStations(scans[i], hole, others);
    const Comparison c = CompareWithTruth(result, truth);
    const FillResult alone = FillScan(MaskScan(scans[i], hole == 0), hole);
    std::printf(
        "site %u, %d box(es) at station %d: hole %lld, from stations %lld (RMSE %.4f m, %lld over 0.3 m), "
        "synthesized %lld (alone %lld)\n",
        seed, movers, i, (long long)result.hole_cells, (long long)result.from_station_cells, c.rmse_m,
        (long long)c.far_off, (long long)result.synthesized_cells, (long long)alone.synthesized_cells);
    worst_rmse = std::max(worst_rmse, c.rmse_m);
    sum_squares += c.rmse_m * c.rmse_m * static_cast<double>(c.compared);
    compared += c.compared;
    taken += result.from_station_cells;
    synthesized += result.synthesized_cells;
    synthesized_alone += alone.synthesized_cells;
  }
  const double rmse = std::sqrt(sum_squares / static_cast<double>(std::max<int64_t>(1, compared)));
  std::printf(
      "all sites: %lld cells from stations, RMSE %.4f m (worst site %.4f m); synthesized %lld, alone %lld\n",
      (long long)taken, rmse, worst_rmse, (long long)synthesized, (long long)synthesized_alone);
  EXPECT_GT(taken, 0);
  EXPECT_LE(rmse, 2 * kNoiseSigma);
  EXPECT_LT(synthesized, synthesized_alone / 2);
}

TEST(FillFromStations, RefusesBadInput) {
  const std::vector<Scan>& stations = Stations();
  EXPECT_THROW(FillFromStations(stations[0], cv::Mat::zeros(3, 3, CV_8U), {stations[1]}), InputError);
  const Scan cloud = MakeScan(1, 50);
  const cv::Mat hole = ObjectHole(stations[0], kHatchback);
  EXPECT_THROW(FillFromStations(stations[0], hole, {cloud}), InputError);
  FromStationsOptions bad;
  bad.max_incidence_deg = 0;
  EXPECT_THROW(FillFromStations(stations[0], hole, {stations[1]}, bad), OptionsError);
}

// The JSON keys of `json`, in order.
std::vector<std::string> Keys(const nlohmann::ordered_json& json) {
  std::vector<std::string> keys;
  for (const auto& item : json.items()) keys.push_back(item.key());
  return keys;
}

TEST(FillFromStations, ResultJsonHoldsTheSynthesisNumbersOnlyWhenItRan) {
  FromStationsResult result;
  result.hole_cells = 9;
  result.from_station_cells = 9;
  result.fill.hole_cells = 4;  // the synthesis's own counts give way to the whole hole's
  result.fill.warnings = {"the synthesis's"};
  result.warnings = {"the fill's"};
  result.stations.push_back({.station = 1, .file = "site.e57", .scan = 2, .name = "station2"});
  EXPECT_EQ(Keys(ToJson(result)),
            (std::vector<std::string>{"hole_cells", "synthesized_cells", "no_return_cells", "warnings",
                                      "from_station_cells", "stations", "rim_cells", "not_free_cells",
                                      "stations_seconds", "fill_seconds"}));
  result.filled_rest = true;
  const nlohmann::ordered_json json = ToJson(result);
  std::vector<std::string> expected = InfoOf<FillResult>().Keys();
  for (const char* key :
       {"from_station_cells", "stations", "rim_cells", "not_free_cells", "stations_seconds", "fill_seconds"})
    expected.push_back(key);
  EXPECT_EQ(Keys(json), expected);
  EXPECT_EQ(json["hole_cells"], 9);
  EXPECT_EQ(json["warnings"], nlohmann::json::array({"the fill's"}));
  EXPECT_EQ(json["timings"], ToJson(result.fill.timings));
  EXPECT_EQ(json["stations"][0].dump(),
            R"({"station":1,"file":"site.e57","scan":2,"name":"station2","from_station_cells":0,)"
            R"("object_cells":0})");
}

}  // namespace
}  // namespace lidarshop
