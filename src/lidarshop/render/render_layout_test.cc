#include "lidarshop/render/render_layout.h"

#include <cmath>

#include <gtest/gtest.h>

#include "lidarshop/io/image_io.h"
#include "lidarshop/io/io_test_util.h"
#include "lidarshop/render/render.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

using testing_io::TempFolder;

constexpr double kDeg = M_PI / 180.0;

// An organized scan of a wall 5 m ahead with pumpA's steps: 0.250° across, 0.0675° down, `cols` x `rows`
// rays, the range growing to the right; the ray at (1, 2) does not return.
Scan PumpLikeScan(int rows = 30, int cols = 40) {
  Scan scan = MakeScan(rows, cols);
  const double azimuth_step = 0.25 * kDeg, elevation_step = 0.0675 * kDeg;
  scan.grid = UniformGrid(rows, cols, -0.5 * (cols - 1) * azimuth_step, 0.5 * (cols - 1) * azimuth_step,
                          -0.5 * (rows - 1) * elevation_step, 0.5 * (rows - 1) * elevation_step);
  scan.direction = DirectionsFromGrid(scan.grid);
  for (int row = 0; row < rows; ++row) {
    for (int col = 0; col < cols; ++col) {
      if (row == 1 && col == 2) continue;
      const float range = 5.0f + 0.01f * col;
      scan.valid.at<uint8_t>(row, col) = kValid;
      scan.range.at<float>(row, col) = range;
      scan.point.at<cv::Vec3f>(row, col) = scan.direction.at<cv::Vec3f>(row, col) * range;
      scan.intensity.at<float>(row, col) = 0.2f + 0.2f * row / rows;
    }
  }
  return scan;
}

// An unorganized 1 x N cloud of points at the given (azimuth, elevation) in degrees and ranges.
Scan Cloud(const std::vector<cv::Vec3d>& azimuth_elevation_range) {
  Scan scan = MakeScan(1, static_cast<int>(azimuth_elevation_range.size()));
  for (int i = 0; i < scan.cols; ++i) {
    const cv::Vec3d& a = azimuth_elevation_range[i];
    const Eigen::Vector3f p = DirectionFromAngles(a[0] * kDeg, a[1] * kDeg) * static_cast<float>(a[2]);
    scan.valid.at<uint8_t>(0, i) = kValid;
    scan.point.at<cv::Vec3f>(0, i) = cv::Vec3f(p.x(), p.y(), p.z());
    scan.range.at<float>(0, i) = static_cast<float>(a[2]);
    scan.direction.at<cv::Vec3f>(0, i) = cv::Vec3f(p.x(), p.y(), p.z()) / static_cast<float>(a[2]);
    scan.intensity.at<float>(0, i) = 0.5f;
  }
  return scan;
}

TEST(RenderLayoutTest, SquareAngularPixelsByDefaultNativeOnRequest) {
  const Scan scan = PumpLikeScan();
  const cv::Vec2d steps = NativeStepsRad(scan);
  EXPECT_NEAR(steps[0] / kDeg, 0.25, 1e-9);
  EXPECT_NEAR(steps[1] / kDeg, 0.0675, 1e-9);

  // Square: the finer step is the pixel, so 40 columns of 0.25° become 148 pixels of 0.0675°.
  const PictureResult square = RenderPicture(scan, RenderOptions{}, PictureLayoutOptions{});
  EXPECT_EQ(square.image.rows, 30);
  EXPECT_EQ(square.image.cols, 148);
  EXPECT_NEAR(square.layout.pixel_width, square.layout.pixel_height, 0.001);
  // The picture's aspect is the scan's angular aspect (10° x 2.025°), not 40 x 30.
  EXPECT_NEAR(static_cast<double>(square.image.cols) / square.image.rows, 10.0 / 2.025, 0.02);

  PictureLayoutOptions native;
  native.aspect = PixelAspect::kNative;
  const PictureResult one_per_ray = RenderPicture(scan, RenderOptions{}, native);
  EXPECT_EQ(one_per_ray.image.size(), cv::Size(40, 30));
  EXPECT_EQ(one_per_ray.image.at<cv::Vec3b>(5, 7),
            RenderScan(scan, RenderOptions{}).image.at<cv::Vec3b>(5, 7));

  // One size given: the other keeps the square aspect; both: exactly that size.
  PictureLayoutOptions sized;
  sized.width_px = 296;
  EXPECT_EQ(LayOutPicture(scan, sized).picture_size, cv::Size(296, 60));
  sized.width_px = 0;
  sized.height_px = 15;
  EXPECT_EQ(LayOutPicture(scan, sized).picture_size, cv::Size(74, 15));
  sized.width_px = 50;
  EXPECT_EQ(RenderPicture(scan, RenderOptions{}, sized).image.size(), cv::Size(50, 15));
  // Automatic sizes stay within max_side_px.
  PictureLayoutOptions capped;
  capped.max_side_px = 74;
  EXPECT_EQ(LayOutPicture(scan, capped).picture_size, cv::Size(74, 15));
}

