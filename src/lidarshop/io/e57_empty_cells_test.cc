// Cells without a return in the E57 we write: no record in `points` (what other readers count and show), the
// scan's grid in lidarshop's extension (lidarshop:angularGrid) and the rays that are not the grid's beside it
// (lidarshop:noReturnDirections), and files of the earlier layout (rays as records of cartesianInvalidState 1
// at unit distance) still read as before.
#include <algorithm>
#include <cstring>
#include <functional>
#include <iterator>
#include <random>
#include <string>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <pugixml.hpp>

#include "lidarshop/io/e57.h"
#include "lidarshop/io/e57_format.h"
#include "lidarshop/io/io_test_util.h"
#include "lidarshop/scan/ray_directions.h"
#include "lidarshop/util/error.h"

namespace lidarshop {
namespace {

using ::testing::HasSubstr;
using testing_io::InputErrorOf;

// A uniform grid with ~25 % no-return cells (each keeping its direction), intensity and colour.
Scan ScanWithHoles(int rows, int cols, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  Scan s = MakeScan(rows, cols, /*with_color=*/true);
  s.name = "holes";
  s.grid = UniformGrid(rows, cols, -1.0, 1.2, -0.5, 0.7);
  s.direction = DirectionsFromGrid(s.grid);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      if (u(rng) < 0.25f) continue;
      const cv::Vec3f p = DirectionImage(s).at<cv::Vec3f>(r, c) * (2.0f + 10.0f * u(rng));
      s.valid.at<uint8_t>(r, c) = kValid;
      s.point.at<cv::Vec3f>(r, c) = p;
      s.range.at<float>(r, c) = static_cast<float>(cv::norm(p));
      s.intensity.at<float>(r, c) = u(rng);
      s.color.at<cv::Vec3b>(r, c) = cv::Vec3b(rng() & 255, rng() & 255, rng() & 255);
    }
  }
  s.world_from_scanner(0, 3) = 4.0;
  return s;
}

// The XML section of an encoded file.
pugi::xml_document XmlOf(const std::vector<uint8_t>& bytes) {
  const std::vector<uint8_t> logical = e57::LogicalFromPages("x.e57", bytes);
  const e57::Header header = e57::ParseHeader("x.e57", logical);
  pugi::xml_document doc;
  doc.load_buffer(logical.data() + e57::LogicalFromPhysical(header.xml_physical_offset),
                  header.xml_logical_length);
  return doc;
}

void ExpectSameCells(const Scan& a, const Scan& b) {
  ASSERT_EQ(a.rows, b.rows);
  ASSERT_EQ(a.cols, b.cols);
  EXPECT_EQ(cv::countNonZero(a.valid != b.valid), 0);
  const cv::Mat rays_a = DirectionImage(a), rays_b = DirectionImage(b);
  for (int64_t c = 0; c < a.num_cells(); ++c) {
    if (a.valid.ptr<uint8_t>()[c]) {
      ASSERT_EQ(a.point.ptr<cv::Vec3f>()[c], b.point.ptr<cv::Vec3f>()[c]) << "cell " << c;
      ASSERT_EQ(a.intensity.ptr<float>()[c], b.intensity.ptr<float>()[c]) << "cell " << c;
      ASSERT_EQ(a.color.ptr<cv::Vec3b>()[c], b.color.ptr<cv::Vec3b>()[c]) << "cell " << c;
    } else {  // the ray, bit for bit
      ASSERT_EQ(rays_a.ptr<cv::Vec3f>()[c], rays_b.ptr<cv::Vec3f>()[c]) << "cell " << c;
    }
  }
}

