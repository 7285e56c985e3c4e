// The fixture of the route tests (server_scan_test, server_points_test, server_edit_test, server_recolor_test,
// server_verify_test, server_review_test): one server for the whole suite, on a free loopback port, with a root
// folder holding a scan, the same scan moved, a broken file, a mesh whose MTL file is missing and a symlink
// leading out of the root. Each test executable makes its own folder (named after its process), so the suites
// run in parallel. Include it after every Eigen include: httplib (server_test_util.h) pulls in <resolv.h>, whose
// `_res` macro breaks Eigen's headers.
#pragma once

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "lidarshop/io/scan_io.h"
#include "lidarshop/testing/scenes.h"
#include "server.h"
#include "server_test_util.h"

namespace lidarshop::server {

class ServerTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    namespace fs = std::filesystem;
    base_ = fs::temp_directory_path() / fmt::format("lidarshop_server_test_{}", getpid());
    fs::remove_all(base_);
    fs::create_directories(base_ / "root" / "sub");
    fs::create_directories(base_ / "outside");
    lidarshop::test_scenes::GroundAndBoxOptions scene;
    scene.rows = 60;
    scene.columns = 90;
    scan_ = new Scan(lidarshop::test_scenes::ScanScene(lidarshop::test_scenes::MakeGroundAndBoxScene(scene)));
    WriteScanFile((base_ / "root" / "sub" / "box.ptx").string(), {*scan_});
    WriteScanFile((base_ / "outside" / "secret.ptx").string(), {*scan_});
    // The same scan with its pose moved (2 m along x, 1 m along y, turned 20 degrees about z): registering
    // it to the box's scan with landmarks must bring the pose back.
    Scan moved = *scan_;
    moved.world_from_scanner = MovedPose() * scan_->world_from_scanner;
    WriteScanFile((base_ / "root" / "sub" / "moved.ptx").string(), {moved});
    std::ofstream(base_ / "root" / "broken.ptx") << "12\nnot a ptx\n";
    // A mesh whose MTL file is missing: read with a warning.
    std::ofstream(base_ / "root" / "sub" / "quad.obj")
        << "mtllib missing.mtl\nv 0 0 0\nv 2 0 0\nv 2 2 0\nv 0 2 0\nf 1 2 3 4\n";
    fs::create_symlink(base_ / "outside" / "secret.ptx", base_ / "root" / "link.ptx");
    ServerOptions options;
    options.port = 0;
    options.token = "secret-token";
    options.roots = {(base_ / "root").string()};
    options.max_body_bytes = 1 << 20;
    options.max_documents = 100;  // the tests open more than the default 16 and close none
    options.builtin_scenes = {"tiny"};
    options.scan_builtin = [](const std::string&) { return *scan_; };
    running_ = new RunningServer(options, 60);
    server_ = &running_->server();
    client_ = &running_->client();
  }
  static void TearDownTestSuite() {
    delete running_;
    delete scan_;
    std::filesystem::remove_all(base_);
  }

  static Eigen::Matrix4d MovedPose() {
    Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();
    const double angle = 20.0 * M_PI / 180.0;
    pose.topLeftCorner<2, 2>() << std::cos(angle), -std::sin(angle), std::sin(angle), std::cos(angle);
    pose(0, 3) = 2.0;
    pose(1, 3) = 1.0;
    return pose;
  }
  static std::string Api(const std::string& path) {
    return path + (path.find('?') == std::string::npos ? "?" : "&") + "token=secret-token";
  }
  static nlohmann::json Json(const httplib::Result& result) { return nlohmann::json::parse(result->body); }
  static int OpenBox() {
    const auto result = client_->Get(Api("/api/open?path=sub/box.ptx"));
    EXPECT_EQ(result->status, 200) << result->body;
    return Json(result)["id"].get<int>();
  }
  // Polls a job until it ends; returns its last JSON.
  static nlohmann::json Wait(const nlohmann::json& job) {
    for (int i = 0; i < 600; ++i) {
      const auto json = Json(client_->Get(Api(fmt::format("/api/jobs/{}", job["id"].get<int>()))));
      const std::string state = json["state"];
      if (state != "queued" && state != "running") return json;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    ADD_FAILURE() << "job did not end";
    return {};
  }
  // Strokes: a few object cells on the box (label 1), background cells on the ground (label 0).
  static std::string StrokesBody() {
    nlohmann::json object = nlohmann::json::array(), background = nlohmann::json::array();
    for (int r = 0; r < scan_->rows; ++r) {
      for (int c = 0; c < scan_->cols; ++c) {
        if (scan_->valid.at<uint8_t>(r, c) == 0 || (r + c) % 7 != 0) continue;
        (scan_->label.at<int32_t>(r, c) == 1 ? object : background).push_back({r, c});
      }
    }
    return nlohmann::json{{"object", object}, {"background", background}, {"radius", 0}}.dump();
  }

  static inline std::filesystem::path base_;
  static inline Scan* scan_ = nullptr;
  static inline EditorServer* server_ = nullptr;
  static inline RunningServer* running_ = nullptr;
  static inline httplib::Client* client_ = nullptr;
};

}  // namespace lidarshop::server
