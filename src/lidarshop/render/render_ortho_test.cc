// Orthographic pictures of clouds (render_layout.h top / front / side, render.h channels): sizes from the
// extent, points drawn as squares with a depth test, --point-size, elevation, intensity in the file's units,
// ASPRS classes, the hillshade, and the checker only where no point is.
#include <cmath>
#include <set>

#include <gtest/gtest.h>

#include "lidarshop/io/io_test_util.h"
#include "lidarshop/io/las.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/render/render.h"
#include "lidarshop/render/render_layout.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/memory_budget.h"

namespace lidarshop {
namespace {

struct Point {
  double x, y, z;
  float intensity = 0.5f;
  int32_t label = 1;
};

// An unorganized 1 x N cloud of world points, its origin (world_from_scanner) at `origin`.
Scan CloudOf(const std::vector<Point>& points, const Eigen::Vector3d& origin = Eigen::Vector3d::Zero()) {
  Scan cloud = MakeScan(1, static_cast<int>(points.size()));
  cloud.world_from_scanner.topRightCorner<3, 1>() = origin;
  cloud.label = cv::Mat(1, cloud.cols, CV_32S, cv::Scalar(kNoLabel));
  for (int i = 0; i < cloud.cols; ++i) {
    const cv::Vec3f p(static_cast<float>(points[i].x - origin.x()),
                      static_cast<float>(points[i].y - origin.y()),
                      static_cast<float>(points[i].z - origin.z()));
    cloud.valid.at<uint8_t>(0, i) = kValid;
    cloud.point.at<cv::Vec3f>(0, i) = p;
    cloud.range.at<float>(0, i) = static_cast<float>(cv::norm(p));
    if (cv::norm(p) > 0) cloud.direction.at<cv::Vec3f>(0, i) = p / cv::norm(p);
    cloud.intensity.at<float>(0, i) = points[i].intensity;
    cloud.label.at<int32_t>(0, i) = points[i].label;
  }
  return cloud;
}

// An aerial-like sparse field 200 m x 100 m, a point every 2 m jittered by up to 0.5 m, with no point in the
// rectangle x in [60, 140), y in [30, 70) (a 80 m x 40 m hole); z rises 0.05 m per metre of x.
std::vector<Point> SparseFieldWithHole() {
  std::vector<Point> points;
  uint32_t state = 12345;
  auto jitter = [&] {
    state = state * 1664525u + 1013904223u;
    return (static_cast<double>(state >> 8) / (1 << 24) - 0.5);  // [-0.5, 0.5)
  };
  for (int i = 0; i <= 100; ++i) {
    for (int j = 0; j <= 50; ++j) {
      const double x = std::clamp(2.0 * i + jitter(), 0.0, 200.0),
                   y = std::clamp(2.0 * j + jitter(), 0.0, 100.0);
      if (x >= 60 && x < 140 && y >= 30 && y < 70) continue;
      points.push_back({x, y, 0.05 * x});
    }
  }
  return points;
}

PictureLayoutOptions View(PictureView view) {
  PictureLayoutOptions options;
  options.view = view;
  return options;
}

TEST(RenderOrthoTest, TopViewIsSizedFromTheExtentAndClosedBetweenPoints) {
  const std::vector<Point> points = SparseFieldWithHole();
  const Scan cloud = CloudOf(points);
  const PictureLayout layout = LayOutPicture(cloud, View(PictureView::kTop));
  // At least 1000 pixels on the longer side, the extent's 2:1 aspect, square pixels of 0.2 m.
  EXPECT_EQ(layout.picture_size.width, 1000);
  EXPECT_NEAR(static_cast<double>(layout.picture_size.width) / layout.picture_size.height, 2.0, 0.01);
  EXPECT_NEAR(layout.pixel_width, 0.2, 0.002);
  EXPECT_NEAR(layout.pixel_height, layout.pixel_width, 0.002);
  // Points 2 m = 10 pixels apart: automatic squares of about twice that.
  EXPECT_TRUE(layout.splat_automatic);
  EXPECT_GE(layout.splat_px, 15);
  EXPECT_LE(layout.splat_px, 30);

  // Every point's pixel is drawn, with that point or a neighbour nearer to the viewer (a higher one: z rises
  // with x) within a square of it (the window is the extent: its corner is x = 0, y = 100).
  const Scan& cells = layout.cells;
  auto pixel_of = [&](const Point& p) {
    return cv::Point(std::min(cells.cols - 1, static_cast<int>(p.x / layout.pixel_width)),
                     std::min(cells.rows - 1, static_cast<int>((100.0 - p.y) / layout.pixel_height)));
  };
  for (const Point& p : points) {
    const cv::Point at = pixel_of(p);
    ASSERT_TRUE(cells.valid.at<uint8_t>(at)) << p.x << ", " << p.y;
    const cv::Vec3f shown = cells.point.at<cv::Vec3f>(at);
    EXPECT_GE(shown[2], p.z - 1e-4);
    EXPECT_LE(std::hypot(shown[0] - p.x, shown[1] - p.y), layout.splat_px * layout.pixel_width);
  }
  EXPECT_GT(layout.points_kept, static_cast<int64_t>(points.size()) * 9 / 10);
  // Between the points the picture is closed: every pixel of the field away from the hole has a point.
  int64_t field = 0, covered = 0, hole = 0, hole_covered = 0;
  for (int row = 0; row < cells.rows; ++row) {
    for (int col = 0; col < cells.cols; ++col) {
      const double x = (col + 0.5) * layout.pixel_width, y = 100.0 - (row + 0.5) * layout.pixel_height;
      const bool valid = cells.valid.at<uint8_t>(row, col) != 0;
      const bool in_field = x > 2 && x < 198 && y > 2 && y < 98 && (x < 56 || x > 144 || y < 26 || y > 74);
      const bool far_in_hole = x > 66 && x < 134 && y > 36 && y < 64;  // > 6 m from every point
      field += in_field;
      covered += in_field && valid;
      hole += far_in_hole;
      hole_covered += far_in_hole && valid;
    }
  }
  EXPECT_EQ(covered, field);
  EXPECT_EQ(hole_covered, 0);
  EXPECT_GT(hole, 40000);
  // The picture: the checker where the hole is, elevation colours elsewhere.
  RenderOptions elevation;
  elevation.channel = RenderChannel::kElevation;
  const PictureResult picture = RenderPicture(cloud, elevation, View(PictureView::kTop));
  const cv::Point hole_centre(cells.cols / 2, cells.rows / 2);
  EXPECT_EQ(picture.image.at<cv::Vec3b>(hole_centre), NoReturnColor(hole_centre.y, hole_centre.x));
  const cv::Point field_pixel = pixel_of(points[5]);
  EXPECT_NE(picture.image.at<cv::Vec3b>(field_pixel), NoReturnColor(field_pixel.y, field_pixel.x));
}

TEST(RenderOrthoTest, GivenSizesAndPointSizeAreHonoured) {
  // Ten points 10 m apart on a line: with --point-size 5 each is a 5 x 5 square, nothing else is drawn.
  std::vector<Point> points;
  for (int i = 0; i < 10; ++i) points.push_back({10.0 * i, 5.0 * (i % 2), 0.0});
  PictureLayoutOptions options = View(PictureView::kTop);
  options.width_px = 800;
  options.point_size_px = 5;
  const PictureLayout layout = LayOutPicture(CloudOf(points), options);
  EXPECT_EQ(layout.picture_size.width, 800);
  EXPECT_NEAR(layout.picture_size.height, 800 * 5.0 / 90.0, 1.0);
  EXPECT_FALSE(layout.splat_automatic);
  EXPECT_EQ(layout.splat_px, 5);
  // The window is the points' extent: every square is cut to 3 rows by the top or bottom border, the first
  // and last also to 3 columns.
  EXPECT_EQ(layout.cells.CountValid(), 8 * 5 * 3 + 2 * 3 * 3);
  options.point_size_px = 1;
  EXPECT_EQ(LayOutPicture(CloudOf(points), options).cells.CountValid(), 10);
  // Without it the squares come from the spacing: far larger than one pixel.
  options.point_size_px = 0;
  EXPECT_GT(LayOutPicture(CloudOf(points), options).cells.CountValid(), 10 * 25);
  options.point_size_px = -1;
  EXPECT_THROW(LayOutPicture(CloudOf(points), options), OptionsError);
  // A size past the memory budget is refused before it is allocated.
  options.point_size_px = 0;
  options.width_px = options.height_px = 16384;
  const int64_t budget = MemoryBudgetBytes();
  SetMemoryBudgetBytes(int64_t{1} << 30);
  EXPECT_THROW(LayOutPicture(CloudOf(points), options), InputError);
  SetMemoryBudgetBytes(budget);
}

TEST(RenderOrthoTest, TheNearestPointToTheViewerWins) {
  // A ground grid (z = 0, intensity 0.1) with a roof over part of it (z = 5, intensity 0.9), 0.5 m apart
  // both, the roof's points between the ground's.
  std::vector<Point> points;
  for (int i = 0; i <= 40; ++i) {
    for (int j = 0; j <= 40; ++j) points.push_back({0.5 * i, 0.5 * j, 0.0, 0.1f});
  }
  for (int i = 0; i < 10; ++i) {
    for (int j = 0; j < 10; ++j) points.push_back({5.25 + 0.5 * i, 5.25 + 0.5 * j, 5.0, 0.9f});
  }
  const Scan cloud = CloudOf(points, Eigen::Vector3d(100, 200, 300));
  for (const int point_size : {0, 9}) {
    PictureLayoutOptions top = View(PictureView::kTop);
    top.width_px = 200;  // 0.1 m pixels: the points 5 pixels apart
    top.point_size_px = point_size;
    const PictureLayout layout = LayOutPicture(cloud, top);
    // Inside the roof (x, y in [6, 9]) every pixel shows a roof point, whatever was under it.
    int roof_pixels = 0;
    for (int row = 0; row < layout.cells.rows; ++row) {
      for (int col = 0; col < layout.cells.cols; ++col) {
        const double x = (col + 0.5) * layout.pixel_width, y = 20.0 - (row + 0.5) * layout.pixel_height;
        if (x < 6 || x > 9 || y < 6 || y > 9) continue;
        ++roof_pixels;
        ASSERT_TRUE(layout.cells.valid.at<uint8_t>(row, col));
        EXPECT_FLOAT_EQ(layout.cells.intensity.at<float>(row, col), 0.9f) << "point size " << point_size;
      }
    }
    EXPECT_GT(roof_pixels, 100);
  }
  // From the side (looking along -x) the ground's points with the largest x (20 m) hide the others; from the
  // front (along +y) those with the smallest y (0 m). The cloud's origin (100, 200, 300) moves nothing.
  const PictureLayout side = LayOutPicture(cloud, View(PictureView::kSide));
  const PictureLayout front = LayOutPicture(cloud, View(PictureView::kFront));
  EXPECT_EQ(side.view, PictureView::kSide);
  const int ground_row = side.cells.rows - 1;  // z = 0 is the bottom row
  for (int col = 0; col < side.cells.cols; col += 7) {
    ASSERT_TRUE(side.cells.valid.at<uint8_t>(ground_row, col));
    EXPECT_NEAR(WorldPointOfCell(side.cells, ground_row, col).x(), 20.0, 1e-4);
  }
  for (int col = 0; col < front.cells.cols; col += 7) {
    ASSERT_TRUE(front.cells.valid.at<uint8_t>(front.cells.rows - 1, col));
    EXPECT_NEAR(WorldPointOfCell(front.cells, front.cells.rows - 1, col).y(), 0.0, 1e-4);
  }
  EXPECT_EQ(TowardViewer(PictureView::kSide), Eigen::Vector3d::UnitX());
  EXPECT_EQ(TowardViewer(PictureView::kGrid), Eigen::Vector3d::Zero());
}

TEST(RenderOrthoTest, ElevationLegendSpansTheCloudsZInMetres) {
  std::vector<Point> points;
  for (int i = 0; i <= 100; ++i) {
    for (int j = 0; j <= 20; ++j) points.push_back({0.5 * i, 0.5 * j, 400.0 + 0.1 * i});  // 400 to 410 m
  }
  const Scan cloud = CloudOf(points, Eigen::Vector3d(5e5, 5e6, 405));
  RenderOptions options;
  options.channel = RenderChannel::kElevation;
  options.legend = true;
  const PictureResult picture = RenderPicture(cloud, options, View(PictureView::kTop));
  ASSERT_TRUE(picture.scale.has_value());
  EXPECT_EQ(picture.scale->unit, "m");
  EXPECT_NEAR(picture.scale->min_value, 400.0, 0.2);  // the 1-99 % quantiles
  EXPECT_NEAR(picture.scale->max_value, 410.0, 0.2);
  EXPECT_GT(picture.image.cols, picture.layout.picture_size.width + 80);  // the scale bar
  // Low on the left, high on the right, in viridis.
  const int row = picture.layout.picture_size.height / 2;
  EXPECT_EQ(picture.image.at<cv::Vec3b>(row, 2), ColorMapTable(ColorMap::kViridis).front());
  EXPECT_EQ(picture.image.at<cv::Vec3b>(row, picture.layout.picture_size.width - 3),
            ColorMapTable(ColorMap::kViridis).back());
  // The float picture holds the elevations themselves.
  const ValuesResult values = RenderValues(cloud, RenderChannel::kElevation, View(PictureView::kTop));
  EXPECT_NEAR(values.values.at<float>(row, 2), 400.0, 0.15);  // (or its higher neighbour, 0.1 m up)
}

TEST(RenderOrthoTest, LasIntensityAndClassesInTheFilesTerms) {
  // A LAS file with 16-bit intensities 1000-3000 and classes ground (2) and building (6).
  std::vector<Point> points;
  for (int i = 0; i < 40; ++i) {
    for (int j = 0; j < 20; ++j) {
      points.push_back(
          {1.0 * i, 1.0 * j, i < 20 ? 100.0 : 110.0, (1000.0f + 50.0f * i) / 65535.0f, i < 20 ? 2 : 6});
    }
  }
  testing_io::TempFolder folder;
  WriteScanFile(folder.File("field.las"), {CloudOf(points, Eigen::Vector3d(20, 10, 100))});
  const Scan las = ReadScanFile(folder.File("field.las")).scans.at(0);
  EXPECT_EQ(IntensityFileRange(las), (std::pair{0.0, 65535.0}));
  EXPECT_TRUE(HoldsAsprsClasses(las));

  RenderOptions intensity;
  intensity.channel = RenderChannel::kIntensity;
  intensity.legend = true;
  const PictureResult by_intensity = RenderPicture(las, intensity, View(PictureView::kTop));
  ASSERT_TRUE(by_intensity.scale.has_value());
  EXPECT_NEAR(by_intensity.scale->min_value, 1000.0, 60.0);  // the 1 % quantile, in the file's units
  EXPECT_NEAR(by_intensity.scale->max_value, 2950.0, 60.0);

  // The labels of a LAS file are its classes: ASPRS names and colours, whichever of the two channels.
  for (const RenderChannel channel : {RenderChannel::kLabels, RenderChannel::kClassification}) {
    RenderOptions classes;
    classes.channel = channel;
    classes.legend = true;
    const PictureResult by_class = RenderPicture(las, classes, View(PictureView::kTop));
    EXPECT_EQ(by_class.legend_lines, (std::vector<std::string>{"2  ground", "6  building"}));
    const cv::Size size = by_class.layout.picture_size;
    EXPECT_EQ(by_class.image.at<cv::Vec3b>(size.height / 2, 3), AsprsClassColor(2));
    EXPECT_EQ(by_class.image.at<cv::Vec3b>(size.height / 2, size.width - 4), AsprsClassColor(6));
    EXPECT_GT(by_class.image.cols, size.width + 80);  // the swatches
  }
  EXPECT_EQ(AsprsClassName(5), "high vegetation");
  EXPECT_EQ(AsprsClassName(9), "water");
  EXPECT_EQ(AsprsClassName(77), "class 77");

  // A cloud that is not from LAS: intensity as stored, labels as object labels unless asked for classes.
  const Scan plain = CloudOf(points);
  EXPECT_EQ(IntensityFileRange(plain), (std::pair{0.0, 1.0}));
  const PictureResult stored = RenderPicture(plain, intensity, View(PictureView::kTop));
  EXPECT_LT(stored.scale->max_value, 0.1);
  RenderOptions labels;
  labels.channel = RenderChannel::kLabels;
  EXPECT_EQ(RenderPicture(plain, labels, View(PictureView::kTop)).legend_lines,
            (std::vector<std::string>{"label 2", "label 6"}));
  labels.channel = RenderChannel::kClassification;
  EXPECT_EQ(RenderPicture(plain, labels, View(PictureView::kTop)).legend_lines,
            (std::vector<std::string>{"2  ground", "6  building"}));
}

TEST(RenderOrthoTest, RealLasFileGivesAClosedPictureWithItsOwnScales) {
  const Scan autzen = ReadScanFile(LIDARSHOP_SHARED_DATA_DIR "/interop/las/autzen-thin.las").scans.at(0);
  RenderOptions intensity;
  intensity.channel = RenderChannel::kIntensity;
  const PictureResult picture = RenderPicture(autzen, intensity, View(PictureView::kTop));
  EXPECT_GE(std::max(picture.image.cols, picture.image.rows), 1000);
  EXPECT_GT(picture.scale->max_value, 50.0);  // 16-bit units (Autzen's are below 256), not 0.003
  // Most of the picture shows points (sparse 10,653 points over 3.4 km x 4.6 km).
  EXPECT_GT(picture.layout.cells.CountValid(), picture.layout.cells.num_cells() / 2);

  // An E57 with integer intensities and limits -66..66: its values, not the [0, 1] they are kept as.
  const Scan e57 = ReadScanFile(LIDARSHOP_SHARED_DATA_DIR "/e57/integer_intensity.e57").scans.at(0);
  EXPECT_EQ(IntensityFileRange(e57), (std::pair{-66.0, 66.0}));
  const PictureResult e57_picture = RenderPicture(e57, intensity, View(PictureView::kTop));
  for (const double value : {e57_picture.scale->min_value, e57_picture.scale->max_value}) {
    EXPECT_GE(value, -66.0);
    EXPECT_LE(value, 66.0);
  }
  EXPECT_TRUE(e57_picture.scale->min_value < 0.0 || e57_picture.scale->max_value > 1.0);
}

TEST(RenderOrthoTest, HillshadeLightsSlopesFacingNorthWest) {
  // A ridge along y: the west slope (x < 10) faces west, the east slope east; a flat strip beyond x = 20.
  std::vector<Point> points;
  for (int i = 0; i <= 120; ++i) {
    for (int j = 0; j <= 40; ++j) {
      const double x = 0.25 * i;
      points.push_back({x, 0.25 * j, x < 10 ? x : x < 20 ? 20 - x : 0.0});
    }
  }
  const Scan cloud = CloudOf(points);
  RenderOptions plain;
  plain.channel = RenderChannel::kIntensity;  // one grey everywhere
  plain.min_value = 0.0;
  plain.max_value = 1.0;
  RenderOptions shaded = plain;
  shaded.hillshade = true;
  const PictureResult flat = RenderPicture(cloud, plain, View(PictureView::kTop));
  const PictureResult lit = RenderPicture(cloud, shaded, View(PictureView::kTop));
  const int row = flat.image.rows / 2;
  auto grey = [&](const cv::Mat& image, double x) {
    return image.at<cv::Vec3b>(row, static_cast<int>(x / lit.layout.pixel_width))[0];
  };
  EXPECT_GT(grey(lit.image, 5), grey(lit.image, 15) + 40);    // west-facing lit, east-facing in shade
  EXPECT_NEAR(grey(lit.image, 25), grey(flat.image, 25), 2);  // flat ground keeps its colour
  EXPECT_THROW(RenderPicture(cloud, shaded, PictureLayoutOptions{}), OptionsError);  // not orthographic

  // The same slopes give the normals of a cloud without them: up and west (-x) on the west slope, up on the
  // flat strip, as (n + 1) / 2 in the scanner frame.
  RenderOptions normals;
  normals.channel = RenderChannel::kNormals;
  const PictureResult by_normal = RenderPicture(cloud, normals, View(PictureView::kTop));
  auto color_at = [&](double x) {
    return by_normal.image.at<cv::Vec3b>(row, static_cast<int>(x / by_normal.layout.pixel_width));
  };
  const double half = 127.5 * (1 - std::sqrt(0.5)), up = 127.5 * (1 + std::sqrt(0.5));  // n = (-1, 0, 1) / √2
  EXPECT_NEAR(color_at(5)[0], half, 3);
  EXPECT_NEAR(color_at(5)[1], 127.5, 3);
  EXPECT_NEAR(color_at(5)[2], up, 3);
  EXPECT_NEAR(color_at(15)[0], up, 3);
  EXPECT_NEAR(color_at(25)[2], 255, 2);
}

}  // namespace
}  // namespace lidarshop
