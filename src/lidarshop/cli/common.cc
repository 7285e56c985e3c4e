#include <exception>

#include <fmt/format.h>

#include "lidarshop/cli/commands.h"

namespace lidarshop::cli {

int RunCommand(CLI::App& app, int argc, char** argv, const std::function<int()>& body) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    return app.exit(error);
  }
  try {
    return body();
  } catch (const std::exception& error) {
    fmt::print(stderr, "lidarshop {}: {}\n", app.get_name(), error.what());
    return 1;
  }
}

void AddQuietFlag(CLI::App& app, bool* quiet) {
  app.add_flag("-q,--quiet", *quiet, "no progress output");
}

}  // namespace lidarshop::cli
