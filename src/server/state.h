// The server's state: open documents with their edit history, and the operations running on them.
// Internal to src/server.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "lidarshop/inpaint/inpaint_session.h"
#include "lidarshop/io/e57.h"
#include "lidarshop/scan/lazy_zeros.h"
#include "lidarshop/scan/scan.h"
#include "lidarshop/segment/segment.h"
#include "lidarshop/util/progress.h"

namespace lidarshop {
struct PreparedScan;  // verify/verify.h
}  // namespace lidarshop

namespace lidarshop::server {

// What an edit changes; undo restores all of it.
//
// Snapshots are immutable once committed (copy on write): copying one shares its buffers (cv::Mat and Scan
// copies are shallow) with the history, so an edit builds every buffer it changes anew — a clone, a library
// result, or NewZeros — and only then assigns it to a field of its copy. Never write into a buffer of a copy:
// not through at<>(), setTo, copyTo, cv::circle, nor by assigning a cv::MatExpr (`m = cv::Mat::zeros(...)`
// writes the zeros into m's existing buffer when the size matches, which the undo entry shares).
struct Snapshot {
  Scan scan;
  cv::Mat strokes;  // CV_8U kStrokeNone / kStrokeObject / kStrokeBackground
  // The cells of `strokes` of each label, kept with it: counted again only where an edit paints (a station's
  // strokes are 100 MB). Set together with `strokes` (ClearStrokes, the strokes route).
  int64_t object_stroke_cells = 0, background_stroke_cells = 0;
  // Every stroke lies in this box (cells outside it are kStrokeNone): what a copy or a comparison of the
  // strokes needs to read.
  cv::Rect strokes_box;
  cv::Mat object_mask;  // CV_8U 255 = the object of the last segmentation (empty = none)
  cv::Rect object_box;  // every cell of object_mask lies in it (SegmentResult::object_box)
  int64_t object_cells = 0;
  cv::Mat hole;  // CV_8U 255 = cells painted with the hole brush or lasso (empty = none)
  // The surface completed behind a kept object (fill shadow): a second layer, every cell synthesized or
  // without a return; empty = none. Saved as a second return (E57) or extra points (PLY, PCD).
  Scan behind;
  // CV_8U 255 = the cells whose point the site's Clean removed as transient (another station saw through
  // it), shown highlighted until the edit is undone; empty = none (routes_stations.cc).
  cv::Mat removed;
};

// The last cut of a document, kept for live refinement (segment/SegmentSession). Used by one job at a time.
struct SegmentCut {
  SegmentSession session;
  SegmentOptions options;
  const uint8_t* scan_data = nullptr;  // the scan it was built on (its range buffer)
  bool ran = false;                    // false: built ahead of the first cut (PrepareCut), not run yet
};

struct Job;

// An inpainting review in progress on a document (inpaint/inpaint_session.h): the scan's colour (or
// intensity) ray image inpainted in a hole, stopping where no candidate passes the acceptance tests so that
// the user decides. The finished fill becomes one undoable edit of that channel.
struct ReviewSession {
  std::unique_ptr<InpaintSession> session;  // null until the first job has built it
  InpaintOptions options;
  std::string channel;  // "color" or "intensity": what the fill is written back to
  cv::Mat hole;         // CV_8U 255 = the cells inpainted
  bool painted = true;  // the hole is the painted one (cleared when the fill is applied, as by fill)
  // The job filling now (null = none): while it runs the session is its alone. Guarded by Document::mutex.
  std::shared_ptr<Job> job;
};

// A new zero-filled buffer of `size` and `type`, for a snapshot field (see Snapshot: not cv::Mat::zeros, a
// cv::MatExpr whose assignment writes into the field's shared buffer). Its memory is touched only where an
// edit writes (a station's strokes: scan/lazy_zeros.h).
inline cv::Mat NewZeros(cv::Size size, int type) { return LazyZeros(size.height, size.width, type); }

// The object of a cut: its mask (shared: SegmentSession never writes it again), box and count.
inline void SetObject(Snapshot* snapshot, const SegmentResult& cut) {
  snapshot->object_mask = cut.mask;
  snapshot->object_box = cut.object_box;
  snapshot->object_cells = cut.object_cells;
}

// No strokes: a new zero buffer of the scan's size, and counts of 0.
inline void ClearStrokes(Snapshot* snapshot) {
  snapshot->strokes = NewZeros(cv::Size(snapshot->scan.cols, snapshot->scan.rows), CV_8U);
  snapshot->object_stroke_cells = snapshot->background_stroke_cells = 0;
  snapshot->strokes_box = cv::Rect();
}

struct Document {
  int id = 0;
  std::string name;  // file name or built-in scene name
  Snapshot now;
  std::vector<Snapshot> undo, redo;
  int64_t version = 0;  // +1 on every edit: clients see whether their view is current
  // The last few distinct point states (what GET /points draws from) with the versions that showed them, so
  // that GET /points?since=V answers only the cells changed since the client's version V. Consecutive
  // versions with the same point buffers (strokes, holes) share one entry: many clients painting at once
  // do not push a client's version out.
  struct PointState {
    int64_t first_version = 0, last_version = 0;
    Snapshot points;  // shallow: shares the history's buffers; strokes and hole left empty
  };
  std::deque<PointState> recent;
  // Ray images rendered, by (channel, the first version of a state in `recent`): a picture patch compares two.
  std::map<std::pair<std::string, int64_t>, cv::Mat> pictures;
  // The ray image's tile pyramid (tiles.cc, docs/api.md "Tiles"): encoded tiles by (channel, level, tx, ty),
  // each with the state it shows (the first version of a state in `recent`). A tile is re-rendered only when
  // the pixels of its footprint changed between the state it shows and the current one (the changed box of
  // the two pictures, kept by (channel, from, to) in `changed_boxes`).
  struct Tile {
    std::string png;
    int64_t state = -1;  // Document::PointState::first_version of the state rendered
    int64_t used = 0;    // a counter: the least recently used tiles go first when the cache is full
  };
  std::map<std::tuple<std::string, int, int, int>, Tile> tiles;
  int64_t tile_bytes = 0, tile_uses = 0;
  std::map<std::tuple<std::string, int64_t, int64_t>, cv::Rect> changed_boxes;
  // The scan prepared for verification (verify/), rebuilt when the version changes.
  std::shared_ptr<const PreparedScan> prepared;
  std::shared_ptr<SegmentCut> cut;  // the last segmentation's session (null = none yet)
  bool preparing_cut = false;       // a job is building a session for the first cut (PrepareCut)
  // The photos (images2D) of the E57 file it was opened from that belong to its scan or to none
  // (associated_scan 0 or -1): a save as E57 writes them back, the recolour tool can use them.
  std::vector<E57Image> e57_images;
  cv::Mat photo;    // CV_8UC3 RGB: the photo to recolour from (empty = none)
  cv::Mat photo_b;  // CV_8UC3 RGB: a second photo for photo <-> photo pairs (empty = none)
  std::shared_ptr<ReviewSession> review;  // the inpainting review in progress (null = none)
  int64_t prepared_version = -1;
  // Memory accounting: the bytes DocumentBytes counted at the last version change (read by other
  // documents' room checks without this one's mutex), and the check an edit must pass before it is committed
  // (EditorServer::State::CheckRoomForEdit: throws DocumentLimitError when the document would hold
  // `bytes_after` and the open documents together would pass the limit). Empty outside a server.
  std::atomic<int64_t> counted_bytes{0};
  std::function<void(const Document&, int64_t bytes_after)> check_room;
  std::mutex mutex;  // guards every field above
};

enum class JobState { kQueued, kRunning, kDone, kFailed, kCancelled };

struct Job {
  int id = 0;
  int document = 0;
  std::string kind;  // "segment", "remove", "fill"
  Progress progress{"queued", 1, false};
  std::atomic<JobState> state{JobState::kQueued};
  std::mutex mutex;  // guards error and result
  std::string error;
  nlohmann::ordered_json result;
  std::function<nlohmann::ordered_json(Progress&)> run;

