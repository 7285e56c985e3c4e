// A program outside the lidarshop tree, built by the ctest `install_test` against the installed package
// (find_package(lidarshop)): writes a small synthetic scan to PLY, reads it back and checks one point.
// Usage: lidarshop_consumer OUT_DIR. Exit 0 when the point came back, 1 otherwise.
#include <cmath>
#include <cstdio>
#include <string>

#include "lidarshop/io/scan_io.h"
#include "lidarshop/scan/scan.h"

int main(int argc, char** argv) {
  if (argc != 2) return std::fprintf(stderr, "usage: lidarshop_consumer OUT_DIR\n"), 2;
  // 3 x 4 rays over ±0.2 rad; every ray returns at 2 m + 0.5 m per row + 0.25 m per column.
  lidarshop::Scan scan = lidarshop::MakeScan(3, 4);
  scan.grid = lidarshop::UniformGrid(3, 4, -0.2, 0.2, -0.2, 0.2);
  scan.direction = lidarshop::DirectionsFromGrid(scan.grid);
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 4; ++col) {
      const float range_m = 2.0f + 0.5f * row + 0.25f * col;
      scan.range.at<float>(row, col) = range_m;
      scan.point.at<cv::Vec3f>(row, col) = scan.direction.at<cv::Vec3f>(row, col) * range_m;
      scan.valid.at<uint8_t>(row, col) = lidarshop::kValid;
    }
  }
  const std::string path = std::string(argv[1]) + "/scan.ply";
  lidarshop::WriteScanFile(path, {scan});
  const lidarshop::ScanFile file = lidarshop::ReadScanFile(path);
  const lidarshop::Scan& back = file.scans.at(0);
  const float range_m = back.rows == 3 && back.cols == 4 ? back.range.at<float>(2, 3) : NAN;
  std::printf("lidarshop_consumer: %s holds %lld points; range at row 2, col 3: %.4f m (want 3.7500)\n",
              path.c_str(), static_cast<long long>(back.CountValid()), range_m);
  return back.CountValid() == 12 && std::abs(range_m - 3.75f) < 1e-5f ? 0 : 1;
}
