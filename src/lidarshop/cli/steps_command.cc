// `lidarshop steps STEPS.json`: several commands one after the other in this one process, as `lidarshop
// COMMAND ARGS...` would run each (the dispatch of main.cc, RunCommandLine), stopping at the first that fails.
// `lidarshop batch` runs one of these per scan: the process starts once (the executable's libraries, OpenCV's
// plugin on the first picture) instead of once per step, and a crash or a memory blow-up still ends only the
// scan's process, not the batch's worker. What one command leaves in the process is reset before the next: the
// memory budget (to what `steps` itself was given) and the protected inputs (util/atomic_file.h: an --options
// file, the FILE of FILE#N); the CLI11 app, its flags and the summary line are made anew by every command.
#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "lidarshop/cli/command_line.h"
#include "lidarshop/cli/commands.h"
#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/input_file.h"
#include "lidarshop/util/memory_budget.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/timer.h"

namespace lidarshop::cli {
namespace {

// Commands that cannot be a step: `batch` replaces the process with Python, `serve` runs until interrupted,
// `steps` would nest.
bool CannotBeAStep(const std::string& command) {
  return command == "batch" || command == "serve" || command == "steps";
}

// STEPS.json: {"steps": [["fill", "in.ptx", "--mask", "m.png", "-o", "out.e57"], ["convert", ...], ...]}.
std::vector<std::vector<std::string>> ReadSteps(const std::string& path) {
  nlohmann::json json;
  try {
    json = nlohmann::json::parse(ReadRegularFile(path, int64_t{64} << 20));
  } catch (const nlohmann::json::exception& error) {
    ThrowInputError(path, "", "", fmt::format("not JSON: {}", error.what()));
  }
  if (!json.is_object() || !json.contains("steps") || !json["steps"].is_array() || json["steps"].empty()) {
    ThrowInputError(path, "", "steps",
                    "expected {\"steps\": [[\"COMMAND\", \"ARG\", ...], ...]}, at least one");
  }
  std::vector<std::vector<std::string>> steps;
  for (size_t i = 0; i < json["steps"].size(); ++i) {
    const nlohmann::json& step = json["steps"][i];
    const std::string where = fmt::format("steps[{}]", i);
    if (!step.is_array() || step.empty() || !step[0].is_string()) {
      ThrowInputError(path, "", where, "expected [\"COMMAND\", \"ARG\", ...]");
    }
    std::vector<std::string> argv;
    for (const nlohmann::json& argument : step) {
      if (!argument.is_string()) ThrowInputError(path, "", where, "every argument must be a string");
      argv.push_back(argument.get<std::string>());
    }
    if (CannotBeAStep(argv[0])) {
      ThrowInputError(path, "", where, fmt::format("'{}' cannot be a step of `lidarshop steps`", argv[0]));
    }
    steps.push_back(std::move(argv));
  }
  return steps;
}

// The stderr of one command: fd 2 goes into a pipe that a thread copies to the real stderr as it comes, keeping
// the last line that is not blank (what `batch` puts in a failed scan's error). Without a pipe (no descriptors
// left) the command writes to stderr directly and no line is kept.
class StderrTap {
 public:
  StderrTap() {
    std::fflush(stderr);
    std::clog.flush();
    int fds[2];
    if (pipe2(fds, O_CLOEXEC) != 0) return;
    saved_ = fcntl(2, F_DUPFD_CLOEXEC, 3);
    if (saved_ < 0 || dup2(fds[1], 2) < 0) {
      if (saved_ >= 0) close(saved_);
      saved_ = -1;
      close(fds[0]);
      close(fds[1]);
      return;
    }
    close(fds[1]);
    read_ = fds[0];
    thread_ = std::thread([this] { Copy(); });
    // A command that calls exit() (a bad LIDARSHOP_SIMD) ends the process: what it said is copied first.
    static const bool drained_at_exit = std::atexit([] {
                                          if (StderrTap* tap = active_.load()) tap->Finish();
                                        }) == 0;
    (void)drained_at_exit;
    active_ = this;
  }
  ~StderrTap() { Finish(); }
  StderrTap(const StderrTap&) = delete;
  StderrTap& operator=(const StderrTap&) = delete;

  // Puts fd 2 back; returns the last line that is not blank, without its trailing white space.
  std::string Finish() {
    if (saved_ >= 0) {
      active_ = nullptr;
      std::fflush(stderr);
      std::clog.flush();
      dup2(saved_, 2);  // closes the pipe's write end: the thread copies the rest, then sees its end
      thread_.join();
      close(saved_);
      saved_ = -1;
      close(read_);
      EndLine();
    }
    return last_line_;
  }
  int64_t bytes() const { return bytes_; }

