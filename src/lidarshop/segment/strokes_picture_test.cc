// Strokes and masks painted on the pictures `render` draws (render/picture_mapping.h) cut the same object as
// strokes on the scan's own grid.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "lidarshop/render/picture_mapping.h"
#include "lidarshop/render/render_layout.h"
#include "lidarshop/render/strokes.h"
#include "lidarshop/segment/segment.h"
#include "lidarshop/testing/scenes.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

// Ground and a box; 100 columns over ±30° and 200 rows over 45°: rays 0.61° apart across and 0.23° down, so
// render's square pixels make the picture 2.7 times wider than the grid.
Scan BoxScan() {
  test_scenes::GroundAndBoxOptions options;
  options.rows = 200;
  options.columns = 100;
  options.box_size = Eigen::Vector3d(1.6, 1.0, 1.4);
  options.box_center = Eigen::Vector3d(0.5, 8.0, 0.7);
  return test_scenes::ScanScene(test_scenes::MakeGroundAndBoxScene(options));
}

double IoU(const cv::Mat& a, const cv::Mat& b) {
  const double both = cv::countNonZero((a != 0) & (b != 0)), either = cv::countNonZero((a != 0) | (b != 0));
  return either > 0 ? both / either : 1.0;
}

cv::Rect CellsOfLabel(const Scan& scan, int32_t label) { return cv::boundingRect(scan.label == label); }

TEST(StrokesPicture, StrokeOnTheRenderPictureCutsTheSameObjectAsOnTheGrid) {
  const Scan scan = BoxScan();
  const PictureLayout layout = LayOutPicture(scan, {});
  const cv::Size picture = layout.picture_size;
  ASSERT_GT(picture.width, 2 * scan.cols);  // square pixels: much wider than the grid
  const double sx = static_cast<double>(picture.width) / scan.cols,
               sy = static_cast<double>(picture.height) / scan.rows;
  const cv::Rect box = CellsOfLabel(scan, 1);
  ASSERT_GT(box.area(), 100);
  // One object stroke across the box's middle and background strokes on the ground below it and the ground
  // left of it, in grid coordinates (cell centres) ...
  const cv::Point2d object_from(box.x + 0.25 * box.width, box.y + 0.5 * box.height),
      object_to(box.x + 0.75 * box.width, box.y + 0.6 * box.height);
  const cv::Point2d ground_from(box.x - 5.0, box.br().y + 8.0),
      ground_to(box.br().x + 5.0, box.br().y + 12.0);
  const cv::Point2d left_from(box.x - 12.0, box.y + 4.0), left_to(box.x - 10.0, box.br().y - 4.0);
  cv::Mat on_grid(scan.rows, scan.cols, CV_8U, cv::Scalar(kStrokeNone));
  cv::Mat painted(picture, CV_8UC3, cv::Scalar::all(0));
  auto draw = [&](cv::Point2d from, cv::Point2d to, uint8_t label) {
    cv::line(on_grid, cv::Point(cvRound(from.x), cvRound(from.y)), cv::Point(cvRound(to.x), cvRound(to.y)),
             cv::Scalar(label), 1);
    // ... and the same strokes 1 pixel thin on the picture, where the cells' centres are shown.
    auto at = [&](cv::Point2d cell) {
      return cv::Point(cvRound((cell.x + 0.5) * sx - 0.5), cvRound((cell.y + 0.5) * sy - 0.5));
    };
    const cv::Scalar colour = label == kStrokeObject ? cv::Scalar(0, 255, 0) : cv::Scalar(255, 0, 0);
    cv::line(painted, at(from), at(to), colour, 1);
  };
  draw(object_from, object_to, kStrokeObject);
  draw(ground_from, ground_to, kStrokeBackground);
  draw(left_from, left_to, kStrokeBackground);

  const PictureMapping mapping = MappingOfLayout(layout, scan);
  const cv::Mat mapped = CellsFromPicture(scan, mapping, StrokesFromImage(painted));
  // Every painted stroke lands on cells, without gaps along the strokes.
  EXPECT_GE(cv::countNonZero(mapped == kStrokeObject), cv::countNonZero(on_grid == kStrokeObject) - 2);
  EXPECT_GT(cv::countNonZero(mapped == kStrokeBackground), 0);
  const SegmentResult from_grid = SegmentSession(scan, SegmentOptions()).Run(on_grid);
  const SegmentResult from_picture = SegmentSession(scan, SegmentOptions()).Run(mapped);
  const cv::Mat truth = scan.label == 1;
  EXPECT_GT(IoU(from_grid.mask, truth), 0.95);
  EXPECT_GE(IoU(from_grid.mask, from_picture.mask), 0.99)
      << IoU(from_grid.mask, from_picture.mask) << " " << cv::countNonZero(from_grid.mask);
}

