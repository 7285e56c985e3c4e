// Input files: only regular files are read. A FIFO, a device or a folder is refused from its `stat` alone —
// opening a FIFO to find out would wait for a writer forever, and a folder or a device has no size that a
// reader could check a header's counts against.
#pragma once

#include <cstdint>
#include <string>

namespace lidarshop {

// Returns the size in bytes of the regular file `path`. Throws InputError naming `path` when it is missing,
// not readable, or not a regular file (FIFO, socket, device, folder), without opening it.
int64_t CheckRegularFile(const std::string& path);

// The whole regular file `path` (CheckRegularFile first). Throws InputError naming `path` when it cannot be
// read or when it is larger than `max_bytes`.
std::string ReadRegularFile(const std::string& path, int64_t max_bytes = int64_t{1} << 40);

}  // namespace lidarshop
