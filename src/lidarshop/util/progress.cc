#include "lidarshop/util/progress.h"

#include <unistd.h>

#include <cstdio>

#include <fmt/format.h>

#include "lidarshop/util/error.h"

namespace lidarshop {

Progress::Progress(std::string label, int64_t total, bool enabled)
    : label_(std::move(label)), total_(total), enabled_(enabled) {
  start_ = std::chrono::steady_clock::now();
  last_draw_ = start_ - std::chrono::seconds(1);
}

Progress::~Progress() { Finish(); }

std::unique_ptr<Progress> Progress::ForTerminal(std::string label, int64_t total, bool quiet) {
  const bool enabled = !quiet && isatty(fileno(stderr)) != 0;
  return std::make_unique<Progress>(std::move(label), total, enabled);
}

int64_t Progress::total() const {
  std::lock_guard lock(draw_mutex_);
  return total_;
}

std::string Progress::label() const {
  std::lock_guard lock(draw_mutex_);
  return label_;
}

void Progress::Advance(int64_t amount) {
  if (cancelled_.load(std::memory_order_relaxed)) throw CancelledError("cancelled");
  done_.fetch_add(amount, std::memory_order_relaxed);
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - last_draw_ < std::chrono::milliseconds(100)) return;
  std::unique_lock lock(draw_mutex_, std::try_to_lock);
  if (!lock.owns_lock()) return;
  last_draw_ = now;
  Draw(false);
}

void Progress::Restart(std::string label, int64_t total) {
  Finish();
  std::lock_guard lock(draw_mutex_);
  label_ = std::move(label);
  total_ = total;
  done_ = 0;
  finished_ = false;
  start_ = std::chrono::steady_clock::now();
}

void Progress::Finish() {
  std::lock_guard lock(draw_mutex_);
  if (finished_) return;
  finished_ = true;
  if (enabled_) Draw(true);
}

void Progress::Draw(bool final) {
  const int64_t done = std::min(done_.load(), total_);
  const double fraction = total_ > 0 ? static_cast<double>(done) / static_cast<double>(total_) : 1.0;
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  constexpr int kWidth = 30;
  const int filled = static_cast<int>(fraction * kWidth);
  std::string bar(filled, '#');
  bar.resize(kWidth, '.');
  fmt::print(stderr, "\r{:<24} [{}] {:5.1f}% {:6.1f}s{}", label_, bar, 100.0 * fraction, seconds,
             final ? "\n" : "");
  std::fflush(stderr);
}

}  // namespace lidarshop