TEST(E57EmptyCells, RaysOfTheGridAreWrittenAsTheGridAndReadWithoutAnImage) {
  const Scan scan = ScanWithHoles(23, 31, 1);
  const std::vector<uint8_t> bytes = EncodeE57({scan});
  const pugi::xml_document doc = XmlOf(bytes);
  const pugi::xml_node entry = doc.child("e57Root").child("data3D").child("vectorChild");
  EXPECT_FALSE(entry.child("lidarshop:noReturnDirections"));  // every ray is the grid's
  const pugi::xml_node grid = entry.child("lidarshop:angularGrid");
  ASSERT_TRUE(grid);
  EXPECT_EQ(std::distance(grid.child("azimuth").begin(), grid.child("azimuth").end()), 31);
  EXPECT_EQ(std::distance(grid.child("elevation").begin(), grid.child("elevation").end()), 23);
  const Scan back = ReadE57Bytes(bytes, "grid.e57").scans[0];
  EXPECT_TRUE(back.direction.empty());                      // 12 bytes a ray not held
  EXPECT_EQ(back.grid.azimuth_rad, scan.grid.azimuth_rad);  // bit for bit
  EXPECT_EQ(back.grid.elevation_rad, scan.grid.elevation_rad);
  ExpectSameCells(scan, back);
  const cv::Mat rays = DirectionImage(back);
  EXPECT_EQ(std::memcmp(rays.data, scan.direction.data, scan.direction.total() * scan.direction.elemSize()),
            0);
  // Written again: the same bytes.
  EXPECT_EQ(EncodeE57({back}), bytes);
}

// The file `bytes` with its XML section (the last section EncodeE57 writes) passed through `edit`.
std::vector<uint8_t> WithEditedXml(const std::vector<uint8_t>& bytes,
                                   const std::function<std::string(std::string)>& edit) {
  std::vector<uint8_t> logical = e57::LogicalFromPages("x.e57", bytes);
  e57::Header header = e57::ParseHeader("x.e57", logical);
  const uint64_t start = e57::LogicalFromPhysical(header.xml_physical_offset);
  const std::string xml =
      edit(std::string(logical.begin() + start, logical.begin() + start + header.xml_logical_length));
  logical.resize(start);
  logical.insert(logical.end(), xml.begin(), xml.end());
  header.xml_logical_length = xml.size();
  header.file_physical_length = (logical.size() + e57::kPagePayload - 1) / e57::kPagePayload * e57::kPageSize;
  e57::StoreHeader(header, logical.data());
  return e57::PagesFromLogical(logical);
}

// `xml` with the values of the grid's `axis` vector replaced by `values` (numbers as text).
std::string ReplaceAngles(std::string xml, const std::string& axis, const std::vector<std::string>& values) {
  const size_t vector = xml.find("<" + axis + " ", xml.find("lidarshop:angularGrid"));
  const size_t open = xml.find(">", vector) + 1, close = xml.find("</" + axis + ">", open);
  std::string elements;
  for (const std::string& value : values) elements += "<value type=\"Float\">" + value + "</value>";
  return xml.replace(open, close - open, elements);
}

std::vector<std::string> AnglesAsText(const std::vector<double>& angles, double shift_rad) {
  std::vector<std::string> text;
  for (const double angle : angles) text.push_back(fmt::format("{}", angle + shift_rad));
  return text;
}

TEST(E57EmptyCells, AStoredGridOfTheWrongSizeOrNotFiniteIsRefused) {
  const Scan scan = ScanWithHoles(9, 11, 4);
  const std::vector<uint8_t> bytes = EncodeE57({scan});
  std::vector<std::string> short_azimuths = AnglesAsText(scan.grid.azimuth_rad, 0.0);
  short_azimuths.pop_back();
  try {
    ReadE57Bytes(
        WithEditedXml(bytes, [&](std::string xml) { return ReplaceAngles(xml, "azimuth", short_azimuths); }),
        "short.e57");
    FAIL() << "a grid with 10 azimuths for 11 columns was read";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("short.e57"));
    EXPECT_THAT(e.what(), HasSubstr("holds 10 angles for the scan's 11 columns"));
  }
  std::vector<std::string> long_azimuths = AnglesAsText(scan.grid.azimuth_rad, 0.0);
  long_azimuths.push_back("0.5");
  EXPECT_THAT(InputErrorOf([&] {
                ReadE57Bytes(
                    WithEditedXml(
                        bytes, [&](std::string xml) { return ReplaceAngles(xml, "azimuth", long_azimuths); }),
                    "long.e57");
              }),
              HasSubstr("holds more than the scan's 11 columns"));
  EXPECT_THAT(InputErrorOf([&] {
                ReadE57Bytes(WithEditedXml(bytes,
                                           [](std::string xml) {  // the element renamed
                                             xml.replace(xml.find("<elevation "), 10, "<elevatio_");
                                             return xml.replace(xml.find("</elevation>"), 12, "</elevatio_>");
                                           }),
                             "no_elevation.e57");
              }),
              HasSubstr("has no 'elevation'"));
  std::vector<std::string> infinite = AnglesAsText(scan.grid.elevation_rad, 0.0);
  infinite[3] = "inf";
  EXPECT_THROW(
      ReadE57Bytes(
          WithEditedXml(bytes, [&](std::string xml) { return ReplaceAngles(xml, "elevation", infinite); }),
          "inf.e57"),
      InputError);
}