TEST(StrokesPicture, AMaskOnTheRenderPictureMapsToItsCells) {
  const Scan scan = BoxScan();
  const cv::Mat truth = scan.label == 1;
  // The mask as render draws it (nearest neighbour) at several widths, wider and narrower than the grid: back
  // on the grid it is the mask itself (wider) or within one picture pixel of it (narrower).
  for (const int width : {0, 377, 1000, 60}) {
    PictureLayoutOptions options;
    options.width_px = width;
    const PictureLayout layout = LayOutPicture(scan, options);
    const cv::Mat drawn = ResampleNearest(truth, layout.picture_size);
    const cv::Mat cells = CellsFromPicture(scan, MappingOfLayout(layout, scan), drawn);
    if (layout.picture_size.width >= scan.cols) {
      EXPECT_EQ(cv::countNonZero(cells != truth), 0) << "width " << layout.picture_size.width;
    } else {
      EXPECT_GT(IoU(cells, truth), 0.7) << "width " << layout.picture_size.width;
    }
  }
  // A rectangle painted on the picture: the cells whose centres it covers, and no cell farther than a pixel.
  const PictureLayout layout = LayOutPicture(scan, {});
  const double sx = static_cast<double>(layout.picture_size.width) / scan.cols;
  cv::Mat painted(layout.picture_size, CV_8U, cv::Scalar(0));
  const cv::Rect rect(101, 40, 57, 30);
  painted(rect).setTo(255);
  const cv::Mat cells = CellsFromPicture(scan, MappingOfLayout(layout, scan), painted);
  for (int col = 0; col < scan.cols; ++col) {
    const double centre_x = (col + 0.5) * sx;  // picture x of the cell's centre
    const bool inside = centre_x >= rect.x + 0.5 && centre_x <= rect.br().x - 0.5;
    const bool outside = centre_x + 0.5 * sx < rect.x || centre_x - 0.5 * sx > rect.br().x;
    const uint8_t value = cells.at<uint8_t>(50, col);
    if (inside) EXPECT_EQ(value, 255) << col;
    if (outside) EXPECT_EQ(value, 0) << col;
  }
  EXPECT_EQ(cv::countNonZero(cells.row(10)), 0);
}

TEST(StrokesPicture, SphereLayoutMapsBackOntoTheCells) {
  const Scan scan = BoxScan();
  PictureLayoutOptions options;
  options.view = PictureView::kSphere;
  // The box's pixels of the spherical picture (the cells keep the label of the point they show), at the
  // automatic size (about 3 points a pixel: the box's edge pixels show ground or box) and finer.
  for (const int width : {0, 3 * scan.cols}) {
    options.width_px = width;
    const PictureLayout layout = LayOutPicture(scan, options);
    const cv::Mat drawn = ResampleNearest(layout.cells.label == 1, layout.picture_size);
    const cv::Mat cells = CellsFromPicture(scan, MappingOfLayout(layout, scan), drawn);
    EXPECT_GT(IoU(cells, scan.label == 1), width == 0 ? 0.9 : 0.97) << width;
  }
  options.width_px = 0;
  const PictureLayout layout = LayOutPicture(scan, options);
  const cv::Mat drawn = ResampleNearest(layout.cells.label == 1, layout.picture_size);
  const PictureMapping mapping = MappingOfLayout(layout, scan);
  const cv::Mat cells = CellsFromPicture(scan, mapping, drawn);
  // The layout file gives the same mapping.
  const PictureMapping parsed = ParsePictureMapping(PictureMappingJson(mapping).dump(), "layout.json");
  EXPECT_EQ(parsed.view, PictureView::kSphere);
  EXPECT_EQ(parsed.azimuth_left_rad, mapping.azimuth_left_rad);
  EXPECT_EQ(parsed.elevation_step_rad, mapping.elevation_step_rad);
  EXPECT_EQ(cv::countNonZero(CellsFromPicture(scan, parsed, drawn) != cells), 0);
}