  // Sets a final state (done, failed, cancelled) and wakes the requests waiting for one.
  void End(JobState final_state) {
    {
      std::lock_guard lock(mutex);
      state = final_state;
    }
    ended_.notify_all();
  }
  // Waits at most `timeout` for a final state (GET /api/jobs/ID?wait_ms=: the client learns of the end when it
  // comes, not at its next poll); true when there is one.
  bool WaitEnded(std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex);
    return ended_.wait_for(lock, timeout, [&] {
      const JobState now = state.load();
      return now != JobState::kQueued && now != JobState::kRunning;
    });
  }

 private:
  std::condition_variable ended_;
};

// Runs jobs on a fixed number of worker threads, in the order they were queued.
class JobRunner {
 public:
  JobRunner(int workers, int max_queued);
  ~JobRunner();
  // Queues `job`; false when the queue is full (the caller answers 503).
  bool Submit(std::shared_ptr<Job> job);
  std::shared_ptr<Job> Find(int id) const;
  int NextId() { return ++last_id_; }

 private:
  void Work();

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::shared_ptr<Job>> queue_;
  std::map<int, std::shared_ptr<Job>> jobs_;  // the last few hundred, for polling
  std::vector<std::thread> workers_;
  std::atomic<int> last_id_{0};
  int max_queued_;
  bool stopping_ = false;
};

}  // namespace lidarshop::server
