#include "lidarshop/util/plugin.h"

#include <dlfcn.h>
#include <unistd.h>

#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace lidarshop {
namespace {

constexpr const char* kPluginFile = "liblidarshop_opencv_plugin.so";

// The folder of the running executable ("" when /proc is not there).
std::string ExecutableFolder() {
  std::vector<char> path(4096);
  const ssize_t length = readlink("/proc/self/exe", path.data(), path.size() - 1);
  if (length <= 0) return "";
  const std::string exe(path.data(), static_cast<size_t>(length));
  return exe.substr(0, exe.rfind('/'));
}

void* LoadPlugin() {
  std::vector<std::string> tried;
  if (const char* given = std::getenv("LIDARSHOP_OPENCV_PLUGIN"); given != nullptr && *given != '\0')
    tried.push_back(given);
#ifdef LIDARSHOP_OPENCV_PLUGIN_PATH
  tried.push_back(LIDARSHOP_OPENCV_PLUGIN_PATH);
#endif
#ifdef LIDARSHOP_OPENCV_PLUGIN_INSTALLED_PATH
  tried.push_back(LIDARSHOP_OPENCV_PLUGIN_INSTALLED_PATH);
#endif
  if (const std::string folder = ExecutableFolder(); !folder.empty())
    tried.push_back(folder + "/" + kPluginFile);
  std::string errors;
  for (const std::string& path : tried) {
    if (void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL)) return handle;
    const char* error = dlerror();
    errors += fmt::format("; {}", error != nullptr ? error : path);
  }
  throw std::runtime_error(
      fmt::format("cannot load lidarshop's OpenCV plugin {} (image codecs, superpixels): tried {}{}",
                  kPluginFile, fmt::join(tried, ", "), errors));
}

}  // namespace

void* OpenCvPluginSymbol(const char* name) {
  static void* const handle = LoadPlugin();
  dlerror();
  void* symbol = dlsym(handle, name);
  if (symbol == nullptr)
    throw std::runtime_error(fmt::format("lidarshop's OpenCV plugin has no function {}", name));
  return symbol;
}

}  // namespace lidarshop