TEST(RenderLayoutTest, UnorganizedCloudIsProjectedOntoASphericalGrid) {
  // A 20° x 10° patch of points 4 m away, 0.25° apart.
  std::vector<cv::Vec3d> points;
  for (int i = 0; i <= 80; ++i) {
    for (int j = 0; j <= 40; ++j) points.push_back({-10.0 + 0.25 * i, -5.0 + 0.25 * j, 4.0});
  }
  const Scan cloud = Cloud(points);
  ASSERT_TRUE(IsUnorganized(cloud));
  EXPECT_FALSE(IsUnorganized(PumpLikeScan()));
  RenderOptions range;
  range.min_value = 3.0;
  range.max_value = 5.0;
  const PictureResult picture = RenderPicture(cloud, range, PictureLayoutOptions{});
  EXPECT_EQ(picture.layout.view, PictureView::kSphere);
  EXPECT_GT(picture.image.rows, 10);  // not 1 x N any more
  EXPECT_GT(picture.image.cols, 20);
  // Square angular cells over a 20° x 10° box, about three points a cell, none of them empty.
  EXPECT_NEAR(picture.layout.pixel_width, picture.layout.pixel_height, 0.1 * picture.layout.pixel_width);
  EXPECT_NEAR(static_cast<double>(picture.image.cols) / picture.image.rows, 2.0, 0.2);
  EXPECT_NEAR(static_cast<double>(picture.image.total()), points.size() / 3.0, points.size() * 0.05);
  EXPECT_EQ(picture.layout.points, static_cast<int64_t>(points.size()));
  EXPECT_EQ(picture.layout.points_kept, static_cast<int64_t>(picture.image.total()));
  EXPECT_NE(picture.layout.Describe().find("spherical grid"), std::string::npos);

  // Orientation: a near point (3 m) at the top right shows at the top right, in the colour of 3 m.
  points.push_back({9.9, 4.9, 3.0});
  const PictureResult with_near = RenderPicture(Cloud(points), range, PictureLayoutOptions{});
  const cv::Vec3b near_color = ColorMapTable(ColorMap::kViridis).front();
  EXPECT_EQ(with_near.image.at<cv::Vec3b>(0, with_near.image.cols - 1), near_color);
  EXPECT_NE(with_near.image.at<cv::Vec3b>(with_near.image.rows - 1, 0), near_color);
  EXPECT_EQ(with_near.layout.points - with_near.layout.points_kept,
            static_cast<int64_t>(points.size()) - with_near.layout.cells.CountValid());
}

TEST(RenderLayoutTest, SphereStartsAfterTheWidestEmptySector) {
  // Points behind the scanner, from 170° to -170° through 180°: 20° wide, not 340°.
  std::vector<cv::Vec3d> points;
  for (int i = 0; i <= 20; ++i) {
    for (int j = 0; j <= 10; ++j)
      points.push_back({170.0 + i > 180.0 ? 170.0 + i - 360.0 : 170.0 + i, static_cast<double>(j), 4.0});
  }
  PictureLayoutOptions options;
  options.width_px = 40;
  const PictureLayout layout = LayOutPicture(Cloud(points), options);
  EXPECT_NEAR(layout.pixel_width * 40, 20.0, 0.01);
  EXPECT_EQ(layout.picture_size, cv::Size(40, 20));
  EXPECT_GE(layout.cells.CountValid(), 21 * 11 - 5);  // 1° apart in 0.5° cells
}

