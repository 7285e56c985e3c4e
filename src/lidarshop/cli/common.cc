#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <exception>
#include <filesystem>
#include <iostream>
#include <new>
#include <optional>

#include <fmt/format.h>
#include <opencv2/core.hpp>

#include "lidarshop/cli/commands.h"
#include "lidarshop/cli/options_cli.h"
#include "lidarshop/cli/scan_selector.h"
#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/memory_budget.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/timer.h"

namespace lidarshop::cli {

namespace {

// Every long name of `app` and its subcommands ("--channel").
void CollectFlags(const CLI::App& app, std::vector<std::string>* flags) {
  for (const CLI::Option* option : app.get_options()) {
    for (const std::string& name : option->get_lnames()) flags->push_back("--" + name);
  }
  for (const CLI::App* sub : app.get_subcommands({})) CollectFlags(*sub, flags);
}

// "unknown option --chanel (did you mean --channel?)" for the first unexpected argument.
std::string ExtrasMessage(const CLI::App& app) {
  const std::vector<std::string> extras = app.remaining(true);
  if (extras.empty()) return "unexpected arguments";
  const std::string& first = extras.front();
  if (first.rfind("-", 0) != 0) return fmt::format("unexpected argument '{}'", first);
  std::vector<std::string> flags;
  CollectFlags(app, &flags);
  const std::string name = first.substr(0, first.find('='));
  const std::string closest = ClosestMatch(name, flags);
  return fmt::format("unknown option {}{}", name,
                     closest.empty() ? "" : fmt::format(" (did you mean {}?)", closest));
}

// One line of a library's exception: the first line, and OpenCV's message without its source location.
std::string OneLine(const std::exception& error) {
  std::string text = error.what();
  if (const auto* cv_error = dynamic_cast<const cv::Exception*>(&error)) {
    text = fmt::format("OpenCV: {}{}", cv_error->err,
                       cv_error->func.empty() ? "" : fmt::format(" (in {})", cv_error->func));
  }
  const size_t newline = text.find('\n');
  if (newline != std::string::npos) text = text.substr(0, newline);
  return text;
}

// The command being run (RunCommand) and the summary its body left (Summarize): one command per process.
struct CommandReport {
  std::string name;  // "lidarshop fill"
  std::optional<std::string> summary;
};
CommandReport& Report() {
  static CommandReport report;
  return report;
}

}  // namespace

void Summarize(std::string what) { Report().summary = std::move(what); }

void PrintResultWarnings(const std::vector<std::string>& warnings) {
  const std::string& name = Report().name.empty() ? std::string("lidarshop") : Report().name;
  for (const std::string& warning : warnings) fmt::print(stderr, "{}: warning: {}\n", name, warning);
}

int RunCommand(CLI::App& app, int argc, char** argv, const std::function<int()>& body,
               const OptionBinder* binder) {
  const std::string name = "lidarshop " + app.get_name();
  Report() = {name, std::nullopt};
  // Every command takes --max-memory and --quiet (README), also those that have no progress to hide.
  if (app.get_option_no_throw("--max-memory") == nullptr) AddMemoryOption(app);
  if (app.get_option_no_throw("--quiet") == nullptr)
    app.add_flag("-q,--quiet")->description("no summary line (warnings and errors still print)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& help) {
    return app.exit(help);
  } catch (const CLI::CallForAllHelp& help) {
    return app.exit(help);
  } catch (const CLI::CallForVersion& version) {
    return app.exit(version);
  } catch (const CLI::ExtrasError&) {
    fmt::print(stderr, "{}: {} (see --help)\n", name, ExtrasMessage(app));
    return kExitUsage;
  } catch (const CLI::ParseError& error) {
    fmt::print(stderr, "{}: {} (see --help)\n", name, error.what());
    return kExitUsage;
  }
  try {
    const Timer timer;
    const int code = body();
    const CLI::Option* quiet = app.get_option_no_throw("--quiet");
    if (code == kExitOk && Report().summary && (quiet == nullptr || quiet->count() == 0))
      fmt::print(stderr, "{}: {} ({:.2f} s)\n", name, *Report().summary, timer.Seconds());
    return code;
  } catch (const OptionsFieldError& error) {
    const std::string message =
        binder != nullptr ? binder->Reworded(error).what() : std::string(error.what());
    fmt::print(stderr, "{}: {}\n", name, message);
    return kExitUsage;
  } catch (const OptionsError& error) {
    fmt::print(stderr, "{}: {}\n", name, OneLine(error));
    return kExitUsage;
  } catch (const std::bad_alloc&) {
    // An allocation no check foresaw: say what ran out and what bounds it, never a bare "std::bad_alloc".
    fmt::print(stderr,
               "{}: out of memory: an allocation failed (the memory budget is {} MiB; a smaller --max-memory "
               "makes large requests fail up front, or free memory and retry)\n",
               name, MemoryBudgetBytes() >> 20);
    return kExitBadInput;
  } catch (const std::exception& error) {
    fmt::print(stderr, "{}: {}\n", name, OneLine(error));
    return kExitBadInput;
  }
}

nlohmann::ordered_json CommandJson(const nlohmann::ordered_json& options,
                                   const nlohmann::ordered_json& result) {
  nlohmann::ordered_json json = result;
  json.update(ToJson(CommandOptions{options}));  // after the result's keys (in its place if it had one)
  return json;
}

CLI::Option* AddJsonOption(CLI::App& app, std::string* path, const std::string& names) {
  CLI::Option* option =
      app.add_option(names, *path, "write the result as JSON to FILE ('-' = stdout)")->type_name("FILE");
  if (!path->empty()) option->capture_default_str();
  return option;
}

std::string DumpWithInlineArrays(const nlohmann::ordered_json& json, int indent, int depth) {
  const bool scalar_array = json.is_array() && std::none_of(json.begin(), json.end(), [](const auto& item) {
                              return item.is_structured();
                            });
  if (!json.is_structured() || json.empty() || indent < 0) return json.dump(indent);
  std::string out;
  if (scalar_array) {
    out = "[";
    for (size_t i = 0; i < json.size(); ++i) out += (i ? ", " : "") + json[i].dump();
    return out + "]";
  }
  const std::string inner(static_cast<size_t>(indent * (depth + 1)), ' ');
  out = json.is_object() ? "{\n" : "[\n";
  bool first = true;
  for (auto it = json.begin(); it != json.end(); ++it) {
    out += first ? "" : ",\n";
    first = false;
    out += inner;
    if (json.is_object()) out += nlohmann::ordered_json(it.key()).dump() + ": ";
    out += DumpWithInlineArrays(it.value(), indent, depth + 1);
  }
  out += "\n" + std::string(static_cast<size_t>(indent * depth), ' ') + (json.is_object() ? "}" : "]");
  return out;
}

void WriteJsonOutput(const std::string& path, const nlohmann::ordered_json& json, int indent,
                     bool inline_arrays) {
  if (path.empty()) return;
  const std::string text = inline_arrays ? DumpWithInlineArrays(json, indent) : json.dump(indent);
  if (path == "-") {
    errno = 0;
    std::cout << text << "\n" << std::flush;
    if (!std::cout) {
      const int saved_errno = errno;
      std::cout.clear();
      throw InputError(fmt::format("cannot write the JSON to stdout: {}",
                                   saved_errno == ENOSPC ? std::string("no space left on device")
                                   : saved_errno != 0    ? std::string(std::strerror(saved_errno))
                                                         : std::string("the stream failed")));
    }
    return;
  }
  WriteFileAtomically(path, [&](std::ostream& out) { out << text << "\n"; });
}

void CheckOutputFile(const std::string& flag, const std::string& path,
                     const std::vector<std::string>& extensions, const std::vector<std::string>& others) {
  if (path.empty() || path == "-") return;
  const std::string extension = FileExtension(path);
  if (!extensions.empty() && std::find(extensions.begin(), extensions.end(), extension) == extensions.end()) {
    throw OptionsError(fmt::format("{} {}: expected a .{} file", flag, path, fmt::join(extensions, ", .")));
  }
  try {
    CheckOutputPath(path, others);
  } catch (const OptionsError& error) {
    throw OptionsError(fmt::format("{} {}", flag, error.what()));
  }
  std::filesystem::path folder = std::filesystem::path(path).parent_path();
  if (folder.empty()) folder = ".";
  if (access(folder.c_str(), W_OK) != 0) {
    throw OptionsError(fmt::format("{} {}: the folder {} is not writable", flag, path, folder.string()));
  }
}

void PrintWarnings(const std::vector<std::string>& warnings) {
  for (const std::string& warning : warnings) fmt::print(stderr, "lidarshop: warning: {}\n", warning);
}

ScanSelector SplitScanSelector(const std::string& path) {
  std::error_code not_a_file;
  const size_t hash = path.rfind('#');
  if (hash == std::string::npos || hash == 0 || std::filesystem::exists(path, not_a_file)) return {path, -1};
  const std::string digits = path.substr(hash + 1);
  int index = -1;
  const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), index);
  if (digits.empty() || error != std::errc() || end != digits.data() + digits.size() || index < 0) {
    return {path, -1};
  }
  return {path.substr(0, hash), index};
}