TEST(E57EmptyCells, AStoredGridThePointsAreNotOnIsFittedAgainWithAWarning) {
  const Scan scan = ScanWithHoles(20, 24, 5);
  // Every azimuth moved by one step: the points were not scanned on this grid.
  const double step = scan.grid.azimuth_rad[1] - scan.grid.azimuth_rad[0];
  const std::vector<uint8_t> bytes = WithEditedXml(EncodeE57({scan}), [&](std::string xml) {
    return ReplaceAngles(xml, "azimuth", AnglesAsText(scan.grid.azimuth_rad, step));
  });
  const E57File back = ReadE57Bytes(bytes, "moved.e57");
  ASSERT_EQ(back.warnings.size(), 1u);
  EXPECT_THAT(back.warnings[0], HasSubstr("is not where the points are"));
  EXPECT_TRUE(back.scans[0].grid.fitted);
  EXPECT_LT(back.scans[0].grid.rms_residual_rad, 1e-4);
}

TEST(E57EmptyCells, OnlyReturnsAreRecordsAndRaysOffTheGridGoToTheExtension) {
  Scan scan = ScanWithHoles(23, 31, 1);
  const int64_t returns = scan.CountValid();
  ASSERT_GT(scan.num_cells() - returns, 100);
  // Every third no-return cell's ray a little off its grid ray (as a scanner's stored rays can be).
  int64_t off_grid = 0, empty = 0;
  for (int64_t c = 0; c < scan.num_cells(); ++c) {
    if (scan.valid.ptr<uint8_t>()[c] || empty++ % 3 != 0) continue;
    cv::Vec3f& d = scan.direction.ptr<cv::Vec3f>()[c];
    d = cv::normalize(d + cv::Vec3f(1e-3f, -2e-3f, 1e-3f));
    ++off_grid;
  }
  for (double scale : {0.0, 1e-4}) {  // float and scaled-integer coordinates: the rays stay exact floats
    SCOPED_TRACE(scale);
    E57WriteOptions options;
    options.coordinate_scale_m = scale;
    const std::vector<uint8_t> bytes = EncodeE57({scan}, options);
    const pugi::xml_document doc = XmlOf(bytes);
    const pugi::xml_node root = doc.child("e57Root");
    EXPECT_STREQ(root.attribute("xmlns:lidarshop").value(), kLidarshopE57Namespace);
    const pugi::xml_node entry = root.child("data3D").child("vectorChild");
    EXPECT_EQ(entry.child("points").attribute("recordCount").as_llong(), returns);
    EXPECT_EQ(entry.child("indexBounds").child("rowMaximum").text().as_int(), 22);
    const pugi::xml_node rays = entry.child("lidarshop:noReturnDirections").child("points");
    EXPECT_EQ(rays.attribute("recordCount").as_llong(), off_grid);
    const E57File back = ReadE57Bytes(bytes, "holes.e57");
    ASSERT_EQ(back.scans.size(), 1u);
    if (scale == 0.0) {
      ExpectSameCells(scan, back.scans[0]);
    } else {
      for (int64_t c = 0; c < scan.num_cells(); ++c) {
        if (scan.valid.ptr<uint8_t>()[c]) continue;
        ASSERT_EQ(DirectionImage(scan).ptr<cv::Vec3f>()[c], DirectionImage(back.scans[0]).ptr<cv::Vec3f>()[c])
            << c;
      }
    }
  }
}

