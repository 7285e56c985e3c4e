// Running command lines of the `lidarshop` executable in this process: one (the dispatch of main.cc, which
// `main` and `steps` share) or several in turn (`lidarshop steps`).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "lidarshop/util/options_fwd.h"

namespace lidarshop::cli {

// Runs the command argv[0] ("fill") with its arguments as `lidarshop fill ...` would, through the command table
// of main.cc: its own flags, checks, messages and exit code; what escapes RunCommand (an allocation failing
// while an error is reported) becomes one line here. An unknown name: one line, exit code 2 (kExitUsage).
int RunCommandLine(int argc, char** argv);

// `lidarshop steps STEPS.json`: several command lines in turn (steps_command.cc).
int RunSteps(int argc, char** argv);

// One step of `lidarshop steps`' report: listed when it starts, its outcome filled in when it ends (a step
// that ended the process keeps exit, seconds and message null).
struct StepReport {
  std::string command;                 // the step's command ("fill")
  std::optional<int> exit;             // its exit code
  std::optional<double> seconds;       // its wall time, seconds
  std::optional<std::string> message;  // its last line on stderr that is not blank
  int64_t stderr_offset = 0;           // bytes this process had written to stderr before the step
};

// `lidarshop steps --json`: the steps run so far (rewritten before and after every step when it goes to a
// file) and the exit code of the whole, null until the last step ended.
struct StepsReport {
  std::vector<StepReport> steps;
  std::optional<int> exit;  // the failed step's, 0 when all succeeded
};

}  // namespace lidarshop::cli

namespace lidarshop {
template <>
const StructInfo& InfoOf<cli::StepReport>();  // steps_command.cc
template <>
const StructInfo& InfoOf<cli::StepsReport>();
}  // namespace lidarshop
