// Routes that place a model in a scan and verify its pose (verify/, thesis ch. 4): the consistency and
// confidence of the pose, recomputed as the user drags the model (docs/api.md).
#include <cstring>
#include <filesystem>

#include <fmt/format.h>

#include "http.h"
#include "lidarshop/io/mesh_io.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/scanner/primitives.h"
#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "lidarshop/verify/pose_text.h"
#include "lidarshop/verify/verify.h"
#include "replies.h"

namespace lidarshop::server {

namespace {

namespace fs = std::filesystem;

// The models every scene can use: the scanner's own procedural meshes.
const std::vector<std::string> kBuiltinModels = {"car:sedan",    "car:hatchback", "car:van",
                                                 "electric_box", "mailbox",       "lamp_post"};

TriangleMesh BuiltinMesh(const std::string& name) {
  if (name.rfind("car:", 0) == 0) {
    CarMeshOptions options;
    options.style = ParseCarStyle(name.substr(4), "model");
    return MakeCarMesh(options);
  }
  if (name == "electric_box") return MakeElectricBoxMesh();
  if (name == "mailbox") return MakeMailboxMesh();
  if (name == "lamp_post") return MakeLampPostMesh();
  throw OptionsFieldError("model", fmt::format("no built-in model '{}'", name));
}

// A mesh as typed arrays: header (uint32 magic "LSM1", vertex count, triangle count, 0), float32 xyz per
// vertex (model frame, metres), uint32 vertex indices per triangle.
std::string MeshBinary(const TriangleMesh& mesh) {
  const uint32_t header[4] = {0x314d534cu, static_cast<uint32_t>(mesh.vertices.size()),
                              static_cast<uint32_t>(mesh.triangles.size()), 0};
  std::string bytes(sizeof(header), '\0');
  std::memcpy(bytes.data(), header, sizeof(header));
  for (const Eigen::Vector3f& v : mesh.vertices) bytes.append(reinterpret_cast<const char*>(v.data()), 12);
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const uint32_t corners[3] = {static_cast<uint32_t>(t[0]), static_cast<uint32_t>(t[1]),
                                 static_cast<uint32_t>(t[2])};
    bytes.append(reinterpret_cast<const char*>(corners), sizeof(corners));
  }
  return bytes;
}

// The body's "pose" (verify/pose_text.h PoseFromJson); errors name the key as "pose.<key>".
Eigen::Matrix4d PoseOfBody(const nlohmann::json& body) {
  try {
    return PoseFromJson(body.value("pose", nlohmann::json::object()));
  } catch (const OptionsFieldError& error) {
    throw OptionsFieldError("pose." + error.key_path(), error.reason());
  }
}

}  // namespace