std::string StationOutputName(const std::string& input) {
  const ScanSelector selector = SplitScanSelector(input);
  const std::filesystem::path path(selector.path);
  if (selector.index < 0) return path.filename().string();
  return fmt::format("{}_{}{}", path.stem().string(), selector.index, path.extension().string());
}

ScanFile ReadScanFileAndWarn(const std::string& path) {
  const ScanSelector selector = SplitScanSelector(path);
  if (selector.index >= 0) ProtectInput(selector.path);  // no output may replace FILE of FILE#N
  ScanFile file = ReadScanFile(selector.path);
  PrintWarnings(file.warnings);
  if (selector.index >= 0) {
    if (selector.index >= static_cast<int>(file.scans.size())) {
      throw OptionsError(fmt::format("{}: scan {} is out of range: {} holds {} scan(s), numbered from 0",
                                     path, selector.index, selector.path, file.scans.size()));
    }
    std::vector<Scan> one = {std::move(file.scans[selector.index])};
    file.scans = std::move(one);
    file.path = path;
  }
  return file;
}

E57File ReadE57AndWarn(const std::string& path) {
  E57File file = ReadE57(path);
  PrintWarnings(file.warnings);
  return file;
}

TriangleMesh ReadMeshAndWarn(const std::string& path) {
  MeshFile file = ReadMeshFile(path);
  PrintWarnings(file.warnings);
  return std::move(file.mesh);
}

