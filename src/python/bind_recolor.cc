// Recolouring a scan from a photo (thesis 3.2): cameras, correspondences, resectioning, the other pair modes
// of the selection tool (landmarks, photo <-> photo), occlusion-aware recolouring, photos stored in E57 files
// and synthetic photos of scenes.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "lidarshop/geometry/camera.h"
#include "lidarshop/io/e57.h"
#include "lidarshop/recolor/align.h"
#include "lidarshop/recolor/auto_resection.h"
#include "lidarshop/recolor/correspondences.h"
#include "lidarshop/recolor/e57_camera.h"
#include "lidarshop/recolor/recolor.h"
#include "lidarshop/recolor/resection.h"
#include "lidarshop/recolor/station_recolor.h"
#include "lidarshop/scanner/photo.h"
#include "lidarshop/scanner/scene.h"
#include "lidarshop/util/enum_names.h"
#include "lidarshop/util/error.h"

namespace lidarshop::python {
namespace {

std::vector<PixelPointPair> PixelPointPairsOf(const py::handle& pixels, const py::handle& points) {
  const auto pixel = VectorsOf<2>(pixels, "pixels");
  const auto point = VectorsOf<3>(points, "points");
  if (pixel.size() != point.size()) {
    throw py::value_error(
        fmt::format("pixels and points: {} pixels but {} points", pixel.size(), point.size()));
  }
  std::vector<PixelPointPair> pairs(pixel.size());
  for (size_t i = 0; i < pairs.size(); ++i) pairs[i] = {pixel[i], point[i]};
  return pairs;
}

// A correspondence file's content as a dict of arrays.
py::dict CorrespondenceDict(const Correspondences& pairs) {
  std::vector<Eigen::Vector2d> pixel, pixel_b;
  std::vector<Eigen::Vector3d> point, source;
  py::dict result;
  result["kind"] = ToString(pairs.kind);
  if (pairs.kind == PairKind::kPixelPoint) {
    for (const PixelPointPair& p : pairs.pixel_point) {
      pixel.push_back(p.pixel_px);
      point.push_back(p.point_in_world);
    }
    result["pixels"] = VectorsArray<2>(pixel);
    result["points"] = VectorsArray<3>(point);
  } else if (pairs.kind == PairKind::kLandmark) {
    for (const PointPair& p : pairs.landmarks) {
      source.push_back(p.source);
      point.push_back(p.target);
    }
    result["source"] = VectorsArray<3>(source);
    result["target"] = VectorsArray<3>(point);
  } else {
    for (const PixelPair& p : pairs.pixel_pixel) {
      pixel.push_back(p.pixel_a);
      pixel_b.push_back(p.pixel_b);
    }
    result["pixels_a"] = VectorsArray<2>(pixel);
    result["pixels_b"] = VectorsArray<2>(pixel_b);
  }
  result["image_size_px"] = pairs.width_px > 0 ? py::object(py::make_tuple(pairs.width_px, pairs.height_px))
                                               : py::object(py::none());
  return result;
}

void BindCamera(py::module_& m) {
  py::class_<PinholeCamera> camera(m, "PinholeCamera",
                                   R"doc(A pinhole camera with Brown-Conrady distortion (geometry/camera.h).

Camera frame: x right, y down, z forward; world_from_camera maps it to the world (metres). Pixels are
continuous: (0, 0) the top-left corner of the photo, (0.5, 0.5) the centre of its first pixel.
PinholeCamera(width_px=..., fx_px=..., ...) sets fields by keyword; to_dict()/from_dict() are the JSON form of
camera files (read_camera / write_camera).)doc");
  camera
      .def(py::init([](const py::kwargs& kwargs) {
             nlohmann::json json = nlohmann::json::parse(CameraToJson(PinholeCamera{}));
             for (const auto& [key, value] : kwargs) json[key.cast<std::string>()] = ToJsonValue(value);
             return ParseCameraJson(json.dump(), "PinholeCamera");
           }),
           "Keyword construction by the fields of the JSON form (width_px, height_px, fx_px, fy_px, cx_px, "
           "cy_px, skew_px, distortion={'k1': ...}, world_from_camera); checked like a camera file.")
      .def_readwrite("width_px", &PinholeCamera::width_px)
      .def_readwrite("height_px", &PinholeCamera::height_px)
      .def_readwrite("fx_px", &PinholeCamera::fx_px)
      .def_readwrite("fy_px", &PinholeCamera::fy_px)
      .def_readwrite("cx_px", &PinholeCamera::cx_px)
      .def_readwrite("cy_px", &PinholeCamera::cy_px)
      .def_readwrite("skew_px", &PinholeCamera::skew_px)
      .def_readwrite("k1", &PinholeCamera::k1)
      .def_readwrite("k2", &PinholeCamera::k2)
      .def_readwrite("k3", &PinholeCamera::k3)
      .def_readwrite("p1", &PinholeCamera::p1)
      .def_readwrite("p2", &PinholeCamera::p2)
      .def_property(
          "world_from_camera", [](const PinholeCamera& c) { return MatrixToArray(c.world_from_camera); },
          [](PinholeCamera& c, const py::object& value) {
            c.world_from_camera = ArrayToMatrix(value, "world_from_camera");
          },
          "float64 (4, 4), rigid, metres")
      .def_property_readonly("K", &PinholeCamera::K, "the 3 x 3 intrinsic matrix")
      .def_property_readonly("center_in_world", &PinholeCamera::center_in_world)
      .def(
          "check", [](const PinholeCamera& c) { c.Check("PinholeCamera"); },
          "Raises InputError naming the field when the camera is not usable.")
      .def(
          "project",
          [](const PinholeCamera& c, const py::object& points_in_world) {
            const auto points = VectorsOf<3>(points_in_world, "points_in_world");
            std::vector<Eigen::Vector2d> pixels(points.size());
            for (size_t i = 0; i < points.size(); ++i) {
              if (!ProjectWorldPoint(c, points[i], &pixels[i])) pixels[i].setConstant(std::nan(""));
            }
            return VectorsArray<2>(pixels);
          },
          py::arg("points_in_world"), "Pixels of world points, float64 (N, 2); NaN behind the camera.")
      .def(
          "unproject",
          [](const PinholeCamera& c, const py::object& pixels_px) {
            const auto pixels = VectorsOf<2>(pixels_px, "pixels_px");
            std::vector<Eigen::Vector3d> rays(pixels.size());
            for (size_t i = 0; i < pixels.size(); ++i) rays[i] = UnprojectPixel(c, pixels[i]);
            return VectorsArray<3>(rays);
          },
          py::arg("pixels_px"),
          "Rays of pixels in the camera frame with z = 1 (depth * ray = point), (N, 3).")
      .def(
          "to_dict",
          [](const PinholeCamera& c) {
            return FromJsonValue(nlohmann::ordered_json::parse(CameraToJson(c)));
          },
          "The JSON form of camera files.")
      .def_static(
          "from_dict",
          [](const py::dict& dict) { return ParseCameraJson(ToJsonValue(dict).dump(), "camera dict"); },
          py::arg("dict"), "A camera from its JSON form; raises InputError naming the field.")
      .def("__repr__", [](const PinholeCamera& c) {
        const Eigen::Vector3d center = c.center_in_world();
        return fmt::format(
            "<lidarshop.PinholeCamera {} x {} px, f {:.1f} px, centre ({:.3f}, {:.3f}, {:.3f}) m>",
            c.width_px, c.height_px, c.fx_px, center.x(), center.y(), center.z());
      });
  m.def("camera_looking_at", &CameraLookingAt, py::arg("eye"), py::arg("target"), py::arg("width_px"),
        py::arg("height_px"), py::arg("horizontal_fov_deg"),
        "An undistorted camera at `eye` looking at `target` (world z up), focal length from the horizontal "
        "field of view.");
  m.def("read_camera", &ReadCameraJson, py::arg("path"), "Reads a camera file (docs/recolor.md).");
  m.def(
      "write_camera", [](const std::string& path, const PinholeCamera& c) { WriteCameraJson(path, c); },
      py::arg("path"), py::arg("camera"), "Writes a camera file, atomically.");
}

void BindCorrespondences(py::module_& m) {
  m.def(
      "read_correspondences",
      [](const std::string& path, const Scan* scan) {
        return CorrespondenceDict(ReadCorrespondences(path, scan));
      },
      py::arg("path"), py::arg("scan") = nullptr,
      "A correspondence file (docs/recolor.md) as a dict: kind ('pixel-point', 'landmark', 'pixel-pixel') "
      "and "
      "its arrays (pixels/points, source/target or pixels_a/pixels_b) and image_size_px. Pairs given by scan "
      "cell need the scan (their world points come from it).");
  m.def(
      "parse_correspondences",
      [](const py::object& pairs, const Scan* scan) {
        return CorrespondenceDict(ParseCorrespondences(ToJsonValue(pairs).dump(), "correspondences", scan));
      },
      py::arg("pairs"), py::arg("scan") = nullptr,
      "The same for the JSON form as a dict ({'pairs': [{'pixel': [u, v], 'cell': [row, col]}, ...]}).");
}

void BindResection(py::module_& m) {
  py::class_<ResectionResult>(m, "ResectionResult", "The camera that took a photo, from its pairs.")
      .def_readonly("camera", &ResectionResult::camera)
      .def_readonly("projection", &ResectionResult::projection, "P (3 x 4) of the DLT on the inliers")
      .def_property_readonly(
          "reprojection_error_px",
          [](const ResectionResult& r) { return VectorArray(r.reprojection_error_px); },
          "per pair, with `camera`")
      .def_property_readonly(
          "inlier", [](const ResectionResult& r) { return BoolArray(r.inlier); }, "bool per pair")
      .def_readonly("num_inliers", &ResectionResult::num_inliers)
      .def_readonly("rms_px", &ResectionResult::rms_px)
      .def_readonly("dlt_rms_px", &ResectionResult::dlt_rms_px)
      .def_readonly("ransac_iterations", &ResectionResult::ransac_iterations)
      .def("summary", &ResectionResult::Summary)
      .def("__repr__",
           [](const ResectionResult& r) { return "<lidarshop.ResectionResult " + r.Summary() + ">"; });
  m.def(
      "resection",
      [](const py::object& pixels, const py::object& points, const py::object& options,
         const py::kwargs& kwargs) {
        const std::vector<PixelPointPair> pairs = PixelPointPairsOf(pixels, points);
        const ResectionOptions resection_options = OptionsOf<ResectionOptions>(options, kwargs);
        py::gil_scoped_release release;
        return Resection(pairs, resection_options);
      },
      py::arg("pixels"), py::arg("points"), py::arg("options") = py::none(),
      "The camera from >= 6 photo pixels (N, 2) and their world points (N, 3): normalized DLT, RANSAC, "
      "Levenberg-Marquardt (ResectionOptions; width_px and height_px are required). A ResectionResult.");
  m.def(
      "resect_with_intrinsics",
      [](const py::object& pixels, const py::object& points, const PinholeCamera& intrinsics,
         const py::object& options, const py::kwargs& kwargs) {
        const std::vector<PixelPointPair> pairs = PixelPointPairsOf(pixels, points);
        const ResectionOptions resection_options = OptionsOf<ResectionOptions>(options, kwargs);
        py::gil_scoped_release release;
        return ResectWithIntrinsics(pairs, intrinsics, resection_options);
      },
      py::arg("pixels"), py::arg("points"), py::arg("intrinsics"), py::arg("options") = py::none(),
      "The pose only, with known intrinsics (>= 4 pairs; planar targets allowed). A ResectionResult.");
  py::class_<AutoResectionResult>(m, "AutoResectionResult",
                                  "The camera of a photo found from the scan alone, with its pairs.")
      .def_readonly("camera", &AutoResectionResult::camera)
      .def_property_readonly(
          "pixels",
          [](const AutoResectionResult& r) {
            std::vector<Eigen::Vector2d> v;
            for (const PixelPointPair& p : r.pairs) v.push_back(p.pixel_px);
            return v;
          },
          "the last round's photo pixels")
      .def_property_readonly(
          "points",
          [](const AutoResectionResult& r) {
            std::vector<Eigen::Vector3d> v;
            for (const PixelPointPair& p : r.pairs) v.push_back(p.point_in_world);
            return v;
          },
          "their world points")
      .def_property_readonly(
          "inlier", [](const AutoResectionResult& r) { return BoolArray(r.inlier); }, "bool per pair")
      .def_readonly("inliers", &AutoResectionResult::inliers)
      .def_readonly("inlier_share", &AutoResectionResult::inlier_share)
      .def_readonly("rms_px", &AutoResectionResult::rms_px)
      .def_readonly("rms_work_px", &AutoResectionResult::rms_work_px)
      .def_readonly("rounds", &AutoResectionResult::rounds)
      .def_readonly("check_pairs", &AutoResectionResult::check_pairs,
                    "SIFT pairs ratio-tested over the whole rendering from the final camera")
      .def_readonly("check_agree", &AutoResectionResult::check_agree,
                    "of those, the ones the camera explains")
      .def_readonly("check_alt_inliers", &AutoResectionResult::check_alt_inliers,
                    "of those, the most another camera explains (PnP RANSAC on them alone)")
      .def_readonly("trace", &AutoResectionResult::trace, "what the rounds did")
      .def_readonly("search_view", &AutoResectionResult::search_view)
      .def_readonly("method", &AutoResectionResult::method,
                    "'features', or 'silhouettes' (a rough pose's fallback: recolor/silhouette_alignment.h)")
      .def_readonly("silhouette_edge_share", &AutoResectionResult::silhouette_edge_share,
                    "silhouettes: share of the scan's outlines on a photo edge")
      .def_readonly("silhouette_mutual_information", &AutoResectionResult::silhouette_mutual_information,
                    "silhouettes: mutual information of the scan's intensity and the photo, nats")
      .def("summary", &AutoResectionResult::Summary)
      .def("__repr__", [](const AutoResectionResult& r) {
        return "<lidarshop.AutoResectionResult " + r.Summary() + ">";
      });
  m.def(
      "auto_resection",
      [](const Scan& scan, const py::object& photo, const std::optional<PinholeCamera>& intrinsics,
         const py::object& rough_world_from_camera, const py::object& options, const py::kwargs& kwargs) {
        const cv::Mat image = ArrayToMat(photo, CV_8U, 3, -1, -1, "photo");
        std::optional<Eigen::Matrix4d> rough;
        if (!rough_world_from_camera.is_none())
          rough = ArrayToMatrix(rough_world_from_camera, "rough_world_from_camera");
        const AutoResectionOptions auto_options = OptionsOf<AutoResectionOptions>(options, kwargs);
        py::gil_scoped_release release;
        return AutoResection(scan, image, auto_options, intrinsics, rough);
      },
      py::arg("scan"), py::arg("photo"), py::arg("intrinsics") = py::none(),
      py::arg("rough_world_from_camera") = py::none(), py::arg("options") = py::none(),
      "The camera of a photo (uint8 RGB) from the scan alone, no pairs (recolor/auto_resection.h): known "
      "intrinsics or a field-of-view search, from the scanner centre or a rough pose (4 x 4). Raises "
      "InputError "
      "when no camera is supported. An AutoResectionResult.");
}

void BindAlign(py::module_& m) {
  // The described fields (model, scale, rms_m, ...; to_dict() gives `lidarshop align --json`), with the
  // per-pair lists as NumPy arrays and the matrices, which are not JSON.
  BindStruct<LandmarkAlignment>(m, true)
      .def_readonly("target_from_source", &LandmarkAlignment::target_from_source)
      .def_property_readonly(
          "residual_m", [](const LandmarkAlignment& a) { return VectorArray(a.residual_m); },
          "per pair, metres");
  BindStruct<PhotoPairModel>(m, true)
      .def_readonly("matrix", &PhotoPairModel::matrix)
      .def_property_readonly(
          "error_px", [](const PhotoPairModel& p) { return VectorArray(p.error_px); }, "per pair, pixels")
      .def_property_readonly(
          "inlier", [](const PhotoPairModel& p) { return BoolArray(p.inlier); }, "bool per pair");
  m.def(
      "align_landmarks",
      [](const py::object& source, const py::object& target, bool with_scale) {
        const auto a = VectorsOf<3>(source, "source"), b = VectorsOf<3>(target, "target");
        if (a.size() != b.size()) {
          throw py::value_error(fmt::format("source and target: {} and {} landmarks", a.size(), b.size()));
        }
        std::vector<PointPair> pairs(a.size());
        for (size_t i = 0; i < pairs.size(); ++i) pairs[i] = {a[i], b[i]};
        return AlignLandmarks(pairs, with_scale, "landmarks");
      },
      py::arg("source"), py::arg("target"), py::arg("with_scale") = false,
      "target_from_source from >= 3 landmark pairs (N, 3) (Umeyama; a similarity with_scale).");
  const auto photo_pairs = [](const py::object& pixels_a, const py::object& pixels_b) {
    const auto a = VectorsOf<2>(pixels_a, "pixels_a"), b = VectorsOf<2>(pixels_b, "pixels_b");
    if (a.size() != b.size())
      throw py::value_error(fmt::format("pixels_a and pixels_b: {} and {} pixels", a.size(), b.size()));
    std::vector<PixelPair> pairs(a.size());
    for (size_t i = 0; i < pairs.size(); ++i) pairs[i] = {a[i], b[i]};
    return pairs;
  };
  m.def(
      "estimate_homography",
      [photo_pairs](const py::object& a, const py::object& b, double threshold_px) {
        return EstimateHomography(photo_pairs(a, b), threshold_px, "pixel pairs");
      },
      py::arg("pixels_a"), py::arg("pixels_b"), py::arg("threshold_px") = 3.0,
      "H with pixels_b = H pixels_a (RANSAC, >= 4 pairs). A PhotoPairModel.");
  m.def(
      "estimate_fundamental",
      [photo_pairs](const py::object& a, const py::object& b, double threshold_px) {
        return EstimateFundamental(photo_pairs(a, b), threshold_px, "pixel pairs");
      },
      py::arg("pixels_a"), py::arg("pixels_b"), py::arg("threshold_px") = 3.0,
      "F with b^T F a = 0 (RANSAC, >= 8 pairs). A PhotoPairModel.");
}

void BindRecolorScan(py::module_& m) {
  py::class_<RecolorResult>(m, "RecolorResult", "The outcome of recolor().")
      .def_readonly("scan", &RecolorResult::scan, "the scan with its colour replaced where recoloured")
      .def_property_readonly(
          "recolored", [](const RecolorResult& r) { return MatToArray(r.recolored); },
          "uint8 (rows, cols): 255 = the point took the photo's colour")
      .def_readonly("returns", &RecolorResult::returns)
      .def_readonly("recolored_count", &RecolorResult::recolored_count)
      .def_readonly("outside_image", &RecolorResult::outside_image)
      .def_readonly("hidden", &RecolorResult::hidden)
      .def_readonly("uncertain", &RecolorResult::uncertain)
      .def_readonly("edge_margin_px", &RecolorResult::edge_margin_px)
      .def_property_readonly(
          "uncertain_mask", [](const RecolorResult& r) { return MatToArray(r.uncertain_mask); },
          "uint8 (rows, cols): 255 = kept its colour near an occluding edge")
      .def("summary", &RecolorResult::Summary)
      .def("__repr__",
           [](const RecolorResult& r) { return "<lidarshop.RecolorResult " + r.Summary() + ">"; });
  m.def(
      "recolor",
      [](const Scan& scan, const py::object& photo, const PinholeCamera& camera, const py::object& options,
         const py::kwargs& kwargs) {
        const cv::Mat image = ArrayToMat(photo, CV_8U, 3, camera.height_px, camera.width_px, "photo");
        const RecolorOptions recolor_options = OptionsOf<RecolorOptions>(options, kwargs);
        py::gil_scoped_release release;
        return RecolorScan(scan, image, camera, recolor_options);
      },
      py::arg("scan"), py::arg("photo"), py::arg("camera"), py::arg("options") = py::none(),
      "Colours the scan's points the camera sees from the photo (uint8 RGB (height_px, width_px, 3)); hidden "
      "points keep their colour (RecolorOptions: z-buffer or exact segment visibility). A RecolorResult.");
  py::class_<Photo>(m, "Photo", "A synthetic photo of a scene: picture, labels and depth per pixel.")
      .def_property_readonly(
          "image", [](const Photo& p) { return MatToArray(p.image); }, "uint8 RGB (height, width, 3)")
      .def_property_readonly(
          "label", [](const Photo& p) { return MatToArray(p.label); }, "int32: the object seen, -1 = none")
      .def_property_readonly(
          "depth_m", [](const Photo& p) { return MatToArray(p.depth_m); }, "float32, +inf = background");
  m.def(
      "render_photo",
      [](const py::object& scene, const PinholeCamera& camera, const py::object& options,
         const py::kwargs& kwargs) {
        const SceneDescription description = SceneOf(scene);
        const PhotoOptions photo_options = OptionsOf<PhotoOptions>(options, kwargs);
        py::gil_scoped_release release;
        return RenderPhoto(description, camera, photo_options);
      },
      py::arg("scene"), py::arg("camera"), py::arg("options") = py::none(),
      "A photo of a synthetic scene (as for scan_scene: a path, dict or built-in name) taken by `camera`.");
  m.def(
      "read_e57_photos",
      [](const std::string& path) {
        E57File file;
        {
          py::gil_scoped_release release;
          file = ReadE57(path);
        }
        py::list photos;
        for (const E57Image& image : file.images) {
          PinholeCamera camera;
          std::string why;
          const bool usable = CameraFromE57Image(image, &camera, &why);
          py::dict photo;
          photo["name"] = image.name;
          photo["projection"] = image.projection;
          photo["image"] = MatToArray(image.image);
          photo["world_from_camera"] = MatrixToArray(image.world_from_camera);
          photo["camera"] = usable ? py::cast(camera) : py::object(py::none());
          photo["why_no_camera"] = usable ? std::string() : why;
          photos.append(photo);
        }
        return photos;
      },
      py::arg("path"),
      "The photos stored in an E57 file (images2D): a list of dicts with name, projection, image (RGB or "
      "None "
      "when its blob does not decode), world_from_camera, camera (a PinholeCamera for pinhole entries, else "
      "None) and why_no_camera.");
}

// A camera of any model (geometry/camera_model.h) from a PinholeCamera or a dict of the camera JSON.
Camera CameraModelOf(const py::handle& camera, const std::string& what) {
  if (py::isinstance<PinholeCamera>(camera)) return CameraFromPinhole(camera.cast<PinholeCamera>());
  if (!py::isinstance<py::dict>(camera))
    throw py::type_error(what + ": expected a PinholeCamera or a dict of the camera JSON (docs/recolor.md)");
  const std::string text = py::module_::import("json").attr("dumps")(camera).cast<std::string>();
  return ParseCameraModelJson(text, what);
}

// The options of a station colouring: RecolorOptions (`options` and keywords) for the occlusion test, without
// the edge guard unless asked for (PhotosRecolorOptions::visibility), and the station's own fields.
PhotosRecolorOptions PhotosOptionsOf(const py::object& options, const py::kwargs& kwargs,
                                     bool equalize_exposure, bool blend_seams, int seam_band_cells,
                                     bool nearest_photo) {
  PhotosRecolorOptions result;
  const bool guard_given = kwargs.contains("edge_guard") || !options.is_none();
  result.visibility = OptionsOf<RecolorOptions>(options, kwargs);
  if (!guard_given) result.visibility.edge_guard = false;
  result.equalize_exposure = equalize_exposure;
  result.blend_seams = blend_seams;
  result.seam_band_cells = seam_band_cells;
  result.nearest_photo = nearest_photo;
  result.Check();
  return result;
}

void BindStationRecolor(py::module_& m) {
  py::class_<PhotosRecolorResult>(m, "PhotosRecolorResult",
                                  "The outcome of recolor_from_photos() / recolor_from_e57_images().")
      .def_readonly("scan", &PhotosRecolorResult::scan, "the scan with its colour set where a photo saw it")
      .def_property_readonly(
          "photo_index", [](const PhotosRecolorResult& r) { return MatToArray(r.photo_index); },
          "uint16 (rows, cols): 1 + the photo that coloured the cell, 0 = none")
      .def_property_readonly(
          "gains",
          [](const PhotosRecolorResult& r) {
            py::array_t<double> gains({static_cast<py::ssize_t>(r.gains.size()), py::ssize_t{3}});
            auto view = gains.mutable_unchecked<2>();
            for (size_t i = 0; i < r.gains.size(); ++i) {
              for (int ch = 0; ch < 3; ++ch) view(static_cast<py::ssize_t>(i), ch) = r.gains[i][ch];
            }
            return gains;
          },
          "float64 (photos, 3): each photo's RGB gain relative to photo 0")
      .def_readonly("returns", &PhotosRecolorResult::returns)
      .def_readonly("coloured", &PhotosRecolorResult::coloured)
      .def_readonly("constraints", &PhotosRecolorResult::constraints)
      .def_readonly("seam_edges", &PhotosRecolorResult::seam_edges)
      .def_readonly("blended", &PhotosRecolorResult::blended)
      .def("summary", &PhotosRecolorResult::Summary)
      .def("__repr__", [](const PhotosRecolorResult& r) {
        return "<lidarshop.PhotosRecolorResult " + r.Summary() + ">";
      });
  m.def(
      "recolor_from_photos",
      [](const Scan& scan, const py::list& photos, const py::list& cameras, bool equalize_exposure,
         bool blend_seams, int seam_band_cells, bool nearest_photo, const py::object& options,
         const py::kwargs& kwargs) {
        if (photos.size() != cameras.size())
          throw py::value_error(
              fmt::format("photos and cameras: {} photos but {} cameras", photos.size(), cameras.size()));
        std::vector<CameraPhoto> given;
        for (size_t i = 0; i < photos.size(); ++i) {
          const std::string what = fmt::format("cameras[{}]", i);
          const Camera camera = CameraModelOf(cameras[i], what);
          given.push_back({ArrayToMat(photos[i], CV_8U, 3, camera.height_px(), camera.width_px(),
                                      fmt::format("photos[{}]", i)),
                           camera});
        }
        const PhotosRecolorOptions photo_options =
            PhotosOptionsOf(options, kwargs, equalize_exposure, blend_seams, seam_band_cells, nearest_photo);
        py::gil_scoped_release release;
        return RecolorFromPhotos(scan, given, photo_options);
      },
      py::arg("scan"), py::arg("photos"), py::arg("cameras"), py::arg("equalize_exposure") = true,
      py::arg("blend_seams") = true, py::arg("seam_band_cells") = 12, py::arg("nearest_photo") = false,
      py::arg("options") = py::none(),
      "Colours the scan from several photos at once (uint8 RGB arrays) with their cameras (PinholeCamera or "
      "a dict of the camera JSON, any model: docs/recolor.md): per point the best photo that sees it, "
      "exposure equalised to photo 0's, seams blended (`recolor --photo P --camera C ...`). RecolorOptions "
      "(`options`, keywords) set the occlusion test. A PhotosRecolorResult.");
  m.def(
      "recolor_from_e57_images",
      [](const std::string& path, int scan_index, bool equalize_exposure, bool blend_seams,
         int seam_band_cells, bool nearest_photo, const py::object& options, const py::kwargs& kwargs) {
        const PhotosRecolorOptions photo_options =
            PhotosOptionsOf(options, kwargs, equalize_exposure, blend_seams, seam_band_cells, nearest_photo);
        py::gil_scoped_release release;
        const E57File file = ReadE57(path);
        if (scan_index < 0 || scan_index >= static_cast<int>(file.scans.size()))
          throw OptionsError(fmt::format("scan_index {} is out of range: {} holds {} scan(s)", scan_index,
                                         path, file.scans.size()));
        const E57StationPhotos station = StationPhotosOfE57(file, scan_index);
        if (station.photos.empty())
          ThrowInputError(path, "images2D", "",
                          fmt::format("no image of scan {} holds a photo with a camera ({} image(s))",
                                      scan_index, file.images.size()));
        return RecolorFromPhotos(file.scans[scan_index], station.photos, photo_options);
      },
      py::arg("path"), py::arg("scan_index") = 0, py::arg("equalize_exposure") = true,
      py::arg("blend_seams") = true, py::arg("seam_band_cells") = 12, py::arg("nearest_photo") = false,
      py::arg("options") = py::none(),
      "Colours scan `scan_index` of an E57 file from its own images (every images2D entry of that scan with "
      "a camera: `recolor --from-e57-images`). A PhotosRecolorResult.");
}

}  // namespace

void BindRecolor(py::module_& m) {
  BindCamera(m);
  BindCorrespondences(m);
  BindResection(m);
  BindAlign(m);
  BindRecolorScan(m);
  BindStationRecolor(m);
}

}  // namespace lidarshop::python
