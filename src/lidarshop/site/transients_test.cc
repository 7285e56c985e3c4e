#include "lidarshop/site/transients.h"

#include <algorithm>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <opencv2/core.hpp>

#include "lidarshop/scanner/scanner.h"
#include "lidarshop/scanner/scene.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

// A street corner: ground, a facade, a low wall and two boxes that stay; what else stands there at one station
// only is passed in `extra` (objects with labels >= 10, the moving ones).
struct Station {
  double x, y, yaw_deg;
};

Scan ScanStation(const Station& s, const std::string& extra) {
  const std::string json = fmt::format(
      R"({{"scanner": {{"position": [{}, {}, 1.6], "rotate_deg": [0, 0, {}], "azimuth_deg": [-60, 60],
           "elevation_deg": [-30, 25], "columns": 420, "rows": 190, "max_range": 80,
           "los_noise_sigma": 0.004, "orthogonal_noise_sigma": 0.002, "seed": {}}},
          "objects": [
            {{"primitive": "plane", "size": [80, 80], "translate": [0, 20, 0], "label": 0, "texture": "gravel"}},
            {{"primitive": "box", "size": [30, 0.5, 8], "translate": [0, 18, 4], "label": 1, "color": [200, 190, 170]}},
            {{"primitive": "box", "size": [6, 0.3, 0.8], "translate": [-6, 12, 0.4], "label": 2}},
            {{"primitive": "box", "size": [1, 1, 1], "translate": [5, 9, 0.5], "label": 3, "color": [60, 90, 160]}},
            {{"primitive": "cylinder", "radius": 0.15, "height": 4, "translate": [-3, 7, 2], "label": 4}}{}]}})",
      s.x, s.y, s.yaw_deg, static_cast<int>(100 + s.x * 10 + s.y), extra);
  return SynthesizeScan(ParseScene(json, "site test scene", "."));
}

const std::vector<Station> kStations = {{0, 0, 0}, {4, 1, -15}, {-4, 2, 15}};

// Moving things: a person-like stack at station 0, a car at station 1 only, a person who walked from one place
// (station 2) to another (station 0).
std::string MovingAt(size_t station) {
  std::string extra;
  if (station == 0) {
    extra +=
        R"(, {"primitive": "cylinder", "radius": 0.25, "height": 1.75, "translate": [1, 8, 0.875], "label": 10})";
    extra += R"(, {"primitive": "box", "size": [0.5, 0.4, 1.7], "translate": [-1.5, 10, 0.85], "label": 12})";
  }
  if (station == 1)
    extra +=
        R"(, {"primitive": "car", "style": "sedan", "rotate_deg": [0, 0, 90], "translate": [-1, 13, 0], "label": 11})";
  if (station == 2)
    extra += R"(, {"primitive": "box", "size": [0.5, 0.4, 1.7], "translate": [2.5, 11, 0.85], "label": 12})";
  return extra;
}

struct Scores {
  int64_t true_positive = 0, false_positive = 0, false_negative = 0;
  double precision() const { return true_positive / std::max(1.0, double(true_positive + false_positive)); }
  double recall() const { return true_positive / std::max(1.0, double(true_positive + false_negative)); }
};

// Moving points (label >= 10) against the transient mask.
void Score(const Scan& scan, const cv::Mat& transient, Scores* scores) {
  for (int r = 0; r < scan.rows; ++r) {
    for (int c = 0; c < scan.cols; ++c) {
      if (scan.valid.at<uint8_t>(r, c) == 0) continue;
      const bool moving = scan.label.at<int32_t>(r, c) >= 10, found = transient.at<uint8_t>(r, c) != 0;
      scores->true_positive += moving && found;
      scores->false_positive += !moving && found;
      scores->false_negative += moving && !found;
    }
  }
}

