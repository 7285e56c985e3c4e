// The page `lidarshop demo` writes (index.html): the template data/demo/index.html.mustache, compiled into the
// executable (this folder's CMakeLists.txt), filled with the numbers of the demo's summary.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace lidarshop::cli {

// Every file the demo writes (index.html aside), with what it holds, for the steps `summary` has results of.
std::vector<std::pair<std::string, std::string>> DemoFiles(const nlohmann::json& summary);

// index.html for the scene `scene_name` from summary.json's content. Throws std::logic_error when the summary
// lacks a number the page shows (a programming error: the demo writes both).
std::string DemoPage(const std::string& scene_name, const nlohmann::json& summary);

}  // namespace lidarshop::cli