TEST(E57EmptyCells, WithoutDirectionsTheGridGivesThem) {
  const Scan scan = ScanWithHoles(20, 24, 2);
  E57WriteOptions options;
  options.write_no_return_directions = false;
  const std::vector<uint8_t> bytes = EncodeE57({scan}, options);
  const pugi::xml_document doc = XmlOf(bytes);
  const pugi::xml_node entry = doc.child("e57Root").child("data3D").child("vectorChild");
  EXPECT_EQ(entry.child("points").attribute("recordCount").as_llong(), scan.CountValid());
  EXPECT_FALSE(entry.child("lidarshop:noReturnDirections"));
  EXPECT_FALSE(doc.child("e57Root").attribute("xmlns:lidarshop"));
  const Scan back = ReadE57Bytes(bytes, "no_rays.e57").scans[0];
  EXPECT_EQ(cv::countNonZero(back.valid != scan.valid), 0);
  for (int64_t c = 0; c < scan.num_cells(); ++c) {  // from the fitted grid: close to the true rays
    ASSERT_LT(cv::norm(DirectionImage(back).ptr<cv::Vec3f>()[c] - DirectionImage(scan).ptr<cv::Vec3f>()[c]),
              1e-3)
        << c;
  }
}

TEST(E57EmptyCells, ACellWithOnlyASecondReturnKeepsAFirstRecordWithoutCoordinates) {
  const Scan front = ScanWithHoles(12, 15, 3);
  Scan behind = MakeScan(front.rows, front.cols, /*with_color=*/true);
  behind.world_from_scanner = front.world_from_scanner;
  behind.direction = front.direction.clone();
  int64_t behind_empty_front = 0;
  for (int64_t c = 0; c < front.num_cells(); c += 2) {
    const cv::Vec3f p = DirectionImage(front).ptr<cv::Vec3f>()[c] * 15.0f;
    behind.valid.ptr<uint8_t>()[c] = kValid;
    behind.point.ptr<cv::Vec3f>()[c] = p;
    behind.range.ptr<float>()[c] = static_cast<float>(cv::norm(p));
    behind_empty_front += front.valid.ptr<uint8_t>()[c] == 0;
  }
  ASSERT_GT(behind_empty_front, 5);
  const std::vector<uint8_t> bytes = EncodeE57WithLayer(front, behind);
  const pugi::xml_document doc = XmlOf(bytes);
  const pugi::xml_node points = doc.child("e57Root").child("data3D").child("vectorChild").child("points");
  // One record per return of either layer, plus a first record (state 2, zero coordinates) per cell whose
  // only return is the second.
  EXPECT_EQ(points.attribute("recordCount").as_llong(),
            front.CountValid() + behind.CountValid() + behind_empty_front);
  const E57File back = ReadE57Bytes(bytes, "layers.e57");
  ExpectSameCells(front, back.scans[0]);
  EXPECT_EQ(cv::countNonZero(back.second_returns[0].valid != behind.valid), 0);
}

// Appends a compressed vector of `columns` (name, one value per record) to `logical`: names ending in "Index"
// or "State" are Integer fields from 0 to their maximum, the others single floats. Returns its physical
// offset; `prototype` receives the fields' XML.
using Columns = std::vector<std::pair<std::string, std::vector<double>>>;
uint64_t AppendColumns(const Columns& columns, std::vector<uint8_t>* logical, std::string* prototype) {
  std::vector<e57::Stream> streams;
  for (const auto& [name, values] : columns) {
    e57::Stream s;
    const bool integer = name.ends_with("Index") || name.ends_with("State");
    if (integer) {
      const double max = values.empty() ? 0 : *std::max_element(values.begin(), values.end());
      s.field = e57::IntegerField(name.c_str(), 0, static_cast<int64_t>(max));
      e57::BitWriter w(s.field.bits);
      for (double v : values) w.PutInteger(static_cast<int64_t>(v), 0);
      s.bytes = w.Finish();
      *prototype += fmt::format(R"(<{} type="Integer" minimum="0" maximum="{}"/>)", name, s.field.maximum);
    } else {
      s.field.name = name;
      s.field.type = e57::Field::Type::kFloat;
      s.field.bits = 32;
      e57::BitWriter w(32);
      for (double v : values) w.PutFloat(static_cast<float>(v));
      s.bytes = w.Finish();
      *prototype += fmt::format(R"(<{} type="Float" precision="single"/>)", name);
    }
    streams.push_back(std::move(s));
  }
  return e57::AppendCompressedVector(streams, static_cast<int64_t>(columns[0].second.size()), logical);
}