TEST(RenderLayoutTest, OrthographicTopAndFrontViews) {
  // A flat square 4 m x 2 m on the ground (z = 0), a 1 m post at (1, 1) (20 points: 2 %) and a stray point
  // 50 m away: from above the post's top hides the ground under it, the stray point is left out.
  Scan cloud = MakeScan(1, 41 * 21 + 21);
  int i = 0;
  auto add = [&](float x, float y, float z, float intensity) {
    cloud.valid.at<uint8_t>(0, i) = kValid;
    cloud.point.at<cv::Vec3f>(0, i) = cv::Vec3f(x, y, z);
    cloud.range.at<float>(0, i) = static_cast<float>(cv::norm(cv::Vec3f(x, y, z)));
    cloud.intensity.at<float>(0, i) = intensity;
    ++i;
  };
  for (int a = 0; a < 41; ++a) {
    for (int b = 0; b < 21; ++b) {
      add(-2.0f + 0.1f * a, 0.1f * b, 0.0f, 0.1f);
    }
  }
  for (int k = 1; k <= 20; ++k) add(1.0f, 1.0f, 0.05f * k, 0.9f);
  add(50.0f, 1.0f, 0.0f, 0.1f);
  cloud.world_from_scanner(2, 3) = 1.5;  // the scanner 1.5 m up: world z = 1.5 + scanner z

  PictureLayoutOptions top;
  top.view = PictureView::kTop;
  top.width_px = 41;
  top.height_px = 21;
  const PictureLayout layout = LayOutPicture(cloud, top);
  EXPECT_EQ(layout.pixel_unit, "m");
  EXPECT_EQ(layout.picture_size, cv::Size(41, 21));
  // The window: x from -2 m to the 99.5 % quantile (2 m) plus a quarter of the span, 3 m, not 50 m: the stray
  // point is left out.
  EXPECT_NEAR(layout.pixel_width * 41, 5.0, 1e-6);
  EXPECT_EQ(layout.points, 41 * 21 + 21);
  // World x = 1 m is column 24 (3 m of 5 m), world y = 1 m is row 10 (y up); the post's top is kept there.
  EXPECT_FLOAT_EQ(layout.cells.point.at<cv::Vec3f>(10, 24)[2], 1.0f);
  EXPECT_FLOAT_EQ(layout.cells.intensity.at<float>(10, 24), 0.9f);

  PictureLayoutOptions front = top;
  front.view = PictureView::kFront;
  const PictureLayout front_layout = LayOutPicture(cloud, front);
  EXPECT_EQ(front_layout.picture_size.width, 41);
  // From the front the post stands 1 m above the ground line (z from 1.5 to 2.5 in the world).
  EXPECT_NEAR(front_layout.pixel_height * front_layout.picture_size.height, 1.0, 0.05);

  const Scan nothing = MakeScan(1, 5);
  EXPECT_THROW(LayOutPicture(nothing, top), InputError);
  PictureLayoutOptions bad;
  bad.width_px = -3;
  EXPECT_THROW(LayOutPicture(cloud, bad), OptionsError);
}

TEST(RenderLayoutTest, FloatPicturesRoundTripThroughExrAndTiff) {
  const Scan scan = PumpLikeScan();
  PictureLayoutOptions native;
  native.aspect = PixelAspect::kNative;
  const ValuesResult range = RenderValues(scan, RenderChannel::kRange, native);
  ASSERT_EQ(range.values.type(), CV_32F);
  ASSERT_EQ(range.values.size(), cv::Size(40, 30));
  EXPECT_TRUE(std::isnan(range.values.at<float>(1, 2)));
  EXPECT_EQ(range.values.at<float>(3, 4), scan.range.at<float>(3, 4));
  TempFolder folder;
  for (const std::string name : {"range.exr", "range.tif"}) {
    WriteImage(folder.File(name), range.values);
    const cv::Mat back = ReadImage(folder.File(name));
    ASSERT_EQ(back.type(), CV_32F) << name;
    ASSERT_EQ(back.size(), range.values.size()) << name;
    for (int row = 0; row < back.rows; ++row) {
      for (int col = 0; col < back.cols; ++col) {
        const float expected = range.values.at<float>(row, col), got = back.at<float>(row, col);
        if (std::isnan(expected)) {
          EXPECT_TRUE(std::isnan(got)) << name << " at " << row << "," << col;
        } else {
          EXPECT_EQ(got, expected) << name << " at " << row << "," << col;
        }
      }
    }
  }
  // Square pixels repeat values, never mix them.
  const ValuesResult square = RenderValues(scan, RenderChannel::kRange, PictureLayoutOptions{});
  EXPECT_EQ(square.values.cols, 148);
  EXPECT_EQ(square.values.at<float>(10, 147), scan.range.at<float>(10, 39));
  EXPECT_EQ(RenderValues(scan, RenderChannel::kNormals, native).values.type(), CV_32FC3);
  EXPECT_THROW(ChannelValues(scan, RenderChannel::kRgb), OptionsError);
}

// Distance in RGB between two colours.
double ColorDistance(const cv::Vec3b& a, const cv::Vec3b& b) {
  return cv::norm(cv::Vec3d(a[0], a[1], a[2]) - cv::Vec3d(b[0], b[1], b[2]));
}

