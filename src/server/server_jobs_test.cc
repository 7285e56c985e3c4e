// Jobs (docs/api.md "Jobs"): a GET of a job with ?wait_ms=N answers when the job ends or after N ms (the long
// poll the editor's live cut uses instead of polling every 150 ms), and refuses a wait it does not allow.
#include <chrono>
#include <thread>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "lidarshop/testing/scenes.h"
#include "server.h"
#include "server_test_util.h"
#include "state.h"

namespace lidarshop::server {
namespace {

using Clock = std::chrono::steady_clock;

TEST(Job, WaitEndedWakesWhenTheJobEnds) {
  Job job;
  job.state = JobState::kRunning;
  EXPECT_FALSE(job.WaitEnded(std::chrono::milliseconds(20)));  // still running: the wait times out
  std::thread ender([&job] {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    job.End(JobState::kDone);
  });
  const auto start = Clock::now();
  EXPECT_TRUE(job.WaitEnded(std::chrono::seconds(30)));
  // Woken by End, not by the timeout (a generous bound: this is not a timing test).
  EXPECT_LT(Clock::now() - start, std::chrono::seconds(20));
  ender.join();
  EXPECT_EQ(job.state.load(), JobState::kDone);
  EXPECT_TRUE(job.WaitEnded(std::chrono::milliseconds(0)));
}

class JobsRouteTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scan_ = new Scan(test_scenes::ScanScene(test_scenes::MakeGroundAndBoxScene()));
    ServerOptions options;
    options.port = 0;
    options.token = "job-token";
    options.builtin_scenes = {"ground"};
    options.scan_builtin = [](const std::string&) { return *scan_; };
    running_ = new RunningServer(options, 120);
  }
  static void TearDownTestSuite() {
    delete running_;
    delete scan_;
  }
  static std::string Api(const std::string& path) {
    return path + (path.find('?') == std::string::npos ? "?" : "&") + "token=job-token";
  }
  static httplib::Client& Client() { return running_->client(); }
  // A segment job on the ground-and-box scene: strokes on the box (label 1) and on the ground.
  static int StartSegment() {
    const auto opened = Client().Get(Api("/api/open?scene=ground"));
    EXPECT_EQ(opened->status, 200) << opened->body;
    const int id = nlohmann::json::parse(opened->body)["id"].get<int>();
    nlohmann::json object = nlohmann::json::array(), background = nlohmann::json::array();
    for (int r = 0; r < scan_->rows; ++r) {
      for (int c = 0; c < scan_->cols; ++c) {
        if (scan_->valid.at<uint8_t>(r, c) == 0 || (r + c) % 7 != 0) continue;
        (scan_->label.at<int32_t>(r, c) == 1 ? object : background).push_back({r, c});
      }
    }
    const auto painted =
        Client().Post(Api(fmt::format("/api/docs/{}/strokes", id)),
                      nlohmann::json{{"object", object}, {"background", background}, {"radius", 0}}.dump(),
                      "application/json");
    EXPECT_EQ(painted->status, 200) << painted->body;
    const auto started =
        Client().Post(Api(fmt::format("/api/docs/{}/segment", id)), "{}", "application/json");
    EXPECT_EQ(started->status, 202) << started->body;
    return nlohmann::json::parse(started->body)["id"].get<int>();
  }

  static inline Scan* scan_ = nullptr;
  static inline RunningServer* running_ = nullptr;
};

TEST_F(JobsRouteTest, ALongPollAnswersAtTheEndOrAfterItsWait) {
  const int job = StartSegment();
  constexpr int kWaitMs = 1000;
  nlohmann::json state;
  for (int request = 0; request < 120; ++request) {
    const auto start = Clock::now();
    const auto answer = Client().Get(Api(fmt::format("/api/jobs/{}?wait_ms={}", job, kWaitMs)));
    const auto elapsed = Clock::now() - start;
    ASSERT_EQ(answer->status, 200) << answer->body;
    state = nlohmann::json::parse(answer->body);
    const std::string now = state["state"];
    if (now != "queued" && now != "running") break;
    // Not ended: the server held the request for the whole wait (a plain poll answers at once).
    EXPECT_GE(elapsed, std::chrono::milliseconds(kWaitMs - 50)) << "request " << request;
  }
  EXPECT_EQ(state["state"], "done") << state.dump();
  EXPECT_GT(state["result"]["object_cells"].get<int>(), 0);
}

TEST_F(JobsRouteTest, AWaitOutsideItsRangeIs400) {
  const int job = StartSegment();
  for (const char* wait : {"abc", "-1", "2001", "", "5ms"}) {
    const auto answer = Client().Get(Api(fmt::format("/api/jobs/{}?wait_ms={}", job, wait)));
    EXPECT_EQ(answer->status, 400) << "wait_ms=" << wait << ": " << answer->body;
    EXPECT_NE(answer->body.find("wait_ms"), std::string::npos) << answer->body;
  }
  EXPECT_EQ(Client().Get(Api(fmt::format("/api/jobs/{}?wait_ms=0", job)))->status, 200);
  EXPECT_EQ(Client().Get(Api("/api/jobs/987654?wait_ms=10"))->status, 404);
}

}  // namespace
}  // namespace lidarshop::server
