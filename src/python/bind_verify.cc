// Pose verification (thesis ch. 4) and sweeps over candidate poses.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "lidarshop/geometry/transform.h"
#include "lidarshop/verify/sweep.h"
#include "lidarshop/verify/verify.h"

namespace lidarshop::python {
namespace {

std::vector<Scan> ScansOf(const py::object& scans) {
  if (py::isinstance<Scan>(scans)) return {scans.cast<Scan>()};
  return scans.cast<std::vector<Scan>>();
}

// The model and the scans prepared once (Embree scene, point grids) for any number of poses.
struct Prepared {
  VerifierModel model;
  std::vector<PreparedScan> scans;
};
Prepared Prepare(const TriangleMesh& mesh, const std::vector<Scan>& scans, const ModelOptions& model_options,
                 const VerifyOptions& options) {
  Prepared prepared{PrepareModel(mesh, model_options, options), {}};
  for (const Scan& scan : scans) prepared.scans.push_back(PrepareScan(scan));
  return prepared;
}

// Sweep poses as columns (157,464 poses are too many for one Python object each).
py::dict PoseColumns(const std::vector<SweepPose>& poses) {
  const auto column = [&poses](auto value_of) {
    py::array_t<double> array(static_cast<py::ssize_t>(poses.size()));
    double* out = array.mutable_data();
    for (size_t i = 0; i < poses.size(); ++i) out[i] = value_of(poses[i]);
    return array;
  };
  py::dict columns;
  columns["x_m"] = column([](const SweepPose& p) { return p.x_m; });
  columns["y_m"] = column([](const SweepPose& p) { return p.y_m; });
  columns["yaw_deg"] = column([](const SweepPose& p) { return p.yaw_deg; });
  columns["consistency"] = column([](const SweepPose& p) { return p.result.consistency; });
  columns["confidence"] = column([](const SweepPose& p) { return p.result.confidence; });
  columns["comparable_pairs"] =
      column([](const SweepPose& p) { return static_cast<double>(p.result.comparable_pairs); });
  columns["icp_cost_m"] = column([](const SweepPose& p) { return p.result.icp_cost_m; });
  columns["inlier_fraction"] = column([](const SweepPose& p) { return p.result.inlier_fraction; });
  columns["evaluated"] = column([](const SweepPose& p) { return p.evaluated ? 1.0 : 0.0; });
  columns["confidence_bound"] = column([](const SweepPose& p) { return p.confidence_bound; });
  return columns;
}

void BindVerifyResults(py::module_& m) {
  py::class_<ScanVerifyStats>(m, "ScanVerifyStats", "verify_pose's outcome for one scan alone.")
      .def_readonly("comparable_pairs", &ScanVerifyStats::comparable_pairs)
      .def_readonly("consistent_pairs", &ScanVerifyStats::consistent_pairs)
      .def_readonly("consistency", &ScanVerifyStats::consistency)
      .def_readonly("confidence", &ScanVerifyStats::confidence);
  BindStruct<VerifyResult>(m, true)
      .def_readonly("per_scan", &VerifyResult::per_scan, "one ScanVerifyStats per scan")
      .def("summary", &VerifyResult::BriefReport);
  py::class_<Detection>(m, "Detection", "A sweep pose that passes both thresholds (after NMS).")
      .def_readonly("x_m", &Detection::x_m)
      .def_readonly("y_m", &Detection::y_m)
      .def_readonly("z_m", &Detection::z_m)
      .def_readonly("yaw_deg", &Detection::yaw_deg)
      .def_readonly("world_from_model", &Detection::world_from_model)
      .def_readonly("consistency", &Detection::consistency)
      .def_readonly("confidence", &Detection::confidence)
      .def_readonly("icp_cost_m", &Detection::icp_cost_m)
      .def_readonly("inlier_fraction", &Detection::inlier_fraction)
      .def_readonly("comparable_pairs", &Detection::comparable_pairs)
      .def("__repr__", [](const Detection& d) {
        return fmt::format(
            "<lidarshop.Detection x {:.2f} m, y {:.2f} m, yaw {:.1f} deg, consistency {:.3f}, "
            "confidence {:.3f}>",
            d.x_m, d.y_m, d.yaw_deg, d.consistency, d.confidence);
      });
  py::class_<SweepResult>(m, "SweepResult", "Consistency and confidence over a grid of poses on the ground.")
      .def_property_readonly(
          "xs_m", [](const SweepResult& r) { return py::array(py::cast(r.xs_m)); }, "the grid's x, metres")
      .def_property_readonly(
          "ys_m", [](const SweepResult& r) { return py::array(py::cast(r.ys_m)); }, "the grid's y, metres")
      .def_property_readonly(
          "yaws_deg", [](const SweepResult& r) { return py::array(py::cast(r.yaws_deg)); }, "degrees")
      .def_property_readonly(
          "consistency_map", [](const SweepResult& r) { return MatToArray(r.consistency_map); },
          "float32 (#y, #x): the best over the verified yaws; row 0 = the largest y; NaN = nothing "
          "comparable "
          "or nothing verified")
      .def_property_readonly(
          "confidence_map", [](const SweepResult& r) { return MatToArray(r.confidence_map); },
          "float32 (#y, #x): the best over the verified yaws; row 0 = the largest y; NaN = nothing verified")
      .def_property_readonly(
          "evaluated_map", [](const SweepResult& r) { return MatToArray(r.evaluated_map); },
          "uint8 (#y, #x): yaws verified at each position (coarse-to-fine skips poses that cannot pass)")
      .def_readonly("evaluated_poses", &SweepResult::evaluated_poses, "grid poses verified")
      .def_property_readonly(
          "poses", [](const SweepResult& r) { return PoseColumns(r.poses); },
          "every grid pose as columns (dict of float64 arrays: x_m, y_m, yaw_deg, consistency, confidence, "
          "comparable_pairs, icp_cost_m, inlier_fraction, evaluated (0 = skipped by coarse-to-fine: its "
          "confidence is at most confidence_bound), confidence_bound), index (iy * #x + ix) * #yaws + iyaw")
      .def_property_readonly(
          "refined", [](const SweepResult& r) { return PoseColumns(r.refined); },
          "the poses of the local refinement, as columns")
      .def_readonly("detections", &SweepResult::detections, "by decreasing confidence")
      .def_readonly("refine_evaluations", &SweepResult::refine_evaluations)
      .def_readonly("nms_radius_m", &SweepResult::nms_radius_m)
      .def("csv", &SweepCsv, "One line per verified pose (x_m,y_m,yaw_deg,consistency,confidence,...).")
      .def(
          "heat_map",
          [](const SweepResult& r, const std::string& measure, double threshold, int cell_px) {
            if (measure != "consistency" && measure != "confidence") {
              throw OptionsError(fmt::format("measure: '{}' is not one of consistency|confidence", measure));
            }
            const cv::Mat& values = measure == "consistency" ? r.consistency_map : r.confidence_map;
            return MatToArray(RenderHeatMap(values, r, measure, threshold, cell_px));
          },
          py::arg("measure") = "confidence", py::arg("threshold") = -1.0, py::arg("cell_px") = 0,
          "The heat map as an RGB picture (uint8 (H, W, 3)) with a colour scale, the threshold marked, the "
          "detections ringed, axes in metres, the scanners (magenta) and the scene points underneath.");
}

}  // namespace

void BindVerify(py::module_& m) {
  BindVerifyResults(m);
  m.def(
      "verify_pose",
      [](const TriangleMesh& mesh, const py::object& scans, const py::object& world_from_model,
         const py::object& options, const py::object& model_options, const py::kwargs& kwargs) {
        const std::vector<Scan> list = ScansOf(scans);
        // One 4 x 4 pose, or many (N x 4 x 4): the model and the scans are prepared once, the poses run in
        // parallel (VerifyPoses) and a list of results comes back.
        const py::array poses = py::module_::import("numpy").attr("asarray")(world_from_model, "float64");
        std::vector<Eigen::Matrix4d> pose_list;
        if (poses.ndim() == 3) {
          for (py::ssize_t i = 0; i < poses.shape(0); ++i) {
            pose_list.push_back(ArrayToMatrix(poses[py::int_(i)], fmt::format("world_from_model[{}]", i)));
          }
        } else {
          pose_list.push_back(ArrayToMatrix(poses, "world_from_model"));
        }
        const VerifyOptions verify_options = OptionsOf<VerifyOptions>(options, kwargs);
        const ModelOptions model = OptionsOf<ModelOptions>(model_options);
        std::vector<VerifyResult> results;
        {
          py::gil_scoped_release release;
          const Prepared prepared = Prepare(mesh, list, model, verify_options);
          results = VerifyPoses(prepared.model, prepared.scans, pose_list, verify_options);
        }
        if (poses.ndim() == 3) return py::cast(results);
        return py::cast(results.front());
      },
      py::arg("model"), py::arg("scans"), py::arg("world_from_model"), py::arg("options") = py::none(),
      py::arg("model_options") = py::none(),
      R"doc(Verifies an object pose against registered scans: consistency (does the pose make physical sense:
no measured point behind the model) and confidence (how much of the model was seen), thesis eqs. 4.1-4.5.

model: a TriangleMesh in its own frame (read_mesh, make_primitive); scans: a Scan or a list (their
world_from_scanner register them); world_from_model: 4 x 4, or N x 4 x 4 for a list of results (the model
and scans are prepared once, the poses verified in parallel). options: a VerifyOptions, a dict or keywords
(verify_pose(mesh, scan, pose, allowance_m=0.05)); model_options: a ModelOptions or a dict.)doc");
  m.def(
      "sweep",
      [](const TriangleMesh& mesh, const py::object& scans, const py::object& options,
         const py::object& verify_options, const py::object& model_options, const py::kwargs& kwargs) {
        const std::vector<Scan> list = ScansOf(scans);
        const SweepOptions sweep_options = OptionsOf<SweepOptions>(options, kwargs);
        const VerifyOptions verify = OptionsOf<VerifyOptions>(verify_options);
        const ModelOptions model = OptionsOf<ModelOptions>(model_options);
        py::gil_scoped_release release;
        const Prepared prepared = Prepare(mesh, list, model, verify);
        return Sweep(prepared.model, prepared.scans, sweep_options, verify);
      },
      py::arg("model"), py::arg("scans"), py::arg("options") = py::none(),
      py::arg("verify_options") = py::none(), py::arg("model_options") = py::none(),
      R"doc(Verifies a grid of poses world_from_model = pose_from_xyz_yaw(x, y, z_m, yaw) (SweepOptions: ranges,
step, yaws, thresholds, local refinement) and returns a SweepResult: heat maps, every pose as columns, and the
detections passing both thresholds after non-maximum suppression.)doc");
  m.def("pose_from_xyz_yaw", &PoseFromXyzYaw, py::arg("x_m"), py::arg("y_m"), py::arg("z_m"),
        py::arg("yaw_deg"), py::arg("pitch_deg") = 0.0, py::arg("roll_deg") = 0.0,
        "world_from_model (4 x 4) of an object standing on the ground: R = Rz(yaw) Ry(pitch) Rx(roll) "
        "(degrees; roll about x first, yaw turns +x towards +y), then translate by (x_m, y_m, z_m).");
  m.def(
      "rotation_from_euler_degrees",
      [](const Eigen::Vector3d& rotate_deg) { return RotationFromEulerDegrees(rotate_deg); },
      py::arg("rotate_deg"),
      "The 3 x 3 rotation R = Rz(yaw) Ry(pitch) Rx(roll) of rotate_deg = [roll, pitch, yaw] = [x, y, z] "
      "degrees: the one angle convention of lidarshop (scene files' rotate_deg, pose_from_xyz_yaw, verify "
      "--pose).");
}

}  // namespace lidarshop::python