TEST(RenderLayoutTest, NoReturnIsAQuietGreyChecker) {
  // Two neutral greys, a light and a mid one, far enough apart to read as a pattern; squares of 8 pixels.
  for (const cv::Vec3b& no_return : {kNoReturnColorA, kNoReturnColorB}) {
    EXPECT_EQ(no_return[0], no_return[1]);
    EXPECT_EQ(no_return[1], no_return[2]);
    EXPECT_GE(no_return[0], 140);
    EXPECT_LE(no_return[0], 220);
  }
  EXPECT_GE(ColorDistance(kNoReturnColorA, kNoReturnColorB), 60.0);
  EXPECT_EQ(NoReturnColor(0, 0), NoReturnColor(7, 7));
  EXPECT_NE(NoReturnColor(0, 0), NoReturnColor(0, 8));
  EXPECT_NE(NoReturnColor(0, 0), NoReturnColor(8, 0));
  EXPECT_EQ(NoReturnColor(0, 0), NoReturnColor(8, 8));
  // In a picture: the ray without a return gets the checker, every other pixel a colour of the map.
  const Scan scan = PumpLikeScan();
  RenderOptions options;
  options.channel = RenderChannel::kIntensity;
  const cv::Mat image = RenderScan(scan, options).image;
  EXPECT_EQ(image.at<cv::Vec3b>(1, 2), NoReturnColor(1, 2));
  EXPECT_EQ(image.at<cv::Vec3b>(1, 3)[0], image.at<cv::Vec3b>(1, 3)[1]);  // grey
  options.channel = RenderChannel::kRange;
  const cv::Mat range = RenderScan(scan, options).image;
  for (int row = 0; row < range.rows; ++row) {
    for (int col = 0; col < range.cols; ++col) {
      if (row == 1 && col == 2) continue;
      EXPECT_GE(ColorDistance(range.at<cv::Vec3b>(row, col), NoReturnColor(row, col)), 30.0);
    }
  }
}

TEST(RenderLayoutTest, IntensityIsScaledByQuantiles) {
  // Intensities from 0.2 to 0.4 span the whole grey map, not a fifth of it.
  const Scan scan = PumpLikeScan();
  RenderOptions options;
  options.channel = RenderChannel::kIntensity;
  const RenderResult result = RenderScan(scan, options);
  ASSERT_TRUE(result.scale.has_value());
  EXPECT_NEAR(result.scale->min_value, 0.2, 0.01);
  EXPECT_NEAR(result.scale->max_value, 0.4, 0.01);
  EXPECT_LT(result.image.at<cv::Vec3b>(0, 0)[0], 10);
  EXPECT_GT(result.image.at<cv::Vec3b>(29, 0)[0], 245);
}

TEST(RenderLayoutTest, LegendsNameObjectsAndShowTheNormalsKey) {
  Scan scan = PumpLikeScan();
  scan.label = cv::Mat(scan.rows, scan.cols, CV_32S, cv::Scalar(1));
  scan.label(cv::Rect(20, 0, 20, scan.rows)).setTo(4);
  RenderOptions options;
  options.channel = RenderChannel::kLabels;
  options.legend = true;
  PictureLayoutOptions native;
  native.aspect = PixelAspect::kNative;
  const cv::Mat numbers_only = RenderPicture(scan, options, native).image;
  options.label_names = {{1, "ground"}, {4, "a rather long object name"}};
  const cv::Mat named = RenderPicture(scan, options, native).image;
  EXPECT_GT(named.cols, numbers_only.cols);  // the legend widened for the names
  EXPECT_GT(numbers_only.cols, 40 + 100);    // a legend is there at all
  EXPECT_GT(cv::norm(LabelLegend({1, 4}, 50, options.label_names)(cv::Rect(28, 8, 60, 14)),
                     LabelLegend({1, 4}, 50)(cv::Rect(28, 8, 60, 14)), cv::NORM_L1),
            0.0);  // other words

  // The picture has a ray without a return: the legend shows the checker's key too.
  const cv::Mat legend = named(cv::Rect(40, 0, named.cols - 40, named.rows));
  int checker_pixels = 0;
  for (int row = 0; row < legend.rows; ++row) {
    for (int col = 0; col < legend.cols; ++col)
      checker_pixels += legend.at<cv::Vec3b>(row, col) == kNoReturnColorA;
  }
  EXPECT_GT(checker_pixels, 20);

  // The normals key: the centre faces the scanner (-y), the top points up (+z, blue), the right +x (red).
  const cv::Mat key = NormalsKey(120);
  const int radius = (120 - 30 - 8) / 2, centre_row = 4 + radius, centre_col = key.cols / 2;
  EXPECT_EQ(key.at<cv::Vec3b>(centre_row, centre_col), cv::Vec3b(128, 0, 128));
  EXPECT_GT(key.at<cv::Vec3b>(centre_row - radius + 2, centre_col)[2], 230);
  EXPECT_GT(key.at<cv::Vec3b>(centre_row, centre_col + radius - 2)[0], 230);
  options.channel = RenderChannel::kNormals;
  EXPECT_GT(RenderPicture(scan, options, native).image.cols, 40 + 80);
}

}  // namespace
}  // namespace lidarshop
