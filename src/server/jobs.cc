#include <exception>

#include "lidarshop/util/error.h"
#include "state.h"

namespace lidarshop::server {

JobRunner::JobRunner(int workers, int max_queued) : max_queued_(max_queued) {
  for (int i = 0; i < workers; ++i) workers_.emplace_back([this] { Work(); });
}

JobRunner::~JobRunner() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
    for (const auto& job : queue_) job->progress.Cancel();
    for (const auto& [id, job] : jobs_) job->progress.Cancel();
  }
  wake_.notify_all();
  for (std::thread& worker : workers_) worker.join();
}

bool JobRunner::Submit(std::shared_ptr<Job> job) {
  {
    std::lock_guard lock(mutex_);
    if (static_cast<int>(queue_.size()) >= max_queued_ || stopping_) return false;
    queue_.push_back(job);
    jobs_[job->id] = job;
    // Finished jobs are kept for polling; the oldest go once there are many.
    while (jobs_.size() > 512) {
      const auto oldest = jobs_.begin();
      if (oldest->second->state == JobState::kQueued || oldest->second->state == JobState::kRunning) break;
      jobs_.erase(oldest);
    }
  }
  wake_.notify_one();
  return true;
}

std::shared_ptr<Job> JobRunner::Find(int id) const {
  std::lock_guard lock(mutex_);
  const auto found = jobs_.find(id);
  return found == jobs_.end() ? nullptr : found->second;
}

void JobRunner::Work() {
  while (true) {
    std::shared_ptr<Job> job;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
      if (stopping_) return;
      job = queue_.front();
      queue_.pop_front();
    }
    if (job->progress.cancelled()) {
      job->End(JobState::kCancelled);
      continue;
    }
    job->state = JobState::kRunning;
    JobState final_state = JobState::kDone;
    try {
      nlohmann::ordered_json result = job->run(job->progress);
      std::lock_guard lock(job->mutex);
      job->result = std::move(result);
    } catch (const CancelledError&) {
      final_state = JobState::kCancelled;
    } catch (const std::exception& error) {
      std::lock_guard lock(job->mutex);
      job->error = error.what();
      final_state = JobState::kFailed;
    }
    job->run = nullptr;  // releases what the operation captured
    job->End(final_state);
  }
}

}  // namespace lidarshop::server
