#include "lidarshop/util/input_file.h"

#include <sys/stat.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>

#include <fmt/format.h>

#include "lidarshop/util/error.h"
#include "lidarshop/util/memory_budget.h"

namespace lidarshop {
namespace {

const char* KindOf(mode_t mode) {
  if (S_ISDIR(mode)) return "a folder";
  if (S_ISFIFO(mode)) return "a named pipe (FIFO)";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "a device";
  return "not a regular file";
}

}  // namespace

int64_t CheckRegularFile(const std::string& path) {
  if (path.empty()) ThrowInputError("", "", "", "empty input path");
  struct stat status {};
  if (stat(path.c_str(), &status) != 0) {
    ThrowInputError(path, "", "", fmt::format("cannot open the file ({})", std::strerror(errno)));
  }
  if (!S_ISREG(status.st_mode)) {
    ThrowInputError(path, "", "", fmt::format("is {}; only regular files are read", KindOf(status.st_mode)));
  }
  return static_cast<int64_t>(status.st_size);
}

std::string ReadRegularFile(const std::string& path, int64_t max_bytes) {
  const int64_t size = CheckRegularFile(path);
  if (size > max_bytes) {
    ThrowInputError(path, "", "",
                    fmt::format("{} bytes is more than the {} bytes accepted", size, max_bytes));
  }
  CheckMemoryBudget(size, fmt::format("{}: reading the file", path));
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!file) ThrowInputError(path, "", "", "cannot open the file (missing or not readable)");
  std::string text(static_cast<size_t>(size), '\0');
  if (size > 0 && std::fread(text.data(), 1, text.size(), file.get()) != text.size()) {
    ThrowInputError(path, "", "", "read error (the file shrank while being read?)");
  }
  return text;
}

}  // namespace lidarshop
