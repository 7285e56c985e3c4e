// Placeholder until this command group is built; replace the whole file.
#include <fmt/format.h>

#include "lidarshop/cli/commands.h"

namespace lidarshop::cli {

int RunInpaint(int argc, char** argv) {
  fmt::print(stderr, "lidarshop {}: not built yet\n", argv[0]);
  return 1;
}

}  // namespace lidarshop::cli
