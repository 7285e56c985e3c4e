// lidarshop serve: the editor in the browser (src/server, docs/api.md, web/).
//
//   lidarshop serve [SCAN...] [--scene NAME] [--port 8080] [--host 127.0.0.1] [--root DIR...] [--web DIR]
#include <malloc.h>
#include <pthread.h>
#include <sys/resource.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <limits>
#include <mutex>
#include <thread>

#include <fmt/format.h>

#include "lidarshop/cli/commands.h"
#include "lidarshop/scanner/builtin_scenes.h"
#include "lidarshop/scanner/scanner.h"
#include "lidarshop/scanner/scene.h"
#include "lidarshop/scanner/site_scan.h"
#include "lidarshop/util/error.h"
#include "server.h"

namespace lidarshop::cli {

namespace {

sigset_t StopSignals() {
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  return signals;
}

// SIGINT and SIGTERM are taken by one thread (sigwait), not by a handler: httplib's stop() is not
// async-signal-safe, and a stop asked for before Run() has begun listening is not seen by httplib (a handler
// calling it then left `serve` running for ever after a script's TERM). Before the server serves, a signal
// ends the process as it would by default (a station may take a minute to read); once it serves, the thread
// calls Stop() until Run() has returned. The signals must be blocked (BlockStopSignals) before any thread is
// made, so that every thread inherits the block and only this one receives them.
class StopOnSignals {
 public:
  explicit StopOnSignals(server::EditorServer& editor) : editor_(editor), thread_([this] { Wait(); }) {}
  ~StopOnSignals() {
    returned_ = true;
    pthread_kill(thread_.native_handle(), SIGTERM);  // wakes the sigwait if no signal came
    thread_.join();
  }
  StopOnSignals(const StopOnSignals&) = delete;
  StopOnSignals& operator=(const StopOnSignals&) = delete;

  // From now on a signal stops the server instead of ending the process.
  void Serving() {
    std::lock_guard lock(mutex_);
    serving_ = true;
  }

 private:
  void Wait() {
    const sigset_t signals = StopSignals();
    int signal = 0;
    if (sigwait(&signals, &signal) != 0 || returned_) return;
    {
      std::lock_guard lock(mutex_);
      if (!serving_) {
        std::signal(signal, SIG_DFL);
        pthread_sigmask(SIG_UNBLOCK, &signals, nullptr);
        raise(signal);  // delivered to this thread, whose mask no longer blocks it
        return;
      }
    }
    while (!returned_) {
      editor_.Stop();
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }

  server::EditorServer& editor_;
  std::mutex mutex_;
  bool serving_ = false;  // guarded by mutex_
  std::atomic<bool> returned_ = false;
  std::thread thread_;  // last: it starts once the members it reads exist
};

// The editor cuts, paints and fills a station again and again, and each edit makes buffers of the station's
// size (a mask of a 100 M-ray station is 100 MB). glibc gives allocations that large pages of their own (mmap)
// and returns them when they are freed, so every new one is fresh memory, which the VMs we run on zero at
// its first touch (3.5 s a GiB, docs/memory.md): most of a live cut's time at 100 M. Served from the heap and
// kept there once freed, they are reused instead. The process keeps its high-water mark, as a server does.
void KeepLargeBuffersForReuse() {
  mallopt(M_MMAP_MAX, 0);
  mallopt(M_TRIM_THRESHOLD, std::numeric_limits<int>::max());
}

void BlockStopSignals() {
  const sigset_t signals = StopSignals();
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
}

// The built front end: web/ beside the executable (the build copies it there), else the source tree's build.
std::string DefaultWebDir(const char* argv0) {
  namespace fs = std::filesystem;
  std::error_code error;
  const fs::path exe = fs::canonical("/proc/self/exe", error);
  for (const fs::path& candidate :
       {exe.parent_path() / "web", fs::path(LIDARSHOP_SOURCE_DIR) / "web" / "dist"}) {
    if (fs::exists(candidate / "index.html", error)) return candidate.string();
  }
  return "";
}

}  // namespace

int RunServe(int argc, char** argv) {
  CLI::App app{
      "The editor in the browser: look at scans in 2-D and 3-D, paint strokes, segment, remove objects, "
      "undo, save (docs/api.md). Prints the URL to open; loopback only unless --host says otherwise.",
      "serve"};
  server::ServerOptions options;
  std::vector<std::string> scans;
  app.add_option("scans", scans, "scan files to open at start (their folders may be browsed)");
  app.add_option("--port", options.port, "TCP port; 0 = any free port")
      ->capture_default_str()
      ->check(CLI::Range(0, 65535));
  app.add_option("--host", options.host, "address to listen on (127.0.0.1 = this machine only)")
      ->capture_default_str();
  std::vector<std::string> scenes;
  app.add_option("--scene", scenes, "built-in scenes to scan and open at start (repeatable)");
  app.add_option("--root", options.roots, "a folder whose scan files the editor may open (repeatable)");
  app.add_option("--web", options.web_dir, "the built front end (default: web/ beside the executable)");
  app.add_option("--token", options.token, "the access token (default: a random one)");
  return RunCommand(app, argc, argv, [&]() {
    // Every open connection takes a descriptor: the soft limit (often 1024) is raised towards the hard one so
    // that the server's connection limit (4096) is the one in force.
    rlimit files{};
    if (getrlimit(RLIMIT_NOFILE, &files) == 0 && files.rlim_cur < files.rlim_max) {
      files.rlim_cur = std::min<rlim_t>(files.rlim_max, 8192);
      setrlimit(RLIMIT_NOFILE, &files);
    }
    BlockStopSignals();
    KeepLargeBuffersForReuse();
    if (options.web_dir.empty()) options.web_dir = DefaultWebDir(argv[0]);
    for (const BuiltinScene& scene : BuiltinScenes()) options.builtin_scenes.push_back(scene.name);
    options.scan_builtin = [](const std::string& name) {
      for (const BuiltinScene& scene : BuiltinScenes()) {
        if (name != scene.name) continue;
        const SceneDescription description =
            ParseScene(scene.json, fmt::format("built-in scene '{}'", name), "");
        return SyntheticScanner(description).Acquire(description.scanner);
      }
      throw InputError(fmt::format("no built-in scene '{}'", name));
    };
    // A site (parking_lot_stations) opened as a site: every station with the objects there.
    options.scan_builtin_stations = [](const std::string& name) {
      for (const BuiltinScene& scene : BuiltinScenes()) {
        if (name == scene.name)
          return ScanStations(ParseScene(scene.json, fmt::format("built-in scene '{}'", name), ""));
      }
      throw InputError(fmt::format("no built-in scene '{}'", name));
    };
    server::EditorServer editor(options);
    StopOnSignals stop_on_signals(editor);
    for (const std::string& scan : scans) {
      std::vector<std::string> warnings;
      editor.OpenAtStart(scan, &warnings);
      PrintWarnings(warnings);
    }
    for (const std::string& scene : scenes) editor.OpenScene(scene);
    editor.Bind();
    if (options.web_dir.empty()) {
      fmt::print(stderr,
                 "serve: no built front end found (run `bash scripts/build.sh`); the API alone is served\n");
    }
    stop_on_signals.Serving();
    fmt::print("{}\n", editor.Url());
    std::fflush(stdout);
    editor.Run();
    return 0;
  });
}

}  // namespace lidarshop::cli
