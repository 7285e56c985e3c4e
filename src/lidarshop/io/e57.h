// E57 (ASTM E2807) scans and images, implemented in lidarshop (no Debian package reads it).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "lidarshop/scan/scan.h"

namespace lidarshop {

// A photo stored in an E57 file's images2D section (pinhole or spherical representation).
struct E57Image {
  std::string name;
  std::string projection;  // "pinhole", "spherical", "cylindrical" or "visual" (visualReferenceRepresentation)
  cv::Mat image;           // decoded, RGB
  Eigen::Matrix4d world_from_camera = Eigen::Matrix4d::Identity();
  // Pinhole intrinsics (metres, as E57 stores them); 0 when absent.
  double focal_length_m = 0, pixel_width_m = 0, pixel_height_m = 0, principal_x_px = 0, principal_y_px = 0;
};

struct E57File {
  std::vector<Scan> scans;  // data3D: organized scans keep their grid; unstructured ones are 1 x N scans
  std::vector<E57Image> images;
};

// Throws InputError naming the file, the page or byte offset and what is wrong (bad CRC, truncated, bad XML).
E57File ReadE57(const std::string& path);

// Writes organized scans with pose, intensity, colour, row/column index and invalid state; atomic.
void WriteE57(const std::string& path, const std::vector<Scan>& scans);

}  // namespace lidarshop
