// lidarshop's OpenCV plugin (src/plugins): OpenCV's image codecs and ximgproc, loaded the first time a command
// reads or writes a picture or computes superpixels. Debian links libopencv_imgcodecs against GDAL and ~120
// more shared libraries; linked into the executable they cost every command 0.1 s and 45 MB before it starts.
// The plugin is looked for at $LIDARSHOP_OPENCV_PLUGIN, where the build wrote it, where it is installed
// (LIBDIR/lidarshop), then beside the executable.
#pragma once

namespace lidarshop {

// The address of the plugin's function `name` (a C name, e.g. "lidarshop_imread"), the plugin loaded on first
// use (thread-safe). Throws std::runtime_error naming the places tried when the plugin or the name is missing.
void* OpenCvPluginSymbol(const char* name);

// Casts OpenCvPluginSymbol(name) to the function type F.
template <class F>
F* OpenCvPluginFunction(const char* name) {
  return reinterpret_cast<F*>(OpenCvPluginSymbol(name));
}

}  // namespace lidarshop
