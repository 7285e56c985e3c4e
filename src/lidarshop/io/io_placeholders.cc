// Placeholders so the library links while the io module is being written; each is replaced by its real file.
#include "lidarshop/io/e57.h"
#include "lidarshop/io/image_io.h"
#include "lidarshop/io/mesh_io.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/util/error.h"

namespace lidarshop {

[[noreturn]] static void NotBuilt(const std::string& what) { throw std::logic_error(what + ": not built yet"); }

ScanFile ReadScanFile(const std::string& path) { NotBuilt("ReadScanFile"); }
void WriteScanFile(const std::string& path, const std::vector<Scan>& scans) { NotBuilt("WriteScanFile"); }
std::string FileExtension(const std::string& path) { NotBuilt("FileExtension"); }
TriangleMesh ReadMesh(const std::string& path) { NotBuilt("ReadMesh"); }
void WriteMesh(const std::string& path, const TriangleMesh& mesh, bool ascii) { NotBuilt("WriteMesh"); }
PointCloud ReadPointCloud(const std::string& path) { NotBuilt("ReadPointCloud"); }
void WritePointCloud(const std::string& path, const PointCloud& cloud, bool ascii) { NotBuilt("WritePointCloud"); }
cv::Mat ReadImage(const std::string& path) { NotBuilt("ReadImage"); }
void WriteImage(const std::string& path, const cv::Mat& image) { NotBuilt("WriteImage"); }
cv::Mat DecodeImage(const std::vector<uint8_t>& bytes, const std::string& what) { NotBuilt("DecodeImage"); }

}  // namespace lidarshop