// The pages of `logical` (binary sections after the header) followed by the XML section `xml`.
std::vector<uint8_t> FileAround(std::vector<uint8_t> logical, const std::string& xml) {
  while (logical.size() % 8) logical.push_back(0);
  e57::Header header;
  header.xml_physical_offset = e57::PhysicalFromLogical(logical.size());
  header.xml_logical_length = xml.size();
  logical.insert(logical.end(), xml.begin(), xml.end());
  header.file_physical_length = (logical.size() + e57::kPagePayload - 1) / e57::kPagePayload * e57::kPageSize;
  e57::StoreHeader(header, logical.data());
  return e57::PagesFromLogical(logical);
}

// One data3D entry around `inside` (points and extension elements); rows x cols in indexBounds.
std::string XmlOfEntry(int rows, int cols, const std::string& inside) {
  return fmt::format(
      R"(<?xml version="1.0" encoding="UTF-8"?><e57Root type="Structure" )"
      R"(xmlns="http://www.astm.org/COMMIT/E57/2010-e57-v1.0" xmlns:ls="http://lidarshop.dev/e57/1.0">)"
      R"(<data3D type="Vector"><vectorChild type="Structure"><name type="String">hand</name>)"
      R"(<indexBounds type="Structure"><rowMaximum type="Integer">{}</rowMaximum>)"
      R"(<columnMaximum type="Integer">{}</columnMaximum></indexBounds>{}</vectorChild></data3D></e57Root>)",
      rows - 1, cols - 1, inside);
}

std::string CompressedVector(const char* name, uint64_t offset, size_t count, const std::string& prototype) {
  return fmt::format(R"(<{} type="CompressedVector" fileOffset="{}" recordCount="{}">)"
                     R"(<prototype type="Structure">{}</prototype><codecs type="Vector"/></{}>)",
                     name, offset, count, prototype, name);
}

// A file as lidarshop wrote it before lidarshop:noReturnDirections: the no-return cells' rays as `points`
// records of cartesianInvalidState 1 whose coordinates are the unit direction.
std::vector<uint8_t> EncodeEarlierLayout(const Scan& scan) {
  Columns columns = {{"cartesianX", {}}, {"cartesianY", {}},  {"cartesianZ", {}},
                     {"rowIndex", {}},   {"columnIndex", {}}, {"cartesianInvalidState", {}}};
  for (int64_t c = 0; c < scan.num_cells(); ++c) {  // every cell has a direction here
    const bool valid = scan.valid.ptr<uint8_t>()[c] != 0;
    const cv::Vec3f p = valid ? scan.point.ptr<cv::Vec3f>()[c] : DirectionImage(scan).ptr<cv::Vec3f>()[c];
    for (int axis = 0; axis < 3; ++axis) columns[axis].second.push_back(p[axis]);
    columns[3].second.push_back(static_cast<double>(c / scan.cols));
    columns[4].second.push_back(static_cast<double>(c % scan.cols));
    columns[5].second.push_back(valid ? 0 : 1);
  }
  std::vector<uint8_t> logical(e57::kHeaderSize, 0);
  std::string prototype;
  const uint64_t offset = AppendColumns(columns, &logical, &prototype);
  return FileAround(logical,
                    XmlOfEntry(scan.rows, scan.cols,
                               CompressedVector("points", offset, columns[0].second.size(), prototype)));
}

