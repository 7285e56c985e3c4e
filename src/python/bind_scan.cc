// Scans (channels as numpy views), meshes, files, built-in scenes and the synthetic scanner; the error types.
#include <cstring>
#include <filesystem>

#include <Python.h>
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "lidarshop/io/image_io.h"
#include "lidarshop/io/mesh_io.h"
#include "lidarshop/io/scan_header.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/scan/ray_directions.h"
#include "lidarshop/scanner/builtin_scenes.h"
#include "lidarshop/scanner/scanner.h"
#include "lidarshop/scanner/scene.h"
#include "lidarshop/scanner/site_scan.h"
#include "lidarshop/util/error.h"

namespace lidarshop::python {

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

namespace {

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
    {"intensity", &Scan::intensity, CV_32F, 1, false,
     "return strength in [0, 1]; float32 (rows, cols), None when the scan has no intensity"},
    {"color", &Scan::color, CV_8U, 3, false,
     "R G B; uint8 (rows, cols, 3), None when the scan has no colour"},
    {"label", &Scan::label, CV_32S, 1, false,
     "object label (synthetic scans), -1 where none; int32 (rows, cols) or None"},
    {"normal", &Scan::normal, CV_32F, 3, false,
     "unit surface normal, scanner frame; float32 (rows, cols, 3) or None"},
    {"curvature", &Scan::curvature, CV_32F, 1, false,
     "surface variation of the normal's neighbourhood in [0, 1/3], NaN where unknown; float32 or None"},
    {"true_range", &Scan::true_range, CV_32F, 1, false,
     "noise-free range (synthetic scans), metres; float32 or None"},
    {"synthesized", &Scan::synthesized, CV_8U, 1, false,
     "255 = created by lidarshop (e.g. a fill); uint8 or None"},
    {"from_station", &Scan::from_station, CV_8U, 1, false,
     "1 + the index of the other station a filled cell's return was taken from (fill_from_stations), 0 = "
     "not; uint8 or None"},
};

}  // namespace

void BindScan(py::module_& m) {
  py::class_<Scan> scan(m, "Scan",
                        R"doc(An organized scan: a rows x cols grid of laser rays from one scanner origin.

Every channel is a numpy array of the grid's shape in image orientation (row 0 = top = highest elevation,
column = azimuth increasing to the right). Reading a channel gives a view of the scan's memory, no copy:
writing into the array changes the scan. Assigning an array replaces the channel (a copy, converted to the
channel's dtype; the shape must match). Optional channels are None when absent and can be set to None.)doc");
  scan.def(py::init([](int rows, int cols, bool with_color, bool with_intensity) {
             if (rows <= 0 || cols <= 0) throw py::value_error("Scan: rows and cols must be > 0");
             return MakeScan(rows, cols, with_color, with_intensity);
           }),
           py::arg("rows"), py::arg("cols"), py::arg("with_color") = false, py::arg("with_intensity") = true,
           "A scan with every required channel allocated and no returns; intensity (0.5) unless "
           "with_intensity=False, colour when with_color.");
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
        spec.name,
        [channel](Scan& s) {
          // A scan read from a file may hold only its grid's rays (ray_directions.h): reading `direction`
          // makes the image, so that the array is a view of the scan as every other channel is.
          if (channel->member == &Scan::direction && s.direction.empty()) s.direction = DirectionImage(s);
          return MatToArray(s.*(channel->member));
        },
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
  scan.def_property_readonly("has_intensity", &Scan::has_intensity);
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

namespace {

std::string BuiltinSceneJson(const std::string& name) {
  const BuiltinScene* scene = FindBuiltinScene(name);
  return scene != nullptr ? scene->json : "";
}

std::string BuiltinNames() {
  std::string names;
  for (const BuiltinScene& scene : BuiltinScenes())
    names += (names.empty() ? "" : ", ") + std::string(scene.name);
  return names;
}

}  // namespace

SceneDescription SceneOf(const py::object& scene) {
  if (py::isinstance<py::dict>(scene)) {
    const std::string json = ToJsonValue(scene).dump();
    py::gil_scoped_release release;
    return ParseScene(json, "scene", fs::current_path().string());
  }
  const std::string text = py::str(py::module_::import("os").attr("fspath")(scene));
  const std::string builtin = BuiltinSceneJson(text);
  py::gil_scoped_release release;
  std::error_code not_a_file;
  if (!builtin.empty() && !fs::exists(text, not_a_file)) {
    return ParseScene(builtin, fmt::format("built-in scene '{}'", text), "");
  }
  return LoadScene(text);
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
      "Reads the first scan of a .ptx, .e57, .ply, .pcd, .las, .laz, .xyz or .pts file. Raises InputError "
      "naming "
      "the file and "
      "field.");
  m.def(
      "read_scan_header",
      [](const std::string& path) {
        nlohmann::ordered_json json;
        {
          py::gil_scoped_release release;
          json = ToJson(ReadScanHeader(path));
        }
        return FromJsonValue(json);
      },
      py::arg("path"),
      "What a scan file says about itself, without reading its points (as `lidarshop info`, "
      "docs/file-formats.md): "
      "a dict with format, size_bytes, scans (organized, rows, cols, points, channels, world_from_scanner, "
      "E57 "
      "metadata) and E57 images.");
  m.def(
      "read_scans", [](const std::string& path) { return ReadScanFile(path).scans; }, py::arg("path"),
      py::call_guard<py::gil_scoped_release>(),
      "Reads every scan of a file (E57 and PTX hold several: a site's stations, docs/stations.md) as a list "
      "of "
      "organized Scans, in the file's order, each with its pose (world_from_scanner) and name.");
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
        for (const BuiltinScene& scene : BuiltinScenes()) names.push_back(scene.name);
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
      [](const py::object& scene, const py::object& scanner) {
        SceneDescription description = SceneOf(scene);
        if (py::isinstance<ScannerOptions>(scanner)) {
          description.scanner = scanner.cast<ScannerOptions>();
        } else if (!scanner.is_none()) {
          ApplyDict(InfoOf<ScannerOptions>(), scanner, &description.scanner);
        }
        Validate(description.scanner);
        py::gil_scoped_release release;
        return SynthesizeScan(description);
      },
      py::arg("scene"), py::arg("scanner") = py::none(),
      "Scans a synthetic scene: a scene file's path, a dict of the scene-file form, or the name of a "
      "built-in "
      "scene (builtin_scenes()). scanner: a ScannerOptions replacing the scene's scanner, or a dict of "
      "fields "
      "changed in it ({'rows': 300, 'los_noise_sigma_m': 0.005}). Returns a Scan with colour, intensity, "
      "labels, normals and true ranges.");
  m.def(
      "scan_stations",
      [](const py::object& scene) {
        const SceneDescription description = SceneOf(scene);
        py::gil_scoped_release release;
        return ScanStations(description);
      },
      py::arg("scene"),
      "Scans every station of a site (a scene with \"stations\", docs/stations.md; as scan_scene: a path, "
      "dict "
      "or built-in name such as 'parking_lot_stations'): a list of Scans, in order, each with the objects "
      "there, "
      "its pose (world_from_scanner) and the name station0, station1, ... A scene with one scanner gives one "
      "Scan. write_scan(list, 'site.e57') writes them as one E57 of several data3D; read_scans reads them "
      "back.");
}

}  // namespace lidarshop::python