void AddVerifyRoutes(State& state) {
  httplib::Server& http = state.http;
  http.Get("/api/models", [&state](const httplib::Request&, httplib::Response& response) {
    std::vector<std::string> files;
    for (const std::string& root : state.options.roots) {
      std::error_code error;
      for (auto it = fs::recursive_directory_iterator(root, error);
           !error && it != fs::recursive_directory_iterator(); it.increment(error)) {
        if (it.depth() > 1) it.disable_recursion_pending();
        const std::string extension = FileExtension(it->path().string());
        if (it->is_regular_file() && !IsAtomicTemporary(it->path().filename().string()) &&
            (extension == "obj" || extension == "ply") && files.size() < 500) {
          files.push_back(it->path().string());
        }
      }
    }
    SendJson(response, ToJson(ModelsReply{kBuiltinModels, files}));
  });
  http.Post("/api/models", [&state](const httplib::Request& request, httplib::Response& response) {
    const auto body = BodyJson(request, response);
    if (!body) return;
    try {
      const std::string name = body->value("model", std::string());
      auto entry = std::make_shared<ModelEntry>();
      entry->name = name;
      std::vector<std::string> warnings;  // what the mesh reader left out of the file
      if (std::find(kBuiltinModels.begin(), kBuiltinModels.end(), name) != kBuiltinModels.end()) {
        entry->mesh = BuiltinMesh(name);
      } else {
        const std::string path = ResolveUnderRoots(state.options.roots, name);
        if (path.empty()) {
          return SendError(response, 403,
                           fmt::format("'{}' is neither a built-in model nor a mesh file under the "
                                       "server's folders",
                                       name));
        }
        MeshFile file = ReadMeshFile(path);
        entry->mesh = std::move(file.mesh);
        warnings = std::move(file.warnings);
      }
      // "options": ModelOptions (e.g. {"model_scale": 0.001} for a mesh in millimetres); the mesh the
      // browser gets is the scaled one, the frame the measures use.
      const ModelOptions model_options =
          body->contains("options") ? FromJson<ModelOptions>(body->at("options")) : ModelOptions{};
      entry->model = PrepareModel(entry->mesh, model_options);
      entry->mesh = entry->model.mesh_in_model;
      Eigen::Vector3f low = Eigen::Vector3f::Constant(INFINITY), high = -low;
      for (const Eigen::Vector3f& v : entry->mesh.vertices) {
        low = low.cwiseMin(v);
        high = high.cwiseMax(v);
      }
      std::lock_guard lock(state.documents_mutex);
      entry->id = ++state.last_model;
      state.models[entry->id] = entry;
      const Eigen::Vector3f size = high - low;
      SendJson(response, ToJson(ModelReply{entry->id,
                                           name,
                                           entry->mesh.vertices.size(),
                                           entry->mesh.triangles.size(),
                                           {size.x(), size.y(), size.z()},
                                           warnings}));
    } catch (const OptionsError& error) {
      SendError(response, 400, error.what());
    } catch (const InputError& error) {
      SendError(response, 422, error.what());
    } catch (const nlohmann::json::exception& error) {  // a field of the wrong type (body.value)
      SendError(response, 400, fmt::format("a field of the request has the wrong type: {}", error.what()));
    }
  });
  http.Get(R"(/api/models/(\d+)/mesh)",
           [&state](const httplib::Request& request, httplib::Response& response) {
             const auto model = state.FindModel(std::atoi(request.matches[1].str().c_str()));
             if (!model) return SendError(response, 404, "no such model");
             response.set_content(MeshBinary(model->mesh), "application/octet-stream");
           });
  // Consistency and confidence of a model at a pose in an open scan: x_m, y_m, z_m, yaw_deg, pitch_deg,
  // roll_deg or world_from_model (world frame; PoseOfBody).
  http.Post(R"(/api/docs/(\d+)/verify)", [&state](const httplib::Request& request,
                                                  httplib::Response& response) {
    auto document = state.FindDocument(request, response);
    if (!document) return;
    const auto body = BodyJson(request, response);
    if (!body) return;
    try {
      const auto model = state.FindModel(body->value("model", 0));
      if (!model) return SendError(response, 404, "no such model: POST /api/models first");
      const Eigen::Matrix4d world_from_model = PoseOfBody(*body);
      std::shared_ptr<const PreparedScan> prepared;
      {
        std::lock_guard lock(document->mutex);
        if (!document->prepared || document->prepared_version != document->version) {
          document->prepared = std::make_shared<PreparedScan>(PrepareScan(document->now.scan));
          document->prepared_version = document->version;
        }
        prepared = document->prepared;
      }
      const VerifyResult result =
          VerifyPose(model->model, std::span<const PreparedScan>(prepared.get(), 1), world_from_model);
      SendJson(response, Joined(ToJson(result), ToJson(VerifyReply{result.BriefReport()})));
    } catch (const OptionsError& error) {
      SendError(response, 400, error.what());
    } catch (const InputError& error) {
      SendError(response, 422, error.what());
    } catch (const nlohmann::json::exception& error) {  // a field of the wrong type (body.value)
      SendError(response, 400, fmt::format("a field of the request has the wrong type: {}", error.what()));
    }
  });
}

}  // namespace lidarshop::server