TEST(StrokesPicture, LegendBesideThePictureIsLeftOut) {
  const Scan scan = BoxScan();
  const PictureLayout layout = LayOutPicture(scan, {});
  const cv::Size image(layout.picture_size.width + 80, layout.picture_size.height);
  cv::Mat painted(image, CV_8U, cv::Scalar(0));
  painted.colRange(layout.picture_size.width, image.width).setTo(255);  // the legend
  const cv::Mat cells = CellsFromPicture(scan, MappingOfLayout(layout, scan, image), painted);
  EXPECT_EQ(cv::countNonZero(cells), 0);
}

TEST(StrokesPicture, FindsTheLayoutFromThePictureSize) {
  const Scan scan = BoxScan();
  const PictureLayout layout = LayOutPicture(scan, {});
  EXPECT_FALSE(
      FindPictureMapping(scan, "no/such/strokes.png", cv::Size(scan.cols, scan.rows), "", "scan.ptx"));
  const auto automatic = FindPictureMapping(scan, "no/such/strokes.png", layout.picture_size, "", "scan.ptx");
  ASSERT_TRUE(automatic);
  EXPECT_EQ(automatic->picture_size, layout.picture_size);
  PictureLayoutOptions narrow;
  narrow.width_px = 500;
  const cv::Size at_500 = LayOutPicture(scan, narrow).picture_size;
  const auto found = FindPictureMapping(scan, "no/such/strokes.png", at_500, "", "scan.ptx");
  ASSERT_TRUE(found);
  EXPECT_EQ(found->picture_size, at_500);
  // A size that is neither: the error names the sizes accepted and how to get a picture to paint on.
  try {
    FindPictureMapping(scan, "no/such/strokes.png", cv::Size(at_500.width, at_500.height + 40), "",
                       "scan.ptx");
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("no/such/strokes.png"), std::string::npos) << message;
    EXPECT_NE(message.find(fmt::format("{} x {} cells", scan.cols, scan.rows)), std::string::npos) << message;
    EXPECT_NE(message.find(
                  fmt::format("{} x {} by default", layout.picture_size.width, layout.picture_size.height)),
              std::string::npos)
        << message;
    EXPECT_NE(message.find("lidarshop render scan.ptx -o PICTURE.png"), std::string::npos) << message;
  }
}

TEST(StrokesPicture, OverlayIsInRendersLayoutWithThinStrokes) {
  const Scan scan = BoxScan();
  const cv::Mat truth = scan.label == 1;
  cv::Mat strokes(scan.rows, scan.cols, CV_8U, cv::Scalar(kStrokeNone));
  strokes.at<uint8_t>(100, 50) = kStrokeObject;
  const cv::Size picture = LayOutPicture(scan, {}).picture_size;
  PaintedStrokes painted;
  painted.cells = strokes;
  const cv::Mat overlay = OverlayOnPicture(scan, truth, painted);
  EXPECT_EQ(overlay.size(), picture);
  // One stroke cell: its own pixels only (about 2.7 x 1), not a disc.
  const int green = cv::countNonZero(cv::Mat(overlay.reshape(1, overlay.total()).col(1) == 255) &
                                     cv::Mat(overlay.reshape(1, overlay.total()).col(0) == 0));
  EXPECT_GE(green, 1);
  EXPECT_LE(green, 4);
}