TEST(FindTransients, NothingMovedNothingIsRemoved) {
  std::vector<Scan> stations;
  for (const Station& s : kStations) stations.push_back(ScanStation(s, ""));
  const TransientResult result = FindTransients(stations);
  ASSERT_EQ(result.stations.size(), 3u);
  for (size_t i = 0; i < stations.size(); ++i) {
    EXPECT_EQ(result.stations[i].transient_cells, 0) << "station " << i;
    // The stations overlap: most points are confirmed by another station.
    EXPECT_GT(result.stations[i].confirmed_cells, stations[i].CountValid() / 3) << "station " << i;
  }
}

TEST(FindTransients, FindsWhatMovedBetweenStations) {
  std::vector<Scan> stations;
  for (size_t i = 0; i < kStations.size(); ++i) stations.push_back(ScanStation(kStations[i], MovingAt(i)));
  const TransientResult result = FindTransients(stations);
  Scores all;
  for (size_t i = 0; i < stations.size(); ++i) {
    Scores one;
    Score(stations[i], result.stations[i].transient, &one);
    EXPECT_GT(one.true_positive, 200) << "station " << i;
    EXPECT_GE(one.precision(), 0.97) << "station " << i;
    all.true_positive += one.true_positive, all.false_positive += one.false_positive,
        all.false_negative += one.false_negative;
    // Every transient cell says which station saw through it.
    EXPECT_EQ(cv::countNonZero(result.stations[i].seen_through_by), result.stations[i].transient_cells);
  }
  EXPECT_GE(all.precision(), 0.97);
  EXPECT_GE(all.recall(), 0.95);
}

// Sites not tuned on: three stations and one to five people or boxes that each stand at one station only, at
// places and sizes drawn from the seed. The distribution of precision and recall over the seeds is printed.
TEST(FindTransients, HoldsOnRandomSites) {
  Scores all;
  double worst_precision = 1, worst_recall = 1;
  for (uint32_t seed = 1; seed <= 10; ++seed) {
    std::mt19937 random(seed);
    auto uniform = [&](double lo, double hi) {
      return std::uniform_real_distribution<double>(lo, hi)(random);
    };
    std::vector<Station> stations;
    for (int i = 0; i < 3; ++i) stations.push_back({uniform(-5, 5), uniform(-1, 3), uniform(-20, 20)});
    std::vector<std::string> extra(3);
    const int movers = 1 + static_cast<int>(random() % 5);
    std::vector<Eigen::Vector2d> places;  // at least 2 m apart: one object where another stood did not move
    for (int m = 0; m < movers; ++m) {
      const size_t at = random() % 3;
      const double height = uniform(1.0, 1.9);
      Eigen::Vector2d place;
      do place = Eigen::Vector2d(uniform(-6, 6), uniform(6, 15));
      while (std::any_of(places.begin(), places.end(),
                         [&](const Eigen::Vector2d& p) { return (p - place).norm() < 2; }));
      places.push_back(place);
      extra[at] += fmt::format(
          R"(, {{"primitive": "box", "size": [{:.2f}, {:.2f}, {:.2f}], "translate": [{:.2f}, {:.2f}, {:.3f}],
               "label": {}}})",
          uniform(0.4, 1.2), uniform(0.3, 0.8), height, place.x(), place.y(), height / 2, 10 + m);
    }
    std::vector<Scan> scans;
    for (int i = 0; i < 3; ++i) scans.push_back(ScanStation(stations[i], extra[i]));
    const TransientResult result = FindTransients(scans);
    Scores site;
    for (int i = 0; i < 3; ++i) Score(scans[i], result.stations[i].transient, &site);
    std::printf("site %u: %d moving, precision %.4f, recall %.4f (%lld moving points)\n", seed, movers,
                site.precision(), site.recall(),
                static_cast<long long>(site.true_positive + site.false_negative));
    worst_precision = std::min(worst_precision, site.precision());
    worst_recall = std::min(worst_recall, site.recall());
    all.true_positive += site.true_positive, all.false_positive += site.false_positive,
        all.false_negative += site.false_negative;
  }
  std::printf("all sites: precision %.4f, recall %.4f; worst site: precision %.4f, recall %.4f\n",
              all.precision(), all.recall(), worst_precision, worst_recall);
  EXPECT_GE(all.precision(), 0.97);
  EXPECT_GE(all.recall(), 0.95);
}

