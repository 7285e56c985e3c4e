// `lidarshop batch`: a pipeline of commands over many scans, locally or on a Dask cluster. The driver is
// Python (src/python/lidarshop_batch.py, copied into build/<preset>/python): Dask is a Python library, so the
// library stays free of it. The driver runs this executable again once per scan, as `lidarshop steps`
// (steps_command.cc: every step of the scan in that one process, each through the same dispatch as `lidarshop
// COMMAND`). This command only starts the driver with this executable as the one to run.
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "lidarshop/cli/commands.h"

namespace lidarshop::cli {

int RunBatch(int argc, char** argv) {
#if defined(LIDARSHOP_PYTHON_EXECUTABLE) && defined(LIDARSHOP_PYTHON_DIR)
  // LIDARSHOP_PYTHON_DIR: where lidarshop_batch.py is (the build's python folder unless set in the environment).
  const char* env_dir = std::getenv("LIDARSHOP_PYTHON_DIR");
  const std::string python_dir = env_dir != nullptr && *env_dir != '\0' ? env_dir : LIDARSHOP_PYTHON_DIR;
  const char* old_path = std::getenv("PYTHONPATH");
  const std::string python_path =
      old_path != nullptr && *old_path != '\0' ? python_dir + ":" + old_path : python_dir;
  setenv("PYTHONPATH", python_path.c_str(), 1);
  char self[4096];
  const ssize_t length = readlink("/proc/self/exe", self, sizeof(self) - 1);
  std::vector<std::string> arguments = {LIDARSHOP_PYTHON_EXECUTABLE, "-m", "lidarshop_batch"};
  if (length > 0) {
    self[length] = '\0';
    arguments.push_back(std::string("--lidarshop=") + self);
  }
  for (int i = 1; i < argc; ++i) arguments.push_back(argv[i]);
  std::vector<char*> pointers;
  for (std::string& argument : arguments) pointers.push_back(argument.data());
  pointers.push_back(nullptr);
  execv(pointers[0], pointers.data());
  fmt::print(stderr, "lidarshop batch: cannot start {}: {}\n", pointers[0], std::strerror(errno));
  return 1;
#else
  fmt::print(stderr,
             "lidarshop batch: this lidarshop was built without Python (LIDARSHOP_BUILD_PYTHON=OFF)\n");
  return 2;
#endif
}

}  // namespace lidarshop::cli
