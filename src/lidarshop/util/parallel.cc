#include "lidarshop/util/parallel.h"

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

namespace lidarshop {

void ParallelForRange(int64_t count, const std::function<void(int64_t, int64_t)>& body, int64_t grain) {
  if (count <= 0) return;
  tbb::parallel_for(tbb::blocked_range<int64_t>(0, count, std::max<int64_t>(1, grain)),
                    [&](const tbb::blocked_range<int64_t>& range) { body(range.begin(), range.end()); });
}

void ParallelFor(int64_t count, const std::function<void(int64_t)>& body, int64_t grain) {
  ParallelForRange(
      count,
      [&](int64_t begin, int64_t end) {
        for (int64_t i = begin; i < end; ++i) body(i);
      },
      grain);
}

ThreadLimit::ThreadLimit(int threads) {
  if (threads > 0) {
    control_ =
        new tbb::global_control(tbb::global_control::max_allowed_parallelism, static_cast<size_t>(threads));
  }
}

ThreadLimit::~ThreadLimit() { delete static_cast<tbb::global_control*>(control_); }

}  // namespace lidarshop
