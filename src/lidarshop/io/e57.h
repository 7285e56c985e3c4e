// E57 (ASTM E2807) scans and images, implemented in lidarshop (no Debian package reads it).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "lidarshop/scan/scan.h"
#include "lidarshop/util/options_fwd.h"

namespace lidarshop {

// A photo stored in an E57 file's images2D section, in any of E57's four representations. The camera model
// each describes (geometry/camera_model.h) comes from io/e57_image_camera.h.
struct E57Image {
  std::string name;
  std::string
      projection;  // "pinhole", "spherical", "cylindrical" or "visual" (visualReferenceRepresentation)
  cv::Mat image;   // decoded, RGB
  Eigen::Matrix4d world_from_camera = Eigen::Matrix4d::Identity();
  // Pinhole intrinsics (metres, as E57 stores them); 0 when absent. The reader fills pixel_width_m and
  // pixel_height_m with pixelWidth / pixelHeight as stored whatever the representation (radians for a
  // spherical entry's both and a cylindrical entry's width); pixel_height_m is the cylindrical
  // representation's pixelHeight (metres on the cylinder) and principal_y_px its principalPointY.
  double focal_length_m = 0, pixel_width_m = 0, pixel_height_m = 0, principal_x_px = 0, principal_y_px = 0;
  // Spherical: pixelWidth and pixelHeight (radians); cylindrical: pixelWidth (radians) and radius (metres).
  // 0 when absent. The writer takes the angles from here (from pixel_width_m / pixel_height_m when 0).
  double pixel_width_rad = 0, pixel_height_rad = 0, radius_m = 0;
  int width_px = 0, height_px = 0;  // imageWidth / imageHeight as the XML states them
  std::string decode_error;  // why `image` is empty when its blob does not decode (e.g. a zero-filled blob)
  // The blob exactly as stored, so that E57 -> E57 keeps the photo bit-exact (recolouring reads it back).
  std::vector<uint8_t> encoded;
  std::string encoding;               // "jpeg" or "png" (the blob's element: jpegImage / pngImage)
  std::vector<uint8_t> mask_encoded;  // the representation's imageMask (PNG) as stored; empty when absent
  std::string guid;                   // as stored; the writer makes one when empty
  std::string description;            // as stored; "" when absent
  // The data3D entry (index into E57File::scans) named by associatedData3DGuid; -1 when none or unknown.
  // The writer writes that scan's guid.
  int associated_scan = -1;
};

struct E57File {
  std::vector<Scan> scans;  // data3D: organized scans keep their grid; unstructured ones are 1 x N scans
  std::vector<E57Image> images;
  // One per scan: the second returns (returnIndex 1) of scans[i] as a scan of the same grid, pose and
  // directions, valid where a cell has a second return (e.g. the layer behind a kept object written by
  // WriteE57WithLayer); 0 x 0 when the scan has none.
  std::vector<Scan> second_returns;
  // What the reader left out, one sentence each (e.g. "scan 0 ('x'): 12 records with returnIndex >= 2 (third
  // and later returns) are not kept"). The library does not print them.
  std::vector<std::string> warnings;
};

// lidarshop's E57 extension (E2807: extensions are XML namespaces declared on e57Root). Declared as
// xmlns:lidarshop="http://lidarshop.dev/e57/1.0" when a file uses it; its fields are
// - the points prototype's `lidarshop:synthesized` (Integer 0..1, 1 = created by lidarshop), read back into
//   Scan::synthesized (255 / 0);
// - the points prototype's `lidarshop:fromStation` (Integer 0..255: 1 + the index of the other station a
//   cell's return was taken from, site/from_stations.h; 0 = not), read back into Scan::from_station;
// - `lidarshop:angularGrid` under a data3D entry: a Structure holding `azimuth` (a Vector of one double Float
//   per columnIndex) and `elevation` (one per rowIndex), radians in lidarshop's scanner frame (scan.h), and
//   `fitted` (Integer 0..1): the scan's ScanGrid, read back bit for bit (a grid the points do not sit around,
//   half a step off on the mean, is fitted again, with a warning). A scan read with it holds no image when every
//   stored ray is the grid's (scan/ray_directions.h);
// - `lidarshop:noReturnDirections` under a data3D entry: a Structure whose `points` CompressedVector holds
//   one record per cell without a return whose ray is not its grid ray (rowIndex, columnIndex, the unit ray
//   as single-float cartesianX/Y/Z), read back into those cells' directions bit for bit.
// Readers that do not know the namespace skip them (libE57Format does).
constexpr char kLidarshopE57Namespace[] = "http://lidarshop.dev/e57/1.0";

// Throws InputError naming the file, the page or byte offset and what is wrong (bad CRC, truncated, bad XML).
E57File ReadE57(const std::string& path);

// Writes organized scans with pose, intensity and colour (each when the scan has it), row/column index and
// invalid state, and the synthesized channel (when present) as the extension field lidarshop:synthesized
// (from_station as lidarshop:fromStation);
// atomic. Cells without a return get no record in `points` (as scanners' own files): every reader counts and
// shows the scan's returns only. Their rays go to lidarshop:noReturnDirections (see E57WriteOptions).
void WriteE57(const std::string& path, const std::vector<Scan>& scans);

// ReadE57 on the bytes of a file already in memory; `name` is used in error messages (fuzzing, tests,
// streams).
E57File ReadE57Bytes(const std::vector<uint8_t>& file_bytes, const std::string& name);

struct E57WriteOptions {
  // Coordinates: 0 = IEEE single floats (bit-exact round trip of the float32 points); > 0 = ScaledInteger
  // with this step in metres (e.g. 1e-4 = 0.1 mm), using the fewest bits that hold the scan's extent.
  double coordinate_scale_m = 0.0;
  // Cells without a return are never records of `points` (a reader that ignores cartesianInvalidState would
  // show their rays as points). true: the scan's grid is written in `lidarshop:angularGrid` and the rays that
  // are not the grid's in `lidarshop:noReturnDirections`, so that every ray survives a round trip bit for bit;
  // false: neither (the reader then gives every cell the fitted grid's direction). Files written by lidarshop before the
  // extension carried these rays as `points` records of cartesianInvalidState 1 at unit distance; ReadE57
  // still reads them so.
  bool write_no_return_directions = true;
  void Check() const;  // throws OptionsError
};
template <>
const StructInfo& InfoOf<E57WriteOptions>();
void WriteE57(const std::string& path, const std::vector<Scan>& scans, const E57WriteOptions& options);
// The bytes WriteE57 would write (bench, tests).
std::vector<uint8_t> EncodeE57(const std::vector<Scan>& scans, const E57WriteOptions& options = {});

// One scan with a second layer behind it (`remove --keep-object`: the kept object in front, the filled
// background behind). `front` and `behind` share the grid (rows x cols, directions) and pose; `behind` holds
// returns only in some cells. Every record of `front` is written as by WriteE57 with returnIndex 0, plus one
// record per valid `behind` cell with the same rowIndex/columnIndex and returnIndex 1 (after a front record
// at zero coordinates with cartesianInvalidState 2 where the front has no return); returnCount is 2 on
// both records of such a cell, else 1; the `lidarshop:synthesized` field is 1 on every second return and
// follows front.synthesized on the others. ReadE57 gives the layers back as scans[0] and second_returns[0].
// Throws std::logic_error when the layers differ in size (check first: WriteScanWithLayer does). Atomic.
void WriteE57WithLayer(const std::string& path, const Scan& front, const Scan& behind,
                       const E57WriteOptions& options = {});
std::vector<uint8_t> EncodeE57WithLayer(const Scan& front, const Scan& behind,
                                        const E57WriteOptions& options = {});
// Scans and photos (images2D): each image is written with its guid, name, description, pose, the scan it
// belongs to (associatedData3DGuid), its representation with that representation's fields (pinhole:
// focalLength, pixelWidth, pixelHeight, principalPointX/Y; spherical: pixelWidth, pixelHeight; cylindrical:
// pixelWidth, pixelHeight, radius, principalPointY) and imageMask; its blob is `encoded` as stored (encoding
// "jpeg" or "png"), or `image` encoded as PNG when it has no stored bytes. Images with neither are skipped.
std::vector<uint8_t> EncodeE57(const std::vector<Scan>& scans, const std::vector<E57Image>& images,
                               const E57WriteOptions& options);
void WriteE57(const std::string& path, const std::vector<Scan>& scans, const std::vector<E57Image>& images,
              const E57WriteOptions& options);
// A whole file as ReadE57 gave it (E57 -> E57): scans, the second returns of each (returnIndex 1; a second
// layer's `synthesized` flags are kept, a layer without the channel is written as measured) and photos.
// Throws std::logic_error when a second layer differs from its scan in size.
std::vector<uint8_t> EncodeE57(const E57File& file, const E57WriteOptions& options);
void WriteE57(const std::string& path, const E57File& file, const E57WriteOptions& options);

}  // namespace lidarshop