TEST(FindTransients, TheSameOnOneThreadAndOnTwo) {
  std::vector<Scan> stations;
  for (size_t i = 0; i < kStations.size(); ++i) stations.push_back(ScanStation(kStations[i], MovingAt(i)));
  TransientResult one, two;
  {
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 1);
    one = FindTransients(stations);
  }
  {
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 2);
    two = FindTransients(stations);
  }
  for (size_t i = 0; i < stations.size(); ++i) {
    EXPECT_EQ(cv::countNonZero(one.stations[i].transient != two.stations[i].transient), 0);
    EXPECT_EQ(cv::countNonZero(one.stations[i].seen_through_by != two.stations[i].seen_through_by), 0);
  }
}

TEST(CleanStations, RemovesTheMovingPointsAndFillsTheirHoles) {
  std::vector<Scan> stations;
  for (size_t i = 0; i < kStations.size(); ++i) stations.push_back(ScanStation(kStations[i], MovingAt(i)));
  std::vector<Scan> before;
  for (const Scan& scan : stations) before.push_back(Clone(scan));
  const CleanResult result = CleanStations(stations);
  ASSERT_EQ(result.stations.size(), 3u);
  for (size_t i = 0; i < stations.size(); ++i) {
    const Scan& cleaned = result.stations[i];
    int64_t moving_left = 0, moving_before = 0;
    for (int r = 0; r < cleaned.rows; ++r) {
      for (int c = 0; c < cleaned.cols; ++c) {
        const bool moving =
            stations[i].valid.at<uint8_t>(r, c) != 0 && stations[i].label.at<int32_t>(r, c) >= 10;
        moving_before += moving;
        // A moving point left as it was: a measured return of this station, neither synthesized nor taken
        // from another station.
        moving_left += moving && cleaned.valid.at<uint8_t>(r, c) != 0 &&
                       cleaned.synthesized.at<uint8_t>(r, c) == 0 &&
                       cleaned.from_station.at<uint8_t>(r, c) == 0;
        // A cell another station filled names that station, never this one, and is not synthesized.
        const uint8_t from = cleaned.from_station.at<uint8_t>(r, c);
        EXPECT_TRUE(from == 0 ||
                    (from != i + 1 && from <= stations.size() && cleaned.synthesized.at<uint8_t>(r, c) == 0))
            << "station " << i << " cell " << r << ", " << c;
      }
    }
    EXPECT_LE(moving_left, moving_before / 20) << "station " << i;
    EXPECT_GT(result.filled_cells[i] + result.from_station_cells[i], moving_before / 2) << "station " << i;
    // Another station had seen behind what moved: real points first.
    EXPECT_GT(result.from_station_cells[i], result.filled_cells[i] / 3) << "station " << i;
    // The input is untouched.
    EXPECT_EQ(cv::countNonZero(stations[i].valid != before[i].valid), 0) << "station " << i;
    EXPECT_EQ(cv::norm(stations[i].range, before[i].range, cv::NORM_INF), 0.0) << "station " << i;
  }
}

TEST(FindTransients, NeedsTwoStationsWithGrids) {
  const Scan one = ScanStation(kStations[0], "");
  EXPECT_THROW(FindTransients({one}), InputError);
  TransientOptions bad;
  bad.min_region_cells = 0;
  EXPECT_THROW(FindTransients({one, one}, bad), OptionsError);
  // A station that is one row of points (an unorganized cloud as read from a file) has no grid to look into.
  const Scan cloud = MakeScan(1, 50);
  EXPECT_THROW(FindTransients({one, cloud}), InputError);
}

}  // namespace
}  // namespace lidarshop
