// The `lidarshop` Python module: a thin layer over the library (parse, check, call, return), like the CLI.
// Scans and images are numpy arrays; options are the generated classes of options_py.h; out-parameters come
// back as return values; the GIL is released around the library's long calls.
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <Python.h>
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "convert.h"
#include "lidarshop/cli/builtin_scenes.h"
#include "lidarshop/fill/fill.h"
#include "lidarshop/fill/fill_metrics.h"
#include "lidarshop/fill/remove.h"
#include "lidarshop/inpaint/acceptance.h"
#include "lidarshop/inpaint/inpaint.h"
#include "lidarshop/io/image_io.h"
#include "lidarshop/io/mesh_io.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/pointset/filters.h"
#include "lidarshop/poisson/poisson.h"
#include "lidarshop/scan/scan.h"
#include "lidarshop/scanner/scanner.h"
#include "lidarshop/scanner/scene.h"
#include "lidarshop/segment/segment.h"
#include "lidarshop/segment/strokes.h"
#include "lidarshop/util/error.h"
#include "lidarshop/verify/verify.h"
#include "options_py.h"

namespace lidarshop::python {
namespace {

namespace fs = std::filesystem;

// ---- errors ----

// lidarshop.OptionsError(ValueError), lidarshop.InputError(ValueError, OSError),
// lidarshop.CancelledError(RuntimeError). The message is the library's, unchanged.
void BindErrors(py::module_& m) {
  static PyObject* options_error = PyErr_NewExceptionWithDoc(
      "lidarshop.OptionsError",
      "An option out of its documented range, of the wrong type or unknown; the message "
      "names the key (\"patch_radius: 0 is out of range [1, 32]\").",
      PyExc_ValueError, nullptr);
  py::tuple input_bases = py::make_tuple(py::handle(PyExc_ValueError), py::handle(PyExc_OSError));
  static PyObject* input_error = PyErr_NewExceptionWithDoc(
      "lidarshop.InputError",
      "Input data that is wrong (a file that does not parse, a mask of the wrong size); "
      "the message names the file, place and field. Both a ValueError and an OSError.",
      input_bases.ptr(), nullptr);
  static PyObject* cancelled_error = PyErr_NewExceptionWithDoc(
      "lidarshop.CancelledError", "An operation stopped by its caller.", PyExc_RuntimeError, nullptr);
  m.attr("OptionsError") = py::handle(options_error);
  m.attr("InputError") = py::handle(input_error);
  m.attr("CancelledError") = py::handle(cancelled_error);
  py::register_exception_translator([](std::exception_ptr pointer) {
    try {
      if (pointer) std::rethrow_exception(pointer);
    } catch (const OptionsError& error) {
      PyErr_SetString(options_error, error.what());
    } catch (const InputError& error) {
      PyErr_SetString(input_error, error.what());
    } catch (const CancelledError& error) {
      PyErr_SetString(cancelled_error, error.what());
    }
  });
}

// ---- scans ----

struct ChannelSpec {
  const char* name;
  cv::Mat Scan::*member;
  int depth;
  int channels;
  bool required;  // always present in a scan (cannot be set to None)
  const char* doc;
};

const ChannelSpec kChannels[] = {
    {"direction", &Scan::direction, CV_32F, 3, true,
     "unit ray direction in the scanner frame, float32 (rows, cols, 3)"},
    {"valid", &Scan::valid, CV_8U, 1, true, "255 = the ray returned, 0 = no return; uint8 (rows, cols)"},
    {"range", &Scan::range, CV_32F, 1, true,
     "metres from the scanner origin, 0 where invalid; float32 (rows, cols)"},
    {"point", &Scan::point, CV_32F, 3, true, "x y z in the scanner frame, metres; float32 (rows, cols, 3)"},
    {"intensity", &Scan::intensity, CV_32F, 1, true, "return strength in [0, 1]; float32 (rows, cols)"},
    {"color", &Scan::color, CV_8U, 3, false,
     "R G B; uint8 (rows, cols, 3), None when the scan has no colour"},
    {"label", &Scan::label, CV_32S, 1, false,
     "object label (synthetic scans), -1 where none; int32 (rows, cols) or None"},
    {"normal", &Scan::normal, CV_32F, 3, false,
     "unit surface normal, scanner frame; float32 (rows, cols, 3) or None"},
    {"true_range", &Scan::true_range, CV_32F, 1, false,
     "noise-free range (synthetic scans), metres; float32 or None"},
    {"synthesized", &Scan::synthesized, CV_8U, 1, false,
     "255 = created by lidarshop (e.g. a fill); uint8 or None"},
};

void BindScan(py::module_& m) {
  py::class_<Scan> scan(m, "Scan",
                        R"doc(An organized scan: a rows x cols grid of laser rays from one scanner origin.

Every channel is a numpy array of the grid's shape in image orientation (row 0 = top = highest elevation,
column = azimuth increasing to the right). Reading a channel gives a view of the scan's memory, no copy:
writing into the array changes the scan. Assigning an array replaces the channel (a copy, converted to the
channel's dtype; the shape must match). Optional channels are None when absent and can be set to None.)doc");
  scan.def(py::init([](int rows, int cols, bool with_color) {
             if (rows <= 0 || cols <= 0) throw py::value_error("Scan: rows and cols must be > 0");
             return MakeScan(rows, cols, with_color);
           }),
           py::arg("rows"), py::arg("cols"), py::arg("with_color") = false,
           "A scan with every required channel allocated and no returns.");
  scan.def_readonly("rows", &Scan::rows);
  scan.def_readonly("cols", &Scan::cols);
  scan.def_readwrite("name", &Scan::name);
  scan.def_property(
      "world_from_scanner",
      [](py::object self) {
        // A view of the scan's own 4x4 (column-major Eigen storage): writable, kept alive by the scan.
        Scan& s = self.cast<Scan&>();
        return py::array_t<double>({4, 4}, {sizeof(double), 4 * sizeof(double)}, s.world_from_scanner.data(),
                                   self);
      },
      [](Scan& s, const py::object& value) {
        s.world_from_scanner = ArrayToMatrix(value, "world_from_scanner");
      },
      "The scanner's pose: world_from_scanner, float64 (4, 4) (a view of the scan's matrix).");
  for (const ChannelSpec& spec : kChannels) {
    const ChannelSpec* channel = &spec;
    scan.def_property(
        spec.name, [channel](const Scan& s) { return MatToArray(s.*(channel->member)); },
        [channel](Scan& s, const py::object& value) {
          if (value.is_none()) {
            if (channel->required)
              throw py::value_error(fmt::format("Scan.{} cannot be None", channel->name));
            s.*(channel->member) = cv::Mat();
            return;
          }
          s.*(channel->member) = ArrayToMat(value, channel->depth, channel->channels, s.rows, s.cols,
                                            fmt::format("Scan.{}", channel->name));
        },
        spec.doc);
  }
  scan.def_property_readonly(
      "azimuth_rad", [](const Scan& s) { return py::array(py::cast(s.grid.azimuth_rad)); },
      "azimuth of each column, radians (empty when the scan has no known grid)");
  scan.def_property_readonly(
      "elevation_rad", [](const Scan& s) { return py::array(py::cast(s.grid.elevation_rad)); },
      "elevation of each image row, radians, decreasing downwards");
  scan.def_property_readonly("has_color", &Scan::has_color);
  scan.def_property_readonly("num_cells", &Scan::num_cells);
  scan.def("count_valid", &Scan::CountValid, "Cells with a return.");
  scan.def("channel_names", &ChannelNames, "Names of the channels present.");
  scan.def("clone", &Clone, "A deep copy (every channel copied).");
  scan.def("__copy__", &Clone);
  scan.def("__deepcopy__", [](const Scan& s, py::dict) { return Clone(s); });
  scan.def(
      "check", [](const Scan& s) { CheckScan(s); }, "Raises when a channel has the wrong size or type.");
  scan.def(
      "points",
      [](const Scan& s, bool world) {
        PointCloud cloud = ToPointCloud(s, world);
        py::array_t<float> points({static_cast<py::ssize_t>(cloud.points.size()), py::ssize_t{3}});
        auto view = points.mutable_unchecked<2>();
        for (size_t i = 0; i < cloud.points.size(); ++i) {
          for (int k = 0; k < 3; ++k) view(i, k) = cloud.points[i][k];
        }
        return points;
      },
      py::arg("world") = false,
      "The valid points, float32 (N, 3), in the scanner frame or (world=True) the world.");
  scan.def("__repr__", [](const Scan& s) {
    return fmt::format("<lidarshop.Scan {} x {}, {} valid, channels {}>", s.rows, s.cols, s.CountValid(),
                       fmt::join(ChannelNames(s), " "));
  });
}

// ---- meshes ----

void BindMesh(py::module_& m) {
  py::class_<TriangleMesh> mesh(m, "TriangleMesh", "A triangle mesh (vertices in metres, in its own frame).");
  mesh.def_property_readonly(
      "vertices",
      [](const TriangleMesh& t) {
        py::array_t<double> array({static_cast<py::ssize_t>(t.vertices.size()), py::ssize_t{3}});
        auto view = array.mutable_unchecked<2>();
        for (size_t i = 0; i < t.vertices.size(); ++i) {
          for (int k = 0; k < 3; ++k) view(i, k) = t.vertices[i][k];
        }
        return array;
      },
      "float64 (V, 3), a copy");
  mesh.def_property_readonly(
      "triangles",
      [](const TriangleMesh& t) {
        py::array_t<int64_t> array({static_cast<py::ssize_t>(t.triangles.size()), py::ssize_t{3}});
        auto view = array.mutable_unchecked<2>();
        for (size_t i = 0; i < t.triangles.size(); ++i) {
          for (int k = 0; k < 3; ++k) view(i, k) = t.triangles[i][k];
        }
        return array;
      },
      "int64 (T, 3) vertex indices, a copy");
  mesh.def("__repr__", [](const TriangleMesh& t) {
    return fmt::format("<lidarshop.TriangleMesh {} vertices, {} triangles>", t.vertices.size(),
                       t.triangles.size());
  });
  m.def("read_mesh", &ReadMesh, py::arg("path"), "Reads a mesh (.obj, .ply).",
        py::call_guard<py::gil_scoped_release>());
  m.def(
      "make_primitive",
      [](const std::string& primitive, const py::object& parameters) {
        const std::string json = parameters.is_none() ? "{}" : ToJsonValue(parameters).dump();
        py::gil_scoped_release release;
        return MakePrimitive(primitive, json);
      },
      py::arg("primitive"), py::arg("parameters") = py::none(),
      "The mesh of a scene-file primitive (\"plane\", \"box\", \"sphere\", \"car\", \"mailbox\", ...) with "
      "its "
      "parameters as a dict, e.g. make_primitive(\"car\", {\"style\": \"van\"}).");
}

// ---- files and the scanner ----

std::string BuiltinSceneJson(const std::string& name) {
  for (const cli::BuiltinScene& scene : cli::BuiltinScenes()) {
    if (name == scene.name) return scene.json;
  }
  return "";
}

std::string BuiltinNames() {
  std::string names;
  for (const cli::BuiltinScene& scene : cli::BuiltinScenes())
    names += (names.empty() ? "" : ", ") + std::string(scene.name);
  return names;
}

void BindFiles(py::module_& m) {
  m.def(
      "read_scan",
      [](const std::string& path) {
        ScanFile file = ReadScanFile(path);
        if (file.scans.empty()) throw InputError(fmt::format("{}: the file holds no scan", path));
        return std::move(file.scans.front());
      },
      py::arg("path"), py::call_guard<py::gil_scoped_release>(),
      "Reads the first scan of a .ptx, .e57, .ply, .pcd, .las, .xyz or .pts file. Raises InputError naming "
      "the file and "
      "field.");
  m.def(
      "read_scans", [](const std::string& path) { return ReadScanFile(path).scans; }, py::arg("path"),
      py::call_guard<py::gil_scoped_release>(), "Reads every scan of a file (E57 and PTX hold several).");
  m.def(
      "write_scan",
      [](const py::object& scans, const std::string& path) {
        std::vector<Scan> list;
        if (py::isinstance<Scan>(scans)) {
          list.push_back(scans.cast<Scan>());
        } else {
          list = scans.cast<std::vector<Scan>>();
        }
        py::gil_scoped_release release;
        for (const Scan& scan : list) CheckScan(scan);
        WriteScanFile(path, list);
      },
      py::arg("scan"), py::arg("path"),
      "Writes a scan (or a list of scans) in the format of the path's extension (.ptx, .e57, .ply, .pcd, "
      ".las, .xyz, .pts), "
      "atomically.");
  m.def(
      "read_image",
      [](const std::string& path) {
        cv::Mat image;
        {
          py::gil_scoped_release release;
          image = ReadImage(path);
        }
        return MatToArray(image);
      },
      py::arg("path"),
      "Reads an image (.png, .jpg, .exr, .tif) keeping its depth and channels; colour as RGB. numpy array.");
  m.def(
      "write_image",
      [](const std::string& path, const py::object& image) {
        py::array array = py::module_::import("numpy").attr("asarray")(image);
        int depth = CV_8U;
        const char kind = array.dtype().kind();
        if (kind == 'f') depth = CV_32F;
        if ((kind == 'u' || kind == 'i') && array.dtype().itemsize() == 2) depth = CV_16U;
        const cv::Mat mat = ArrayToMatAnyChannels(array, depth, "image");
        py::gil_scoped_release release;
        WriteImage(path, mat);
      },
      py::arg("path"), py::arg("image"),
      "Writes an image: uint8 / bool (masks: True = 255) as 8-bit, 16-bit integers as 16-bit, floats as "
      "32-bit "
      "(.exr, .tif); (H, W, 3) is RGB. Atomic.");
  m.def(
      "builtin_scenes",
      [] {
        std::vector<std::string> names;
        for (const cli::BuiltinScene& scene : cli::BuiltinScenes()) names.push_back(scene.name);
        return names;
      },
      "Names of the scenes compiled into lidarshop (data/scenes/*.json).");
  m.def(
      "builtin_scene",
      [](const std::string& name) {
        const std::string json = BuiltinSceneJson(name);
        if (json.empty()) throw InputError(fmt::format("no built-in scene '{}': {}", name, BuiltinNames()));
        return FromJsonValue(nlohmann::ordered_json::parse(json));
      },
      py::arg("name"),
      "A built-in scene as a dict (the scene-file form, docs/scene-format.md), to change and give to "
      "scan_scene.");
  m.def(
      "scan_scene",
      [](const py::object& scene) {
        SceneDescription description;
        if (py::isinstance<py::dict>(scene)) {
          const std::string json = ToJsonValue(scene).dump();
          py::gil_scoped_release release;
          description = ParseScene(json, "scene", fs::current_path().string());
        } else {
          const std::string text = py::str(py::module_::import("os").attr("fspath")(scene));
          const std::string builtin = BuiltinSceneJson(text);
          py::gil_scoped_release release;
          if (!builtin.empty() && !fs::exists(text)) {
            description = ParseScene(builtin, fmt::format("built-in scene '{}'", text), "");
          } else {
            description = LoadScene(text);
          }
        }
        py::gil_scoped_release release;
        return SynthesizeScan(description);
      },
      py::arg("scene"),
      "Scans a synthetic scene: a scene file's path, a dict of the scene-file form, or the name of a "
      "built-in "
      "scene (builtin_scenes()). Returns a Scan with colour, intensity, labels, normals and true ranges.");
}

// ---- algorithms ----

cv::Mat MaskOf(const py::handle& mask, const Scan& scan, const std::string& what) {
  return ArrayToMat(mask, CV_8U, 1, scan.rows, scan.cols, what);
}

// Strokes: a uint8 array of 0 / 1 (object) / 2 (background), a path (.png or .json), or the JSON polylines as a
// dict ({"strokes": [{"label": "object", "points": [[col, row], ...]}]}).
cv::Mat StrokesOf(const py::handle& strokes, const Scan& scan) {
  if (py::isinstance<py::dict>(strokes)) {
    return StrokesFromJson(ToJsonValue(strokes).dump(), scan.rows, scan.cols, "strokes");
  }
  if (py::isinstance<py::str>(strokes) || py::hasattr(strokes, "__fspath__")) {
    const std::string path = py::str(py::module_::import("os").attr("fspath")(strokes));
    return ReadStrokes(path, scan.rows, scan.cols);
  }
  return ArrayToMat(strokes, CV_8U, 1, scan.rows, scan.cols, "strokes");
}

template <class Options>
Options OptionsOf(const py::object& options, const py::kwargs& kwargs) {
  Options result{};
  if (!options.is_none()) {
    if (py::isinstance<Options>(options)) {
      result = options.cast<Options>();
    } else {
      ApplyDict(InfoOf<Options>(), options, &result);  // a dict of the JSON form
    }
  }
  if (kwargs.size() > 0) ApplyDict(InfoOf<Options>(), kwargs, &result);
  Validate(result);
  return result;
}

void BindResults(py::module_& m) {
  BindStruct<SegmentTimings>(m, true);
  BindStruct<SegmentResult>(m, true)
      .def_property_readonly(
          "mask", [](const SegmentResult& r) { return MatToArray(r.mask); },
          "uint8 (rows, cols), 255 = object")
      .def_property_readonly(
          "step1_mask", [](const SegmentResult& r) { return MatToArray(r.step1_mask); },
          "two-step: the depth-dominant cut, uint8 (rows, cols), else None")
      .def_property_readonly(
          "inferred_background", [](const SegmentResult& r) { return MatToArray(r.inferred_background); },
          "two-step: ring cells marked background in step 2, uint8, else None")
      .def("summary", &SegmentResult::Summary);
  BindStruct<FillTimings>(m, true);
  BindStruct<FillResult>(m, true)
      .def_property_readonly(
          "scan", [](const FillResult& r) { return r.scan; }, "the filled Scan")
      .def_property_readonly(
          "filled", [](const FillResult& r) { return MatToArray(r.filled); },
          "uint8 (rows, cols), 255 = a hole cell given a synthesized return")
      .def_property_readonly(
          "fill_order", [](const FillResult& r) { return MatToArray(r.fill_order); },
          "int32 (rows, cols): patch iteration that filled each cell, -1 = known (patch methods)")
      .def_property_readonly(
          "source_cell", [](const FillResult& r) { return MatToArray(r.source_cell); },
          "int32 (rows, cols, 2): (row, col) each hole cell was copied from (patch methods)")
      .def("summary", &FillResult::Summary);
  BindStruct<RemoveResult>(m, true)
      .def_property_readonly(
          "hole", [](const RemoveResult& r) { return MatToArray(r.hole); },
          "uint8 (rows, cols), 255 = the filled cells (object grown by the margin)")
      .def_property_readonly(
          "behind", [](const RemoveResult& r) { return r.behind.rows > 0 ? py::cast(r.behind) : py::none(); },
          "keep_object: the surface behind the object as a Scan, else None")
      .def_property_readonly(
          "scan", [](const RemoveResult& r) { return r.fill.scan; },
          "the scan without the object (fill.scan)");

  py::class_<InpaintResult>(m, "InpaintResult", "The outcome of inpaint().")
      .def_property_readonly(
          "image", [](const InpaintResult& r) { return MatToArray(r.image); },
          "float32 (H, W) or (H, W, C), the hole filled")
      .def_property_readonly(
          "fill_iteration", [](const InpaintResult& r) { return MatToArray(r.fill_iteration); },
          "int32 (H, W): iteration that filled each pixel, -1 = known")
      .def_property_readonly(
          "source_pixel", [](const InpaintResult& r) { return MatToArray(r.source_pixel); },
          "int32 (H, W, 2): (row, col) each pixel was copied from, (-1, -1) = known")
      .def_readonly("iterations", &InpaintResult::iterations)
      .def_readonly("hole_pixels", &InpaintResult::hole_pixels)
      .def_readonly("candidates_evaluated", &InpaintResult::candidates_evaluated)
      .def_readonly("acceptance_fallbacks", &InpaintResult::acceptance_fallbacks)
      .def_readonly("rejected", &InpaintResult::rejected)
      .def_readonly("seconds", &InpaintResult::seconds)
      .def("summary", &InpaintResult::Summary);

  py::class_<PoissonResult>(m, "PoissonResult",
                            "The outcome of poisson_fill() / reconstruct_from_gradients().")
      .def_property_readonly(
          "image", [](const PoissonResult& r) { return MatToArray(r.image); },
          "float32 (H, W) or (H, W, C) (float64 for float64 input): the solution in the mask")
      .def_property_readonly("solver", [](const PoissonResult& r) { return ToString(r.solver); })
      .def_readonly("iterations", &PoissonResult::iterations)
      .def_readonly("relative_residual", &PoissonResult::relative_residual)
      .def_readonly("seconds", &PoissonResult::seconds)
      .def("summary", &PoissonResult::Summary);
}

int ImageDepth(const py::handle& image) {
  const py::array array = py::module_::import("numpy").attr("asarray")(image);
  return array.dtype().kind() == 'f' && array.dtype().itemsize() == 8 ? CV_64F : CV_32F;
}

void BindAlgorithms(py::module_& m) {
  m.def(
      "segment",
      [](const Scan& scan, const py::object& strokes, const py::object& options, const py::kwargs& kwargs) {
        const cv::Mat stroke_image = StrokesOf(strokes, scan);
        const SegmentOptions segment_options = OptionsOf<SegmentOptions>(options, kwargs);
        py::gil_scoped_release release;
        return SegmentObject(scan, stroke_image, segment_options);
      },
      py::arg("scan"), py::arg("strokes"), py::arg("options") = py::none(),
      R"doc(Cuts an object out of a scan from strokes (graph cuts on RGB+D, two-step by default).

strokes: uint8 (rows, cols) with 0 = none, 1 = object, 2 = background; or a .png / .json stroke file's path;
or the JSON polylines as a dict {"strokes": [{"label": "object", "width": 3, "points": [[col, row], ...]}]}.
options: a SegmentOptions, a dict of its JSON form, or keywords (segment(scan, strokes, method="depth")).
Returns a SegmentResult (mask: uint8 255 = object).)doc");
  m.def(
      "fill",
      [](const Scan& scan, const py::object& hole, const py::object& options, const py::kwargs& kwargs) {
        const cv::Mat hole_mask = MaskOf(hole, scan, "hole_mask");
        const FillOptions fill_options = OptionsOf<FillOptions>(options, kwargs);
        py::gil_scoped_release release;
        return FillScan(scan, hole_mask, fill_options);
      },
      py::arg("scan"), py::arg("hole_mask"), py::arg("options") = py::none(),
      R"doc(Fills a hole in a scan (gradient-domain patches + Poisson by default).

hole_mask: (rows, cols), non-zero or True = fill this cell. options: a FillOptions, a dict or keywords.
Returns a FillResult: .scan (the filled Scan, synthesized cells flagged), .filled, counts and .timings.)doc");
  m.def(
      "remove_object",
      [](const Scan& scan, const py::object& strokes, const py::object& options, const py::kwargs& kwargs) {
        const cv::Mat stroke_image = StrokesOf(strokes, scan);
        const RemoveOptions remove_options = OptionsOf<RemoveOptions>(options, kwargs);
        py::gil_scoped_release release;
        return RemoveObject(scan, stroke_image, remove_options);
      },
      py::arg("scan"), py::arg("strokes"), py::arg("options") = py::none(),
      "Cuts the object marked by strokes out (segment) and fills its cells grown by a margin (fill). Returns "
      "a "
      "RemoveResult: .cut (SegmentResult), .hole, .fill (FillResult), .scan, .behind.");
  m.def(
      "grow_hole",
      [](const py::object& hole, int margin_cells) {
        const cv::Mat mask = ArrayToMat(hole, CV_8U, 1, -1, -1, "hole");
        cv::Mat grown;
        {
          py::gil_scoped_release release;
          grown = GrowHole(mask, margin_cells);
        }
        return MatToArray(grown);
      },
      py::arg("hole"), py::arg("margin_cells"), "The hole grown by a disc of margin_cells; uint8 255/0.");
  m.def(
      "inpaint",
      [](const py::object& image, const py::object& hole, const py::object& options,
         const py::kwargs& kwargs) {
        const cv::Mat input = ArrayToMatAnyChannels(image, CV_32F, "image");
        const cv::Mat hole_mask = ArrayToMat(hole, CV_8U, 1, input.rows, input.cols, "hole_mask");
        const InpaintOptions inpaint_options = OptionsOf<InpaintOptions>(options, kwargs);
        py::gil_scoped_release release;
        return Inpaint(input, hole_mask, inpaint_options);
      },
      py::arg("image"), py::arg("hole_mask"), py::arg("options") = py::none(),
      "Patch-based inpainting (Criminisi and beyond) of an image (H, W) or (H, W, C), any number type "
      "(solved "
      "in float32), where hole_mask (H, W) is non-zero. Returns an InpaintResult (.image float32).");
  m.def(
      "poisson_fill",
      [](const py::object& image, const py::object& mask, const py::object& options,
         const py::kwargs& kwargs) {
        const cv::Mat input = ArrayToMatAnyChannels(image, ImageDepth(image), "image");
        const cv::Mat unknown = ArrayToMat(mask, CV_8U, 1, input.rows, input.cols, "mask");
        const PoissonOptions poisson_options = OptionsOf<PoissonOptions>(options, kwargs);
        py::gil_scoped_release release;
        return FillLaplace(PreparePoisson(unknown, poisson_options), input);
      },
      py::arg("image"), py::arg("mask"), py::arg("options") = py::none(),
      "Membrane (Laplace) fill: solves ∇²I = 0 where mask is non-zero, I = image elsewhere. Returns a "
      "PoissonResult (.image).");
  m.def(
      "reconstruct_from_gradients",
      [](const py::object& boundary, const py::object& gx, const py::object& gy, const py::object& mask,
         const py::object& options, const py::kwargs& kwargs) {
        const int depth = ImageDepth(boundary);
        const cv::Mat input = ArrayToMatAnyChannels(boundary, depth, "boundary");
        const cv::Mat gx_mat = ArrayToMatAnyChannels(gx, depth, "gx");
        const cv::Mat gy_mat = ArrayToMatAnyChannels(gy, depth, "gy");
        const cv::Mat unknown = ArrayToMat(mask, CV_8U, 1, input.rows, input.cols, "mask");
        const PoissonOptions poisson_options = OptionsOf<PoissonOptions>(options, kwargs);
        py::gil_scoped_release release;
        return ReconstructFromGradients(PreparePoisson(unknown, poisson_options), input, gx_mat, gy_mat);
      },
      py::arg("boundary"), py::arg("gx"), py::arg("gy"), py::arg("mask"), py::arg("options") = py::none(),
      "Poisson reconstruction ∇²I = div G where mask is non-zero (G = forward differences gx, gy), I = "
      "boundary elsewhere. Returns a PoissonResult.");
}

// ---- point sets ----
// Only the tools without an options struct for now: the point-set options are being described
// (util/options.h); each then binds like fill (BindStruct + OptionsOf).

PointCloud CloudOf(const py::handle& points) {
  const cv::Mat mat = ArrayToMat(points, CV_32F, 3, -1, -1, "points");  // (N, 3) read as N x 1 x 3
  PointCloud cloud;
  cloud.points.resize(mat.rows * mat.cols);
  std::memcpy(cloud.points.data(), mat.data, cloud.points.size() * sizeof(Eigen::Vector3f));
  return cloud;
}

py::array_t<float> PointsArray(const std::vector<Eigen::Vector3f>& points) {
  py::array_t<float> array({static_cast<py::ssize_t>(points.size()), py::ssize_t{3}});
  if (!points.empty())
    std::memcpy(array.mutable_data(), points.data(), points.size() * sizeof(Eigen::Vector3f));
  return array;
}

void BindPointSets(py::module_& m) {
  m.def(
      "voxel_downsample",
      [](const py::object& points, double voxel_m) {
        const py::array input = py::module_::import("numpy").attr("asarray")(points, "float32");
        if (input.ndim() != 2 || input.shape(1) != 3)
          throw py::value_error("points: expected an array of shape (N, 3)");
        const PointCloud cloud = CloudOf(input.attr("reshape")(input.shape(0), 1, 3));
        if (!(voxel_m > 0)) throw OptionsError(fmt::format("voxel_m: {} is out of range > 0", voxel_m));
        PointCloud result;
        {
          py::gil_scoped_release release;
          result = VoxelDownsample(cloud, voxel_m);
        }
        return PointsArray(result.points);
      },
      py::arg("points"), py::arg("voxel_m"),
      "One point per occupied cube of side voxel_m (metres), at the centroid of its points: float32 (M, 3).");
  m.def(
      "transform_scan",
      [](const Scan& scan, const py::object& b_from_world) {
        const Eigen::Matrix4d transform = ArrayToMatrix(b_from_world, "b_from_world");
        py::gil_scoped_release release;
        return TransformScan(scan, transform);
      },
      py::arg("scan"), py::arg("b_from_world"),
      "The scan moved rigidly: world_from_scanner becomes b_from_world @ world_from_scanner (points stay in "
      "the "
      "scanner frame). Raises OptionsError when the transform is not rigid.");
}

// ---- verify ----
// VerifyOptions is not described on main yet (util/options.h): its keywords are set by name below, with the
// library's defaults and checks. When InfoOf<VerifyOptions> exists, this becomes BindStruct<VerifyOptions>
// and OptionsOf<VerifyOptions>, like fill.
VerifyOptions VerifyOptionsOf(const py::kwargs& kwargs) {
  VerifyOptions options;
  for (const auto& [key, value] : kwargs) {
    const std::string name = key.cast<std::string>();
    if (name == "allowance_m") {
      options.allowance_m = value.cast<double>();
    } else if (name == "sigma_m") {
      options.sigma_m = value.cast<double>();
    } else if (name == "icp_trim_m") {
      options.icp_trim_m = value.cast<double>();
    } else if (name == "footprint_margin_cells") {
      options.footprint_margin_cells = value.cast<double>();
    } else {
      throw OptionsError(
          fmt::format("unknown verify option '{}': allowance_m, sigma_m, icp_trim_m, "
                      "footprint_margin_cells",
                      name));
    }
  }
  options.Check();
  return options;
}

void BindVerify(py::module_& m) {
  py::class_<ScanVerifyStats>(m, "ScanVerifyStats", "verify_pose's outcome for one scan alone.")
      .def_readonly("comparable_pairs", &ScanVerifyStats::comparable_pairs)
      .def_readonly("consistent_pairs", &ScanVerifyStats::consistent_pairs)
      .def_readonly("consistency", &ScanVerifyStats::consistency)
      .def_readonly("confidence", &ScanVerifyStats::confidence);
  py::class_<VerifyResult>(m, "VerifyResult", "Consistency and confidence of an object pose (thesis ch. 4).")
      .def_readonly("consistency", &VerifyResult::consistency, "[0, 1]; NaN when no comparable pair")
      .def_readonly("has_comparable_pairs", &VerifyResult::has_comparable_pairs)
      .def_readonly("comparable_pairs", &VerifyResult::comparable_pairs)
      .def_readonly("consistent_pairs", &VerifyResult::consistent_pairs)
      .def_readonly("confidence", &VerifyResult::confidence, "[0, 1]: share of the model's information seen")
      .def_readonly("icp_cost_m", &VerifyResult::icp_cost_m, "trimmed-ICP mean distance, metres (NaN: none)")
      .def_readonly("inlier_fraction", &VerifyResult::inlier_fraction)
      .def_readonly("per_scan", &VerifyResult::per_scan)
      .def("__repr__",
           [](const VerifyResult& r) { return "<lidarshop.VerifyResult " + r.BriefReport() + ">"; })
      .def("summary", &VerifyResult::BriefReport);
  m.def(
      "verify_pose",
      [](const TriangleMesh& mesh, const py::object& scans, const py::object& world_from_model,
         const py::kwargs& kwargs) {
        std::vector<Scan> list;
        if (py::isinstance<Scan>(scans)) {
          list.push_back(scans.cast<Scan>());
        } else {
          list = scans.cast<std::vector<Scan>>();
        }
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
        const VerifyOptions options = VerifyOptionsOf(kwargs);
        std::vector<VerifyResult> results;
        {
          py::gil_scoped_release release;
          const VerifierModel model = PrepareModel(mesh, ModelOptions{}, options);
          std::vector<PreparedScan> prepared;
          for (const Scan& scan : list) prepared.push_back(PrepareScan(scan));
          results = VerifyPoses(model, prepared, pose_list, options);
        }
        if (poses.ndim() == 3) return py::cast(results);
        return py::cast(results.front());
      },
      py::arg("model"), py::arg("scans"), py::arg("world_from_model"),
      R"doc(Verifies an object pose against registered scans: consistency (does the pose make physical sense:
no measured point behind the model) and confidence (how much of the model was seen), thesis eqs. 4.1-4.5.

model: a TriangleMesh in its own frame (read_mesh, make_primitive); scans: a Scan or a list (their
world_from_scanner register them); world_from_model: 4 x 4, or N x 4 x 4 for a list of results (the model
and scans are prepared once, the poses verified in parallel). Keywords: allowance_m, sigma_m, icp_trim_m,
footprint_margin_cells (VerifyOptions, verify/verify.h; defaults from the library).)doc");
  m.def("pose_from_xyz_yaw", &PoseFromXyzYaw, py::arg("x_m"), py::arg("y_m"), py::arg("z_m"),
        py::arg("yaw_deg"), py::arg("pitch_deg") = 0.0, py::arg("roll_deg") = 0.0,
        "world_from_model (4 x 4) of an object standing on the ground: translate, then yaw about +z "
        "(degrees).");
}

}  // namespace

// The described structs bound as Python classes: adding a described struct is one line here.
void BindOptionStructs(py::module_& m) {
  BindStruct<PoissonOptions>(m);
  BindStruct<MeanTestOptions>(m);
  BindStruct<RepresentativeTestOptions>(m);
  BindStruct<HistogramTestOptions>(m);
  BindStruct<SmoothTextureTestOptions>(m);
  BindStruct<AcceptanceOptions>(m);
  BindStruct<InpaintOptions>(m);
  BindStruct<CutWeights>(m);
  BindStruct<SegmentOptions>(m);
  BindStruct<FillOptions>(m);
  BindStruct<RemoveOptions>(m);
  BindStruct<FillMetricsOptions>(m);
}

}  // namespace lidarshop::python

PYBIND11_MODULE(lidarshop, m) {
  namespace python = lidarshop::python;
  m.doc() = "lidarshop: editing terrestrial LiDAR scans (organized ray images) from Python. docs/python.md.";
  python::BindErrors(m);
  python::BindOptionStructs(m);
  python::BindScan(m);
  python::BindMesh(m);
  python::BindFiles(m);
  python::BindResults(m);
  python::BindAlgorithms(m);
  python::BindPointSets(m);
  python::BindVerify(m);
}