TEST(E57EmptyCells, FilesOfTheEarlierLayoutReadAsBefore) {
  Scan scan = ScanWithHoles(18, 26, 4);
  scan.intensity = cv::Mat();  // the earlier layout above writes no intensity nor colour
  scan.color = cv::Mat();
  const E57File earlier = ReadE57Bytes(EncodeEarlierLayout(scan), "earlier.e57");
  ASSERT_EQ(earlier.scans.size(), 1u);
  const Scan& a = earlier.scans[0];
  EXPECT_EQ(a.CountValid(), scan.CountValid());
  for (int64_t c = 0; c < scan.num_cells(); ++c) {
    if (scan.valid.ptr<uint8_t>()[c]) {
      ASSERT_EQ(a.point.ptr<cv::Vec3f>()[c], scan.point.ptr<cv::Vec3f>()[c]) << c;
    } else {  // the stored unit direction, bit for bit
      ASSERT_EQ(DirectionImage(a).ptr<cv::Vec3f>()[c], DirectionImage(scan).ptr<cv::Vec3f>()[c]) << c;
    }
  }
  // The same scan in today's layout reads to the same cells, rays included.
  const Scan b = ReadE57Bytes(EncodeE57({a}), "today.e57").scans[0];
  EXPECT_EQ(cv::countNonZero(a.valid != b.valid), 0);
  const cv::Mat rays_a = DirectionImage(a), rays_b = DirectionImage(b);
  for (int64_t c = 0; c < a.num_cells(); ++c) {
    ASSERT_EQ(DirectionImage(a).ptr<cv::Vec3f>()[c], DirectionImage(b).ptr<cv::Vec3f>()[c]) << c;
    if (a.valid.ptr<uint8_t>()[c]) ASSERT_EQ(a.point.ptr<cv::Vec3f>()[c], b.point.ptr<cv::Vec3f>()[c]) << c;
  }
}

TEST(E57EmptyCells, RaysOfACellWithAReturnOrOutsideTheGridAreRefused) {
  // A 2 x 3 grid, one return at row 0, column 1; the extension (under another prefix bound to lidarshop's
  // namespace) gives rays for `ray_cells`.
  auto file = [](std::vector<std::pair<int, int>> ray_cells) {
    std::vector<uint8_t> logical(e57::kHeaderSize, 0);
    std::string points_prototype, rays_prototype;
    const uint64_t points = AppendColumns({{"cartesianX", {0.5}},
                                           {"cartesianY", {2.0}},
                                           {"cartesianZ", {0.1}},
                                           {"rowIndex", {0}},
                                           {"columnIndex", {1}}},
                                          &logical, &points_prototype);
    Columns rays = {
        {"rowIndex", {}}, {"columnIndex", {}}, {"cartesianX", {}}, {"cartesianY", {}}, {"cartesianZ", {}}};
    for (const auto& [r, c] : ray_cells) {
      rays[0].second.push_back(r);
      rays[1].second.push_back(c);
      rays[2].second.push_back(0.0);
      rays[3].second.push_back(0.6);
      rays[4].second.push_back(0.8);
    }
    const uint64_t extension = AppendColumns(rays, &logical, &rays_prototype);
    return FileAround(logical,
                      XmlOfEntry(2, 3,
                                 CompressedVector("points", points, 1, points_prototype) +
                                     "<ls:noReturnDirections type=\"Structure\">" +
                                     CompressedVector("points", extension, ray_cells.size(), rays_prototype) +
                                     "</ls:noReturnDirections>"));
  };
  const Scan good = ReadE57Bytes(file({{1, 2}, {0, 0}}), "good.e57").scans[0];
  ASSERT_EQ(good.rows, 2);
  ASSERT_EQ(good.cols, 3);
  EXPECT_EQ(good.CountValid(), 1);
  // The rays survive whatever orientation the reader chose (one return: no flip), under the `ls` prefix.
  EXPECT_EQ(DirectionImage(good).at<cv::Vec3f>(1, 2), cv::Vec3f(0.0f, 0.6f, 0.8f));
  EXPECT_EQ(DirectionImage(good).at<cv::Vec3f>(0, 0), cv::Vec3f(0.0f, 0.6f, 0.8f));
  try {
    ReadE57Bytes(file({{0, 1}}), "ray_on_a_return.e57");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("ray_on_a_return.e57"));
    EXPECT_THAT(e.what(), HasSubstr("noReturnDirections"));
    EXPECT_THAT(e.what(), HasSubstr("the cell has a return"));
  }
  try {
    ReadE57Bytes(file({{2, 0}}), "ray_outside.e57");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("ray_outside.e57"));
    EXPECT_THAT(e.what(), HasSubstr("rowIndex 2 is outside the scan's 2 x 3 grid"));
  }
}

}  // namespace
}  // namespace lidarshop
