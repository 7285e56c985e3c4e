// Placeholder so the library links while the E57 reader is being written; replaced by the real files.
#include "lidarshop/io/e57.h"

namespace lidarshop {

E57File ReadE57(const std::string& path) { throw std::logic_error("ReadE57: not built yet"); }
void WriteE57(const std::string& path, const std::vector<Scan>& scans) {
  throw std::logic_error("WriteE57: not built yet");
}

}  // namespace lidarshop
