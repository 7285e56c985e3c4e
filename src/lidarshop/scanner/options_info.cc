// Descriptions of the scanner's options and enums (util/options.h). Not described (geometry and colours, not
// options): ScannerOptions' position and rotate_deg (scene files give them; Check() keeps checking them),
// PhotoOptions' background, CarMeshOptions' paint, FacadeMeshOptions' colours.
#include "lidarshop/scanner/photo.h"
#include "lidarshop/scanner/primitives.h"
#include "lidarshop/scanner/scene.h"
#include "lidarshop/scanner/site_scan.h"
#include "lidarshop/scanner/station_photos.h"
#include "lidarshop/scanner/texture.h"
#include "lidarshop/util/options.h"

namespace lidarshop {

template <>
const EnumInfo& EnumInfoOf<CarStyle>() {
  static const EnumInfo info =
      MakeEnumInfo<CarStyle>("car style", {{CarStyle::kSedan, "sedan", "4.6 x 1.8 x 1.45 m"},
                                           {CarStyle::kHatchback, "hatchback", "4.0 x 1.75 x 1.5 m"},
                                           {CarStyle::kVan, "van", "van / SUV, 4.9 x 1.95 x 1.95 m"}});
  return info;
}

template <>
const EnumInfo& EnumInfoOf<TextureKind>() {
  static const EnumInfo info =
      MakeEnumInfo<TextureKind>("texture", {{TextureKind::kNone, "none", "plain colour"},
                                            {TextureKind::kChecker, "checker", "checkerboard"},
                                            {TextureKind::kGrass, "grass", "grass"},
                                            {TextureKind::kGravel, "gravel", "gravel"},
                                            {TextureKind::kBrick, "brick", "brick"}});
  return info;
}

template <>
const StructInfo& InfoOf<ScannerOptions>() {
  static const StructInfo info = [] {
    StructBuilder<ScannerOptions> b("ScannerOptions",
                                    "the synthetic scanner (position and rotation: scene files)");
    b.Field(&ScannerOptions::azimuth_min_deg, "azimuth_min_deg", "azimuth of the leftmost column, from +y")
        .Unit("deg");
    b.Field(&ScannerOptions::azimuth_max_deg, "azimuth_max_deg", "azimuth of the rightmost column")
        .Unit("deg");
    b.Field(&ScannerOptions::elevation_min_deg, "elevation_min_deg", "elevation of the bottom row")
        .Unit("deg")
        .Range(-90, 90);
    b.Field(&ScannerOptions::elevation_max_deg, "elevation_max_deg", "elevation of the top row")
        .Unit("deg")
        .Range(-90, 90);
    b.Field(&ScannerOptions::columns, "columns", "strips, left to right").Min(2);
    b.Field(&ScannerOptions::rows, "rows", "points per strip").Min(2);
    b.Field(&ScannerOptions::max_range_m, "max_range_m", "farther hits are no return")
        .Unit("m")
        .AboveZero()
        .Max(1e7);
    b.Field(&ScannerOptions::min_range_m, "min_range_m", "nearer hits are ignored").Unit("m").Min(0);
    b.Field(&ScannerOptions::los_noise_sigma_m, "los_noise_sigma_m", "Gaussian error along the ray")
        .Unit("m")
        .Min(0);
    b.Field(&ScannerOptions::orthogonal_noise_sigma_m, "orthogonal_noise_sigma_m",
            "Gaussian error perpendicular to the ray")
        .Unit("m")
        .Min(0);
    b.Field(&ScannerOptions::seed, "seed", "noise seed");
    b.Field(&ScannerOptions::intensity_falloff_m, "intensity_falloff_m",
            "range at which intensity falls to 1/e")
        .Unit("m")
        .AboveZero();
    b.Field(&ScannerOptions::filter_textures, "filter_textures",
            "band-limit textures to each ray's footprint");
    b.Field(&ScannerOptions::cast_method, "cast_method", "how rays are traced (speed only)");
    b.Field(&ScannerOptions::simd_path, "simd_path", "SIMD path of the shading (speed only; bit-identical)");
    b.Check([](const ScannerOptions& o) {
      if (o.azimuth_max_deg <= o.azimuth_min_deg || o.azimuth_max_deg - o.azimuth_min_deg > 360.0) {
        throw OptionsFieldError("azimuth_max_deg", "must be above azimuth_min_deg, at most 360 degrees on");
      }
      if (o.elevation_max_deg <= o.elevation_min_deg) {
        throw OptionsFieldError("elevation_max_deg", "must be above elevation_min_deg");
      }
      if (int64_t{o.columns} * o.rows > (int64_t{1} << 28)) {
        throw OptionsFieldError("rows", "columns x rows must be at most 2^28");
      }
      if (o.min_range_m >= o.max_range_m) throw OptionsFieldError("min_range_m", "must be below max_range_m");
    });
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<PhotoOptions>() {
  static const StructInfo info = [] {
    StructBuilder<PhotoOptions> b("PhotoOptions", "the synthetic camera (background colour: C++ only)");
    b.Field(&PhotoOptions::samples_per_axis, "samples_per_axis", "rays per pixel = samples^2").Range(1, 8);
    b.Field(&PhotoOptions::max_range_m, "max_range_m", "farther hits count as background")
        .Unit("m")
        .AboveZero();
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<PhotoSummary>() {
  static const StructInfo info = [] {
    StructBuilder<PhotoSummary> b("PhotoSummary", "a synthetic photo, in brief");
    b.Field(&PhotoSummary::model, "model", "the camera model");
    b.Field(&PhotoSummary::width_px, "width_px", "the photo's width").Unit("px");
    b.Field(&PhotoSummary::height_px, "height_px", "the photo's height").Unit("px");
    b.Field(&PhotoSummary::scene_pixels, "scene_pixels", "pixels whose centre sees the scene").Unit("px");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<CarMeshOptions>() {
  static const StructInfo info = [] {
    StructBuilder<CarMeshOptions> b("CarMeshOptions", "the procedural car (paint: C++ only)");
    b.Field(&CarMeshOptions::style, "style", "car style");
    b.Field(&CarMeshOptions::wheel_segments, "wheel_segments", "facets around each wheel").Min(8);
    b.Field(&CarMeshOptions::subdivisions, "subdivisions", "each triangle split into 4^n").Range(0, 7);
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<FacadeMeshOptions>() {
  static const StructInfo info = [] {
    StructBuilder<FacadeMeshOptions> b("FacadeMeshOptions", "the procedural facade (colours: C++ only)");
    b.Field(&FacadeMeshOptions::width, "width", "along x").Unit("m").Min(2).min_exclusive = true;
    b.Field(&FacadeMeshOptions::height, "height", "along z").Unit("m").Min(2).min_exclusive = true;
    b.Field(&FacadeMeshOptions::depth, "depth", "the slab's thickness, along y")
        .Unit("m")
        .Min(0.2)
        .min_exclusive = true;
    b.Field(&FacadeMeshOptions::floors, "floors", "floors").Range(1, 100);
    b.Field(&FacadeMeshOptions::windows_per_floor, "windows_per_floor", "windows per floor").Range(1, 200);
    return b.Build();
  }();
  return info;
}

namespace {

// A list written only when it holds something (FieldInfo::present, as for an optional member): a site's
// stations, the photos.
template <class S, class T>
void AbsentWhenEmpty(FieldInfo& field, std::vector<T> S::*member) {
  field.present = [member](const void* object) { return !(static_cast<const S*>(object)->*member).empty(); };
}

}  // namespace

template <>
const StructInfo& InfoOf<StationPhotoSummary>() {
  static const StructInfo info = [] {
    StructBuilder<StationPhotoSummary> b("StationPhotoSummary", "a station photo written with the scan");
    b.Field(&StationPhotoSummary::name, "name",
            "panorama, or the cube face: front, right, back, left, up, down");
    b.Field(&StationPhotoSummary::model, "model", "camera model: spherical or pinhole");
    b.Field(&StationPhotoSummary::width_px, "width_px", "image width").Unit("px");
    b.Field(&StationPhotoSummary::height_px, "height_px", "image height").Unit("px");
    b.Field(&StationPhotoSummary::gain, "gain", "exposure relative to photo 0");
    b.Field(&StationPhotoSummary::station, "station", "the station it was taken at (a site's photos only)");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<StationScanSummary>() {
  static const StructInfo info = [] {
    StructBuilder<StationScanSummary> b("StationScanSummary", "one station of a scanned site");
    b.Field(&StationScanSummary::index, "index", "the station's index in the scene's stations");
    b.Field(&StationScanSummary::name, "name", "its scan's name (station0, station1, ...)");
    b.Field(&StationScanSummary::position, "position", "the scanner's centre (x, y, z), world frame")
        .Unit("m");
    b.Field(&StationScanSummary::objects, "objects", "objects of the scene at this station");
    b.Field(&StationScanSummary::rows, "rows", "rows of its scan").Unit("cells");
    b.Field(&StationScanSummary::columns, "columns", "columns of its scan").Unit("cells");
    b.Field(&StationScanSummary::rays, "rays", "rays cast");
    b.Field(&StationScanSummary::returns, "returns", "rays that hit something");
    b.Field(&StationScanSummary::output, "output", "--split: its scan file");
    b.Field(&StationScanSummary::labels, "labels", "--labels: its label image (16-bit PNG)");
    b.Field(&StationScanSummary::labels_color, "labels_color", "--labels: its labels' colour picture");
    b.Field(&StationScanSummary::mesh, "mesh", "--mesh: its mesh file");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<SceneScanSeconds>() {
  static const StructInfo info = [] {
    StructBuilder<SceneScanSeconds> b("SceneScanSeconds", "wall-clock seconds per stage of a scan");
    b.Field(&SceneScanSeconds::loading, "loading", "reading or generating the scene").Unit("s");
    b.Field(&SceneScanSeconds::building, "building", "building the ray-casting scenes").Unit("s");
    b.Field(&SceneScanSeconds::casting, "casting", "ray casting").Unit("s");
    b.Field(&SceneScanSeconds::shading, "shading", "noise, colour, intensity and normals").Unit("s");
    b.Field(&SceneScanSeconds::scanning, "scanning", "the whole scans").Unit("s");
    b.Field(&SceneScanSeconds::meshing, "meshing", "meshing the scans (--mesh)").Unit("s");
    b.Field(&SceneScanSeconds::photos, "photos", "rendering the station photos (--photos)").Unit("s");
    b.Field(&SceneScanSeconds::writing, "writing", "writing every file").Unit("s");
    b.Field(&SceneScanSeconds::writing_scan, "writing_scan", "writing the scan files").Unit("s");
    b.Field(&SceneScanSeconds::writing_labels, "writing_labels", "writing the label pictures (--labels)")
        .Unit("s");
    b.Field(&SceneScanSeconds::writing_mesh, "writing_mesh", "writing the meshes (--mesh)").Unit("s");
    b.Field(&SceneScanSeconds::total, "total", "the whole command").Unit("s");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<SceneScanSummary>() {
  static const StructInfo info = [] {
    StructBuilder<SceneScanSummary> b("SceneScanSummary", "a synthetic scan: what was scanned and written");
    b.Field(&SceneScanSummary::scene, "scene", "the scene file, built-in scene or 'random scene SEED'");
    b.Field(&SceneScanSummary::output, "output", "the scan file");
    b.Field(&SceneScanSummary::labels, "labels", "--labels (one station): the label image");
    b.Field(&SceneScanSummary::labels_color, "labels_color", "--labels (one station): its colour picture");
    b.Field(&SceneScanSummary::scene_file, "scene_file", "--write-scene: the random scene's JSON");
    b.Field(&SceneScanSummary::target_label, "target_label", "label of the scene's target object, if any");
    b.Field(&SceneScanSummary::objects, "objects", "objects in the scene");
    b.Field(&SceneScanSummary::triangles, "triangles", "triangles of the largest ray-casting scene");
    b.Field(&SceneScanSummary::rows, "rows", "rows of the (first) scan").Unit("cells");
    b.Field(&SceneScanSummary::columns, "columns", "columns of the (first) scan").Unit("cells");
    b.Field(&SceneScanSummary::rays, "rays", "rays cast, every station");
    b.Field(&SceneScanSummary::returns, "returns", "rays that hit something, every station");
    b.Field(&SceneScanSummary::mesh_triangles, "mesh_triangles", "triangles of the meshes written (--mesh)");
    AbsentWhenEmpty(b.Field(&SceneScanSummary::stations, "stations", "a site's stations in order"),
                    &SceneScanSummary::stations);
    AbsentWhenEmpty(b.Field(&SceneScanSummary::photos, "photos", "the station photos written (--photos)"),
                    &SceneScanSummary::photos);
    b.Field(&SceneScanSummary::threads, "threads", "worker threads asked for (0 = all cores)");
    b.Field(&SceneScanSummary::seconds, "seconds", "wall-clock seconds per stage");
    b.Field(&SceneScanSummary::rays_per_second, "rays_per_second", "rays per second of scanning").Unit("1/s");
    b.Field(&SceneScanSummary::mesh_options, "mesh_options", "--mesh: how the meshes were made");
    return b.Build();
  }();
  return info;
}

}  // namespace lidarshop