const Scan& PickScan(const ScanFile& file, int index, const std::string& flag) {
  if (index < 0 || index >= static_cast<int>(file.scans.size())) {
    throw OptionsError(fmt::format("{} {} is out of range: {} holds {} scan(s), numbered from 0", flag, index,
                                   file.path, file.scans.size()));
  }
  return file.scans[index];
}

void AddScanIndexOption(CLI::App& app, int* index, const std::string& help) {
  CLI::Option* scan = app.add_option("--scan", *index, help)->capture_default_str();
  app.add_option("--scan-index", *index, "= --scan (its older name)")->excludes(scan);
}

std::string ScanIndexFlag(const CLI::App& app) {
  return app.count("--scan-index") > 0 ? "--scan-index" : "--scan";
}

void AddQuietFlag(CLI::App& app, bool* quiet) {
  app.add_flag("-q,--quiet", *quiet,
               "no progress output and no summary line (warnings and errors still print)");
  AddMemoryOption(app);
}

void AddMemoryOption(CLI::App& app) {
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

namespace lidarshop {

template <>
const StructInfo& InfoOf<cli::CommandOptions>() {
  static const StructInfo info = [] {
    StructBuilder<cli::CommandOptions> b("CommandOptions", "the end of every command's --json");
    b.Field(&cli::CommandOptions::options, "options",
            "the options it ran with: its options struct's JSON form (docs/options.md, \"What each command "
            "accepts\")");
    return b.Build();
  }();
  return info;
}

}  // namespace lidarshop
