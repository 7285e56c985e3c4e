#include <charconv>
#include <exception>

#include <fmt/format.h>

#include "lidarshop/cli/commands.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/memory_budget.h"

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

const Scan& PickScan(const ScanFile& file, int index, const std::string& flag) {
  if (index < 0 || index >= static_cast<int>(file.scans.size())) {
    throw OptionsError(fmt::format("{} {} is out of range: {} holds {} scan(s), numbered from 0", flag, index,
                                   file.path, file.scans.size()));
  }
  return file.scans[index];
}

void AddQuietFlag(CLI::App& app, bool* quiet) {
  app.add_flag("-q,--quiet", *quiet, "no progress output");
  app.add_option_function<std::string>(
      "--max-memory",
      [](const std::string& text) {
        try {
          SetMemoryBudgetBytes(ParseMemorySize(text, "--max-memory"));
        } catch (const OptionsError& error) {
          throw CLI::ValidationError(error.what());  // a usage error like any other, one line
        }
      },
      "memory budget (e.g. 512M, 8G): larger requests fail up front; default half of the RAM");
}

void AddSeedOption(CLI::App& app, uint64_t* seed, const std::string& help) {
  app.add_option_function<std::string>(
         "--seed",
         [seed](const std::string& text) {
           uint64_t value = 0;
           const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
           if (error != std::errc() || end != text.data() + text.size() || value >= (uint64_t{1} << 63)) {
             throw CLI::ValidationError(fmt::format("--seed: '{}' is not a whole number in [0, 2^63)", text));
           }
           *seed = value;
         },
         help)
      ->default_str(std::to_string(*seed));
}

}  // namespace lidarshop::cli
