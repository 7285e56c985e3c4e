// Progress of long operations, shown on a terminal.
//
// A library function that may run for seconds takes a `Progress*` (nullptr = silent) and calls Advance() from
// any thread. The CLI makes one with `Progress::ForTerminal(label, total, quiet)`, which draws a bar on
// stderr only when stderr is a TTY and --quiet was not given, at most ~10 times a second.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>

namespace lidarshop {

class Progress {
 public:
  // A bar that draws on stderr when `enabled`. `total` is in whatever unit the caller advances by.
  Progress(std::string label, int64_t total, bool enabled);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  // Enabled iff !quiet and stderr is a terminal.
  static std::unique_ptr<Progress> ForTerminal(std::string label, int64_t total, bool quiet);

  // Thread-safe.
  void Advance(int64_t amount = 1);
  // Starts a new stage with its own label and total (the bar restarts).
  void Restart(std::string label, int64_t total);
  void Finish();

  int64_t done() const { return done_.load(); }
  int64_t total() const;
  std::string label() const;

  // Asks the operation to stop (from any thread): its next Advance() throws CancelledError, which unwinds it
  // (parallel loops pass the exception on). Used by the editor's cancel button.
  void Cancel() { cancelled_ = true; }
  bool cancelled() const { return cancelled_.load(); }

 private:
  void Draw(bool final);

  std::string label_;
  int64_t total_;
  bool enabled_;
  bool finished_ = false;
  std::atomic<int64_t> done_{0};
  std::atomic<bool> cancelled_{false};
  mutable std::mutex draw_mutex_;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
};

// Advances `progress` when it is not null.
inline void Advance(Progress* progress, int64_t amount = 1) {
  if (progress != nullptr) progress->Advance(amount);
}

}  // namespace lidarshop
