#include <exception>

#include <fmt/format.h>

#include "lidarshop/cli/commands.h"

namespace lidarshop::cli {

int RunCommand(CLI::App& app, int argc, char** argv, const std::function<int()>& body) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& help) {
    return app.exit(help);
  } catch (const CLI::CallForAllHelp& help) {
    return app.exit(help);
  } catch (const CLI::CallForVersion& version) {
    return app.exit(version);
  } catch (const CLI::ParseError& error) {
    // Usage errors are one line too, like every other failure.
    fmt::print(stderr, "lidarshop {}: {} (see --help)\n", app.get_name(), error.what());
    return error.get_exit_code() != 0 ? error.get_exit_code() : 2;
  }
  try {
    return body();
  } catch (const std::exception& error) {
    fmt::print(stderr, "lidarshop {}: {}\n", app.get_name(), error.what());
    return 1;
  }
}

void AddQuietFlag(CLI::App& app, bool* quiet) { app.add_flag("-q,--quiet", *quiet, "no progress output"); }

}  // namespace lidarshop::cli
