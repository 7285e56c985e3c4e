// Parallel loops over oneTBB. Hot loops are written as "for every cell / every row, independently", which is
// the shape a GPU back end would take over; results never depend on the thread count.
#pragma once

#include <cstdint>
#include <functional>

namespace lidarshop {

// Calls body(begin, end) on disjoint chunks covering [0, count). `grain` is the smallest chunk worth a task.
void ParallelForRange(int64_t count, const std::function<void(int64_t begin, int64_t end)>& body,
                      int64_t grain = 1);

// Calls body(i) for every i in [0, count).
void ParallelFor(int64_t count, const std::function<void(int64_t index)>& body, int64_t grain = 1);

// Limits the threads of every parallel loop started while the returned object lives (0 = all cores).
class ThreadLimit {
 public:
  explicit ThreadLimit(int threads);
  ~ThreadLimit();
  ThreadLimit(const ThreadLimit&) = delete;
  ThreadLimit& operator=(const ThreadLimit&) = delete;

 private:
  void* control_ = nullptr;
};

}  // namespace lidarshop
