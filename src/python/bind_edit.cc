// The editing algorithms: segment, fill, remove an object, inpaint, Poisson; their result classes.
#include <cstring>
#include <filesystem>
#include <optional>

#include <Python.h>
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "lidarshop/fill/fill.h"
#include "lidarshop/fill/remove.h"
#include "lidarshop/inpaint/inpaint.h"
#include "lidarshop/poisson/poisson.h"
#include "lidarshop/render/strokes.h"
#include "lidarshop/segment/segment.h"
#include "lidarshop/site/from_stations.h"
#include "lidarshop/site/transients.h"

namespace lidarshop::python {
namespace {

// FillFromStations' result as a dict (the scan, its masks and counts).
py::dict FromStationsDict(const FromStationsResult& result) {
  py::dict out;
  out["scan"] = py::cast(result.scan);
  out["from_station"] = MatToArray(result.from_station);
  out["synthesized"] = MatToArray(result.synthesized);
  out["hole_cells"] = result.hole_cells;
  out["from_station_cells"] = result.from_station_cells;
  out["cells_per_station"] = py::cast(result.cells_per_station);
  out["synthesized_cells"] = result.synthesized_cells;
  out["no_return_cells"] = result.no_return_cells;
  out["object_cells"] = py::cast(result.object_cells);
  out["rim_cells"] = result.rim_cells;
  out["not_free_cells"] = result.not_free_cells;
  out["stations_seconds"] = result.stations_seconds;
  out["fill_seconds"] = result.fill_seconds;
  out["warnings"] = py::cast(result.warnings);
  return out;
}

}  // namespace

// ---- algorithms ----

cv::Mat MaskOf(const py::handle& mask, const Scan& scan, const std::string& what) {
  return ArrayToMat(mask, CV_8U, 1, scan.rows, scan.cols, what);
}

namespace {

// Strokes: a uint8 array of 0 / 1 (object) / 2 (background), a path (.png of the grid or painted on a render
// picture, or .json), or the JSON polylines as a dict ({"strokes": [{"label": "object", "points": [[col, row],
// ...]}]}).
cv::Mat StrokesOf(const py::handle& strokes, const Scan& scan) {
  if (py::isinstance<py::dict>(strokes)) {
    return StrokesFromJson(ToJsonValue(strokes).dump(), scan.rows, scan.cols, "strokes");
  }
  if (py::isinstance<py::str>(strokes) || py::hasattr(strokes, "__fspath__")) {
    const std::string path = py::str(py::module_::import("os").attr("fspath")(strokes));
    return ReadStrokesForScan(path, scan, "", "the scan").cells;  // a grid-sized PNG or a render picture
  }
  return ArrayToMat(strokes, CV_8U, 1, scan.rows, scan.cols, "strokes");
}

}  // namespace

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