 private:
  void Copy() {
    char buffer[4096];
    for (;;) {
      const ssize_t got = read(read_, buffer, sizeof(buffer));
      if (got < 0 && errno == EINTR) continue;
      if (got <= 0) return;
      for (ssize_t done = 0; done < got;) {
        const ssize_t wrote = write(saved_, buffer + done, static_cast<size_t>(got - done));
        if (wrote < 0 && errno == EINTR) continue;
        if (wrote <= 0) break;  // the real stderr is gone: keep reading, so that the command never blocks
        done += wrote;
      }
      bytes_ += got;
      for (ssize_t i = 0; i < got; ++i) {
        if (buffer[i] == '\n' || buffer[i] == '\r') {
          EndLine();
        } else {
          line_ += buffer[i];
        }
      }
    }
  }
  void EndLine() {
    const size_t end = line_.find_last_not_of(" \t\v\f");
    if (end != std::string::npos) last_line_ = line_.substr(0, end + 1);
    line_.clear();
  }

  static inline std::atomic<StderrTap*> active_{nullptr};  // the tap of the running command
  int saved_ = -1;                                         // the real stderr
  int read_ = -1;
  std::thread thread_;
  std::string line_;
  std::string last_line_;
  int64_t bytes_ = 0;
};

}  // namespace

int RunSteps(int argc, char** argv) {
  CLI::App app{
      "Run several lidarshop commands one after the other in this process, each as `lidarshop COMMAND "
      "ARGS...` "
      "would (its flags, checks, messages and exit code), stopping at the first that fails. STEPS.json: "
      "{\"steps\": [[\"fill\", \"in.ptx\", \"--mask\", \"m.png\", \"-o\", \"filled.e57\"], [\"convert\", "
      "\"filled.e57\", \"filled.ply\"]]}. The report (--json) has per step: command, exit, seconds, message "
      "(its last line on stderr) and stderr_offset (the bytes this process had written to stderr before it); "
      "a file is rewritten before and after every step, so that a step that ended the process shows as "
      "\"exit\": null. Exit code: the failed step's, 0 when all succeed. `lidarshop batch` runs one per "
      "scan.",
      "steps"};
  std::string steps_path;
  std::string json_path = "-";
  app.add_option("STEPS", steps_path, "the steps (JSON)")->required()->type_name("FILE");
  AddJsonOption(app, &json_path, "--json,--report");
  return RunCommand(app, argc, argv, [&] {
    CheckOutputFile("--json", json_path, {"json"}, {steps_path});
    const std::vector<std::vector<std::string>> steps = ReadSteps(steps_path);
    const int64_t budget = MemoryBudgetBytes();  // `steps`' own --max-memory, or the default
    StepsReport report;
    const bool to_file = json_path != "-";
    int64_t stderr_offset = 0;
    int code = kExitOk;
    for (const std::vector<std::string>& step : steps) {
      StepReport& entry = report.steps.emplace_back();
      entry.command = step[0];
      entry.stderr_offset = stderr_offset;
      if (to_file) WriteJsonOutput(json_path, ToJson(report));
      SetMemoryBudgetBytes(budget);
      ForgetProtectedInputs();
      std::vector<std::string> arguments = step;
      std::vector<char*> pointers;
      for (std::string& argument : arguments) pointers.push_back(argument.data());
      pointers.push_back(nullptr);
      const Timer timer;
      StderrTap tap;
      code = RunCommandLine(static_cast<int>(arguments.size()), pointers.data());
      const std::string message = tap.Finish();
      entry.exit = code;
      entry.seconds = timer.Seconds();
      entry.message = message;
      stderr_offset += tap.bytes();
      if (code != kExitOk) break;
    }
    report.exit = code;
    WriteJsonOutput(json_path, ToJson(report));
    if (code == kExitOk) Summarize(fmt::format("ran {} step(s)", steps.size()));
    return code;
  });
}

}  // namespace lidarshop::cli

namespace lidarshop {

template <>
const StructInfo& InfoOf<cli::StepReport>() {
  static const StructInfo info = [] {
    using Step = cli::StepReport;
    StructBuilder<Step> b("StepReport", "a step of steps --json (null: it has not ended)");
    b.Field(&Step::command, "command", "the step's command");
    b.Field(&Step::exit, "exit", "its exit code").NullWhenAbsent();
    b.Field(&Step::seconds, "seconds", "its wall time").Unit("s").NullWhenAbsent();
    b.Field(&Step::message, "message", "its last line on stderr that is not blank").NullWhenAbsent();
    b.Field(&Step::stderr_offset, "stderr_offset", "bytes this process had written to stderr before it")
        .Unit("bytes");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<cli::StepsReport>() {
  static const StructInfo info = [] {
    StructBuilder<cli::StepsReport> b("StepsReport", "the --json of steps: the steps run so far");
    b.Field(&cli::StepsReport::steps, "steps", "the steps started, in order");
    b.Field(&cli::StepsReport::exit, "exit",
            "the failed step's exit code, 0 when all succeeded; null until the end")
        .NullWhenAbsent();
    return b.Build();
  }();
  return info;
}

}  // namespace lidarshop
