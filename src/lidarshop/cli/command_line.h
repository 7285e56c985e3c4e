// Running command lines of the `lidarshop` executable in this process: one (the dispatch of main.cc, which
// `main` and `steps` share) or several in turn (`lidarshop steps`).
#pragma once

namespace lidarshop::cli {

// Runs the command argv[0] ("fill") with its arguments as `lidarshop fill ...` would, through the command table
// of main.cc: its own flags, checks, messages and exit code; what escapes RunCommand (an allocation failing
// while an error is reported) becomes one line here. An unknown name: one line, exit code 2 (kExitUsage).
int RunCommandLine(int argc, char** argv);

// `lidarshop steps STEPS.json`: several command lines in turn (steps_command.cc).
int RunSteps(int argc, char** argv);

}  // namespace lidarshop::cli