// Strokes painted on a view from the front (or above) reach the cells whose points show there: the mapping
// is the picture's own (each painted pixel -> the cell whose point won it), it comes back the same through the
// layout file (the view laid out again at the file's sizes), and a scan whose points changed is refused.
TEST(StrokesPicture, PaintingOnAnOrthographicViewReachesTheCellsThatShow) {
  const Scan scan = BoxScan();
  const std::filesystem::path folder =
      std::filesystem::temp_directory_path() / fmt::format("lidarshop_strokes_picture_{}", getpid());
  std::filesystem::create_directories(folder);
  for (const PictureView view : {PictureView::kFront, PictureView::kTop}) {
    for (const int point_size_px : {0, 3}) {
      PictureLayoutOptions options;
      options.view = view;
      options.point_size_px = point_size_px;
      const PictureLayout layout = LayOutPicture(scan, options);
      ASSERT_EQ(layout.source_cells.size(), layout.picture_size);
      // Paint every pixel that shows the box; remember which cells those pixels show.
      cv::Mat painted(layout.picture_size, CV_8U, cv::Scalar(0));
      std::set<int> shown_box_cells;
      for (int y = 0; y < painted.rows; ++y) {
        for (int x = 0; x < painted.cols; ++x) {
          const int32_t cell = layout.source_cells.at<int32_t>(y, x);
          if (cell < 0 || scan.label.at<int32_t>(cell / scan.cols, cell % scan.cols) != 1) continue;
          painted.at<uint8_t>(y, x) = 255;
          shown_box_cells.insert(cell);
        }
      }
      const std::string what = fmt::format("{} view, point size {}", ToString(view), point_size_px);
      ASSERT_GT(shown_box_cells.size(), view == PictureView::kFront ? 50u : 5u) << what;
      const cv::Mat cells = CellsFromPicture(scan, MappingOfLayout(layout, scan), painted);
      EXPECT_EQ(cv::countNonZero(cells), static_cast<int>(shown_box_cells.size())) << what;
      EXPECT_EQ(cv::countNonZero(cells & (scan.label != 1)), 0) << what;  // no ground cell picked up
      // Through the layout file beside the picture: the same cells.
      const std::string picture = (folder / fmt::format("{}_{}.png", ToString(view), point_size_px)).string();
      std::ofstream(LayoutFilePath(picture)) << LayoutFileJson(layout, scan, {}).dump();
      const auto found = FindPictureMapping(scan, picture, layout.picture_size, "", "scan.ptx");
      ASSERT_TRUE(found) << what;
      EXPECT_EQ(found->view, view);
      EXPECT_EQ(found->point_size_px, point_size_px);
      EXPECT_EQ(cv::countNonZero(CellsFromPicture(scan, *found, painted) != cells), 0) << what;
      // The scan's points changed since the picture (a quarter of the columns gone): refused, not mis-mapped.
      Scan changed = Clone(scan);
      changed.valid.colRange(0, scan.cols / 4).setTo(0);
      EXPECT_THROW(FindPictureMapping(changed, picture, layout.picture_size, "", "scan.ptx"), InputError)
          << what;
    }
  }
  std::filesystem::remove_all(folder);
}

// The layout file's orthographic fields are checked like the rest: an unknown view, a point size out of
// range and a missing origin are refused naming the file and the field.
TEST(StrokesPicture, OrthographicLayoutFileFieldsAreChecked) {
  const Scan scan = BoxScan();
  PictureLayoutOptions options;
  options.view = PictureView::kTop;
  const nlohmann::ordered_json good = LayoutFileJson(LayOutPicture(scan, options), scan, {});
  EXPECT_EQ(ParsePictureMapping(good.dump(), "top.json").view, PictureView::kTop);
  auto refused = [&](nlohmann::ordered_json doc, const std::string& field) {
    try {
      ParsePictureMapping(doc.dump(), "top.json");
      ADD_FAILURE() << "accepted without a good " << field;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("top.json"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  nlohmann::ordered_json doc = good;
  doc["view"] = "oblique";
  refused(doc, "view");
  doc = good;
  doc["point_size_px"] = 33;
  refused(doc, "point_size_px");
  doc = good;
  doc["point_size_px"] = 2.5;
  refused(doc, "point_size_px");
  doc = good;
  doc.erase("left_m");
  refused(doc, "left_m");
}

}  // namespace
}  // namespace lidarshop