  // The numbers come from the descriptions (inpaint/options_info.cc, poisson/options_info.cc), as the CLI's
  // --json writes them; the images are added here.
  BindStruct<ReviewStop>(m, true);
  BindStruct<InpaintResult>(m, true)
      .def_property_readonly(
          "image", [](const InpaintResult& r) { return MatToArray(r.image); },
          "float32 (H, W) or (H, W, C), the hole filled")
      .def_property_readonly(
          "fill_iteration", [](const InpaintResult& r) { return MatToArray(r.fill_iteration); },
          "int32 (H, W): iteration that filled each pixel, -1 = known")
      .def_property_readonly(
          "source_pixel", [](const InpaintResult& r) { return MatToArray(r.source_pixel); },
          "int32 (H, W, 2): (row, col) each pixel was copied from, (-1, -1) = known")
      .def("summary", &InpaintResult::Summary);
  BindStruct<PoissonResult>(m, true)
      .def_property_readonly(
          "image", [](const PoissonResult& r) { return MatToArray(r.image); },
          "float32 (H, W) or (H, W, C) (float64 for float64 input): the solution in the mask")
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
      "fill_window",
      [](const Scan& scan, const py::object& hole, const py::object& options, const py::kwargs& kwargs) {
        const cv::Mat hole_mask = MaskOf(hole, scan, "hole_mask");
        const FillOptions fill_options = OptionsOf<FillOptions>(options, kwargs);
        py::gil_scoped_release release;
        return FillScanWindow(scan, hole_mask, fill_options);
      },
      py::arg("scan"), py::arg("hole_mask"), py::arg("options") = py::none(),
      R"doc(fill() without the whole scan in its result: .scan and the per-cell images cover the window the fill
worked in (.window_row, .window_col, .window_rows, .window_cols), so a fill in a 100 M-ray station costs what
its hole costs. apply_fill(result, scan) writes it into the scan.)doc");
  m.def(
      "apply_fill",
      [](const FillResult& fill, Scan& scan) {
        py::gil_scoped_release release;
        ApplyFill(fill, &scan);
      },
      py::arg("fill"), py::arg("scan"),
      R"doc(Writes a fill_window() result into the scan it was computed from, in place: the scan then equals
fill()'s .scan.)doc");
  m.def(
      "remove_object",
      [](const Scan& scan, const py::object& strokes, const py::object& options,
         const std::optional<std::vector<Scan>>& stations, const py::kwargs& kwargs) -> py::object {
        const cv::Mat stroke_image = StrokesOf(strokes, scan);
        const RemoveOptions remove_options = OptionsOf<RemoveOptions>(options, kwargs);
        if (!stations) {
          RemoveResult result;
          {
            py::gil_scoped_release release;
            result = RemoveObject(scan, stroke_image, remove_options);
          }
          return py::cast(std::move(result));
        }
        RemoveFromStationsResult result;
        {
          py::gil_scoped_release release;
          result = RemoveObjectFromStations(scan, stroke_image, *stations, remove_options);
        }
        py::dict out;
        out["cut"] = py::cast(result.cut);
        out["hole"] = MatToArray(result.hole);
        out["filled"] = FromStationsDict(result.filled);
        out["scan"] = py::cast(result.filled.scan);
        out["behind"] = py::cast(result.behind);
        out["warnings"] = py::cast(result.warnings);
        return out;
      },
      py::arg("scan"), py::arg("strokes"), py::arg("options") = py::none(), py::kw_only(),
      py::arg("stations") = py::none(),
      "Cuts the object marked by strokes out (segment) and fills its cells grown by a margin (fill). Returns "
      "a RemoveResult: .cut (SegmentResult), .hole, .fill (FillResult), .scan, .behind. With stations=[Scan, "
      "...] (other registered stations of the site) the hole is filled first from what they measured "
      "(fill_from_stations) and a dict comes back: cut, hole, filled (as fill_from_stations), scan, behind, "
      "warnings.");
  m.def(
      "fill_from_stations",
      [](const Scan& scan, const py::object& hole, const std::vector<Scan>& stations,
         const py::object& options, const py::kwargs& kwargs) {
        const cv::Mat hole_mask = MaskOf(hole, scan, "hole_mask");
        const FromStationsOptions from_options = OptionsOf<FromStationsOptions>(options, kwargs);
        FromStationsResult result;
        {
          py::gil_scoped_release release;
          result = FillFromStations(scan, hole_mask, stations, from_options);
        }
        return FromStationsDict(result);
      },
      py::arg("scan"), py::arg("hole_mask"), py::arg("stations"), py::arg("options") = py::none(),
      R"doc(Fills a hole from what other registered stations measured behind the removed object, then synthesizes
only the rest (docs/stations.md "Filling from other stations").

stations: other Scans of the site, their world_from_scanner in one frame with the scan's. options: a
FromStationsOptions, a dict or keywords. Returns a dict: scan (the filled Scan: from_station = 1 + the station's
index where a cell was taken from it, synthesized where invented), from_station (uint8 (rows, cols)),
synthesized (uint8, 255), hole_cells, from_station_cells, cells_per_station, synthesized_cells,
no_return_cells, object_cells (per station: the removed object marked there), rim_cells, not_free_cells,
stations_seconds, fill_seconds, warnings.)doc");
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
  m.def(
      "clean",
      [](const std::vector<Scan>& stations, const py::object& options, const py::kwargs& kwargs) {
        const CleanOptions clean_options = OptionsOf<CleanOptions>(options, kwargs);
        CleanResult result;
        {
          py::gil_scoped_release release;
          result = CleanStations(stations, clean_options);
        }
        py::list removed, counts;
        for (size_t i = 0; i < stations.size(); ++i) {
          const StationTransients& found = result.transients.stations[i];
          removed.append(MatToArray(found.seen_through_by));
          py::dict count;
          count["removed"] = found.transient_cells;
          count["seen_through"] = found.seen_through_cells;
          count["confirmed"] = found.confirmed_cells;
          count["filled"] = result.filled_cells[i];
          counts.append(count);
        }
        return py::make_tuple(result.stations, removed, counts);
      },
      py::arg("stations"), py::arg("options") = py::none(),
      "Removes what moved between registered stations (a point another station's rays passed through, "
      "hitting farther) and fills the holes (docs/clean.md). Returns (cleaned Scans, removed masks: uint8 "
      "(rows, cols) per station, 1 + the index of the station that saw through, 0 elsewhere, counts: a dict "
      "per station). options: a CleanOptions, a dict or keywords.");
}

}  // namespace lidarshop::python
