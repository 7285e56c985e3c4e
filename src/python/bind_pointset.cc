// The point-set toolbox (docs/points.md): filters, planes, clusters, normals, superpixels, registration.
// Every tool takes an (N, 3) array or a Scan (its valid points in the world frame, with their attributes);
// per-point flags come back as bool arrays of length N, labels as int32 arrays.
#include <cstring>
#include <optional>

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "lidarshop/pointset/clustering.h"
#include "lidarshop/pointset/features.h"
#include "lidarshop/pointset/filters.h"
#include "lidarshop/pointset/hough_planes.h"
#include "lidarshop/pointset/normals.h"
#include "lidarshop/pointset/planes.h"
#include "lidarshop/pointset/region_growing.h"
#include "lidarshop/pointset/registration.h"
#include "lidarshop/pointset/site_registration.h"
#include "lidarshop/pointset/superpixels.h"
#include "lidarshop/pointset/surface.h"
#include "lidarshop/util/error.h"

namespace lidarshop::python {

PointCloud CloudOf(const py::handle& points, const std::string& what) {
  if (py::isinstance<Scan>(points)) return ToPointCloud(points.cast<const Scan&>(), /*world=*/true);
  const py::array input = py::module_::import("numpy").attr("asarray")(points, "float32");
  if (input.ndim() != 2 || input.shape(1) != 3) {
    throw py::value_error(fmt::format("{}: expected an array of shape (N, 3) or a Scan", what));
  }
  const py::array_t<float, py::array::c_style | py::array::forcecast> rows(input);
  PointCloud cloud;
  cloud.points.resize(rows.shape(0));
  if (!cloud.points.empty()) {
    std::memcpy(cloud.points.data(), rows.data(), cloud.points.size() * sizeof(Eigen::Vector3f));
  }
  return cloud;
}

py::array_t<float> PointsArray(const std::vector<Eigen::Vector3f>& points) {
  py::array_t<float> array({static_cast<py::ssize_t>(points.size()), py::ssize_t{3}});
  if (!points.empty())
    std::memcpy(array.mutable_data(), points.data(), points.size() * sizeof(Eigen::Vector3f));
  return array;
}

std::vector<Eigen::VectorXd> RowsOf(const py::handle& values, int k, const std::string& what) {
  const py::array_t<double, py::array::c_style | py::array::forcecast> array =
      py::module_::import("numpy").attr("asarray")(values, "float64");
  if (array.ndim() != 2 || array.shape(1) != k) {
    throw py::value_error(fmt::format("{}: expected an array of shape (N, {})", what, k));
  }
  std::vector<Eigen::VectorXd> rows(array.shape(0), Eigen::VectorXd(k));
  const auto view = array.unchecked<2>();
  for (py::ssize_t i = 0; i < array.shape(0); ++i) {
    for (int j = 0; j < k; ++j) rows[i][j] = view(i, j);
  }
  return rows;
}

Eigen::Vector3f Vector3Of(const py::handle& value, const std::string& what) {
  return RowsOf(py::make_tuple(value), 3, what).front().cast<float>();
}

void SetNormals(const py::handle& normals, PointCloud* cloud) {
  const PointCloud given = CloudOf(normals, "normals");
  if (given.size() != cloud->size()) {
    throw py::value_error(fmt::format("normals: {} rows for {} points", given.size(), cloud->size()));
  }
  cloud->normals = given.points;
}

py::array BoolArray(const std::vector<uint8_t>& flags) {
  py::array_t<bool> array(static_cast<py::ssize_t>(flags.size()));
  bool* out = array.mutable_data();
  for (size_t i = 0; i < flags.size(); ++i) out[i] = flags[i] != 0;
  return std::move(array);
}

namespace {

// A per-point tool: fn(cloud, options) for a cloud of `points` and options from an object, a dict or keywords.
template <class Options, class Fn>
void DefCloudTool(py::module_& m, const char* name, Fn fn, const char* doc) {
  m.def(
      name,
      [fn](const py::object& points, const py::object& options, const py::kwargs& kwargs) {
        const PointCloud cloud = CloudOf(points);
        const Options tool_options = OptionsOf<Options>(options, kwargs);
        return fn(cloud, tool_options);
      },
      py::arg("points"), py::arg("options") = py::none(), doc);
}

void BindPointSetResults(py::module_& m) {
  py::class_<PlaneFit>(m, "PlaneFit", "A plane normal · x + offset_m = 0 and the points on it.")
      .def_property_readonly(
          "normal", [](const PlaneFit& p) { return Eigen::Vector3d(p.normal); }, "unit normal, float64 (3,)")
      .def_readonly("offset_m", &PlaneFit::offset_m)
      .def_property_readonly(
          "inliers", [](const PlaneFit& p) { return VectorArray(p.inliers); },
          "uint32 indices of the points on the plane, increasing")
      .def_readonly("rms_m", &PlaneFit::rms_m, "RMS distance of the inliers to the refitted plane, metres")
      .def_readonly("iterations", &PlaneFit::iterations)
      .def(
          "distance",
          [](const PlaneFit& p, const py::object& points) {
            const PointCloud cloud = CloudOf(points);
            std::vector<double> distance(cloud.size());
            for (size_t i = 0; i < cloud.size(); ++i) distance[i] = p.Distance(cloud.points[i]);
            return VectorArray(distance);
          },
          py::arg("points"), "Signed distances of points to the plane, metres, float64 (N,).")
      .def("__repr__", [](const PlaneFit& p) {
        return fmt::format(
            "<lidarshop.PlaneFit normal ({:.4f}, {:.4f}, {:.4f}), offset {:.4f} m, {} inliers, "
            "rms {:.4f} m>",
            p.normal.x(), p.normal.y(), p.normal.z(), p.offset_m, p.inliers.size(), p.rms_m);
      });
  py::class_<ClusterResult>(m, "ClusterResult", "Euclidean clusters: a label per point, -1 = noise.")
      .def_property_readonly(
          "labels", [](const ClusterResult& r) { return VectorArray(r.labels); }, "int32 (N,), -1 = noise")
      .def_property_readonly(
          "sizes", [](const ClusterResult& r) { return VectorArray(r.sizes); }, "points per cluster, int64")
      .def_property_readonly("num_clusters", &ClusterResult::num_clusters);
  py::class_<KMeansResult>(m, "KMeansResult", "k-means (k-means++ seeding, Lloyd iterations).")
      .def_property_readonly(
          "labels", [](const KMeansResult& r) { return VectorArray(r.labels); }, "int32 (N,)")
      .def_property_readonly(
          "centers", [](const KMeansResult& r) { return VectorsArray<3>(r.centers); }, "float64 (k, 3)")
      .def_readonly("inertia_m2", &KMeansResult::inertia_m2)
      .def_readonly("iterations", &KMeansResult::iterations);
  py::class_<IcpResult>(m, "IcpResult", "Point-to-plane ICP.")
      .def_readonly("fixed_from_moving", &IcpResult::fixed_from_moving)
      .def_readonly("rms_m", &IcpResult::rms_m)
      .def_readonly("fitness", &IcpResult::fitness, "moving points with a correspondence at the end, [0, 1]")
      .def_readonly("correspondences", &IcpResult::correspondences)
      .def_readonly("iterations", &IcpResult::iterations)
      .def_readonly("converged", &IcpResult::converged)
      .def("__repr__", [](const IcpResult& r) {
        return fmt::format("<lidarshop.IcpResult rms {:.4f} m, fitness {:.3f}, {} iterations{}>", r.rms_m,
                           r.fitness, r.iterations, r.converged ? ", converged" : "");
      });
  py::class_<GlobalAlignResult>(m, "GlobalAlignResult", "FPFH feature matching + RANSAC.")
      .def_readonly("fixed_from_moving", &GlobalAlignResult::fixed_from_moving)
      .def_readonly("matches", &GlobalAlignResult::matches)
      .def_readonly("inliers", &GlobalAlignResult::inliers)
      .def_readonly("iterations", &GlobalAlignResult::iterations);
}

void BindFilters(py::module_& m) {
  m.def(
      "voxel_downsample",
      [](const py::object& points, double voxel_m) {
        const PointCloud cloud = CloudOf(points);
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
  DefCloudTool<StatisticalOutlierOptions>(
      m, "statistical_outlier_inliers",
      [](const PointCloud& cloud, const StatisticalOutlierOptions& options) {
        std::vector<uint8_t> keep;
        {
          py::gil_scoped_release release;
          keep = StatisticalOutlierInliers(cloud, options);
        }
        return BoolArray(keep);
      },
      "True for points whose mean distance to their k neighbours is within std_ratio standard deviations "
      "of the cloud's mean (StatisticalOutlierOptions). bool (N,).");
  DefCloudTool<RadiusOutlierOptions>(
      m, "radius_outlier_inliers",
      [](const PointCloud& cloud, const RadiusOutlierOptions& options) {
        std::vector<uint8_t> keep;
        {
          py::gil_scoped_release release;
          keep = RadiusOutlierInliers(cloud, options);
        }
        return BoolArray(keep);
      },
      "True for points with at least min_neighbors others within radius_m (RadiusOutlierOptions). bool "
      "(N,).");
  m.def(
      "crop_inliers",
      [](const py::object& points, const py::object& options, const py::object& box,
         const py::object& polygon, const py::object& origin, const py::kwargs& kwargs) {
        const PointCloud cloud = CloudOf(points);
        CropOptions crop = OptionsOf<CropOptions>(options, kwargs);
        if (!box.is_none()) {
          const auto corners = RowsOf(box, 3, "box");
          if (corners.size() != 2)
            throw py::value_error("box: expected [[x_min, y_min, z_min], [x_max, y_max, z_max]]");
          crop.box = Eigen::AlignedBox3f(corners[0].cast<float>(), corners[1].cast<float>());
        }
        if (!polygon.is_none()) {
          for (const Eigen::VectorXd& corner : RowsOf(polygon, 2, "polygon"))
            crop.polygon.push_back(corner.cast<float>());
        }
        if (!origin.is_none()) crop.origin = Vector3Of(origin, "origin");
        crop.Check();
        return BoolArray(CropInliers(cloud, crop));
      },
      py::arg("points"), py::arg("options") = py::none(), py::kw_only(), py::arg("box") = py::none(),
      py::arg("polygon") = py::none(), py::arg("origin") = py::none(),
      "True for points inside the limits of CropOptions (labels and intensities need a Scan), the box "
      "[[x_min, y_min, z_min], [x_max, y_max, z_max]] and the polygon [[x, y], ...] (>= 3 corners) in the "
      "cloud's frame; ranges are measured from `origin` (default 0). bool (N,).");
  m.def(
      "random_sample_inliers",
      [](const py::object& points, int64_t count, uint64_t seed) {
        const PointCloud cloud = CloudOf(points);
        return BoolArray(RandomSampleInliers(cloud, count, seed));
      },
      py::arg("points"), py::arg("count"), py::arg("seed") = 1,
      "True for `count` points drawn without replacement (seeded). bool (N,).");
  m.def(
      "transform_scan",
      [](const Scan& scan, const py::object& b_from_world) {
        const Eigen::Matrix4d transform = ArrayToMatrix(b_from_world, "b_from_world");
        py::gil_scoped_release release;
        return TransformScan(scan, transform);
      },
      py::arg("scan"), py::arg("b_from_world"),
      "The scan moved rigidly: world_from_scanner becomes b_from_world @ world_from_scanner (points stay in "
      "the scanner frame). Raises OptionsError when the transform is not rigid.");
}

void BindShapes(py::module_& m) {
  DefCloudTool<RansacPlaneOptions>(
      m, "fit_plane_ransac",
      [](const PointCloud& cloud, const RansacPlaneOptions& options) {
        py::gil_scoped_release release;
        return FitPlaneRansac(cloud, options);
      },
      "The plane with the most inliers (RANSAC, seeded, refitted by least squares). A PlaneFit.");
  DefCloudTool<RansacPlaneOptions>(
      m, "detect_planes_ransac",
      [](const PointCloud& cloud, const RansacPlaneOptions& options) {
        py::gil_scoped_release release;
        return DetectPlanesRansac(cloud, options);
      },
      "Up to max_planes planes, one after the other on the points not yet taken. A list of PlaneFit.");
  DefCloudTool<HoughPlaneOptions>(
      m, "detect_planes_hough",
      [](const PointCloud& cloud, const HoughPlaneOptions& options) {
        py::gil_scoped_release release;
        return DetectPlanesHough(cloud, options);
      },
      "Planes by a 3-D Hough transform over (normal, offset). A list of PlaneFit.");
  DefCloudTool<EuclideanClusterOptions>(
      m, "euclidean_clusters",
      [](const PointCloud& cloud, const EuclideanClusterOptions& options) {
        py::gil_scoped_release release;
        return EuclideanClusters(cloud, options);
      },
      "Connected components of points closer than radius_m. A ClusterResult.");
  DefCloudTool<KMeansOptions>(
      m, "kmeans",
      [](const PointCloud& cloud, const KMeansOptions& options) {
        py::gil_scoped_release release;
        return KMeans(cloud, options);
      },
      "k-means of the positions. A KMeansResult.");
  m.def(
      "estimate_normals",
      [](const py::object& points, const py::object& options, const py::object& viewpoint,
         const py::kwargs& kwargs) {
        const PointCloud cloud = CloudOf(points);
        NormalOptions normal_options = OptionsOf<NormalOptions>(options, kwargs);
        if (!viewpoint.is_none()) {
          normal_options.viewpoint = Vector3Of(viewpoint, "viewpoint");
        }
        NormalResult result;
        {
          py::gil_scoped_release release;
          result = EstimateNormals(cloud, normal_options);
        }
        return py::make_tuple(PointsArray(result.normals), VectorArray(result.curvature));
      },
      py::arg("points"), py::arg("options") = py::none(), py::kw_only(), py::arg("viewpoint") = py::none(),
      "(normals float32 (N, 3), curvature float32 (N,)) by PCA of the k nearest or radius neighbours; "
      "normals turned toward `viewpoint` (default the origin: the scanner of a scan's points).");
  m.def(
      "fpfh",
      [](const py::object& points, double radius_m, const py::object& normals, double normal_radius_m) {
        PointCloud cloud = CloudOf(points);
        if (!(radius_m > 0)) throw OptionsError(fmt::format("radius_m: {} is out of range > 0", radius_m));
        if (!normals.is_none()) SetNormals(normals, &cloud);
        std::vector<Fpfh> features;
        {
          py::gil_scoped_release release;
          if (cloud.normals.empty()) {
            NormalOptions normal_options;
            normal_options.radius_m = normal_radius_m > 0 ? normal_radius_m : radius_m / 2;
            cloud.normals = EstimateNormals(cloud, normal_options).normals;
          }
          features = ComputeFpfh(cloud, radius_m);
        }
        py::array_t<float> array({static_cast<py::ssize_t>(features.size()), py::ssize_t{33}});
        if (!features.empty())
          std::memcpy(array.mutable_data(), features.data(), features.size() * sizeof(Fpfh));
        return array;
      },
      py::arg("points"), py::arg("radius_m"), py::arg("normals") = py::none(),
      py::arg("normal_radius_m") = 0.0,
      "Fast point feature histograms, float32 (N, 33), three 11-bin histograms each summing to 100. Normals: "
      "`normals` (N, 3), a Scan's own, or estimated within normal_radius_m (default radius_m / 2).");
}

void BindSurfaces(py::module_& m) {
  m.def(
      "reconstruct_surface",
      [](const py::object& points, const py::object& options, const py::object& normals,
         const py::object& viewpoint, const py::kwargs& kwargs) {
        PointCloud cloud = CloudOf(points);
        SurfaceOptions surface_options = OptionsOf<SurfaceOptions>(options, kwargs);
        if (!normals.is_none()) SetNormals(normals, &cloud);
        if (!viewpoint.is_none()) {
          surface_options.viewpoint = Vector3Of(viewpoint, "viewpoint");
        }
        py::gil_scoped_release release;
        return ReconstructSurface(cloud, surface_options);
      },
      py::arg("points"), py::arg("options") = py::none(), py::kw_only(), py::arg("normals") = py::none(),
      py::arg("viewpoint") = py::none(),
      "A TriangleMesh through the points (SurfaceOptions: 'poisson' with oriented normals — given, a Scan's, "
      "or estimated toward `viewpoint` — or 'scale-space'). docs/points.md.");
}

void BindScanTools(py::module_& m) {
  m.def(
      "scan_normals",
      [](const Scan& scan, const py::object& options, const py::kwargs& kwargs) {
        const NormalOptions normal_options = OptionsOf<NormalOptions>(options, kwargs);
        py::gil_scoped_release release;
        return WithGridNormals(scan, normal_options);
      },
      py::arg("scan"), py::arg("options") = py::none(),
      "The scan with its `normal` and `curvature` channels estimated on the grid (window_cells around each "
      "cell).");
  m.def(
      "superpixels",
      [](const Scan& scan, const py::object& options, const py::kwargs& kwargs) {
        const SuperpixelOptions superpixel_options = OptionsOf<SuperpixelOptions>(options, kwargs);
        int count = 0;
        cv::Mat labels;
        {
          py::gil_scoped_release release;
          labels = ScanSuperpixels(scan, superpixel_options, &count);
        }
        return py::make_tuple(MatToArray(labels), count);
      },
      py::arg("scan"), py::arg("options") = py::none(),
      "(labels int32 (rows, cols), count): SLIC or graph superpixels on colour and log range; -1 where no "
      "return.");
  m.def(
      "region_growing",
      [](const Scan& scan, double max_angle_deg, const py::object& options, const py::object& normal_options,
         const py::kwargs& kwargs) {
        const RegionGrowingOptions region_options = OptionsOf<RegionGrowingOptions>(options, kwargs);
        const NormalOptions normals = OptionsOf<NormalOptions>(normal_options);
        if (!(max_angle_deg > 0 && max_angle_deg <= 180)) {
          throw OptionsError(fmt::format("max_angle_deg: {} is out of range (0, 180]", max_angle_deg));
        }
        int count = 0;
        cv::Mat labels;
        {
          py::gil_scoped_release release;
          const Scan with_normals = scan.normal.empty() ? WithGridNormals(scan, normals) : scan;
          labels = SegmentByRegionGrowing(scan, region_options,
                                          NormalAngleCondition(with_normals, max_angle_deg), &count);
        }
        return py::make_tuple(MatToArray(labels), count);
      },
      py::arg("scan"), py::arg("max_angle_deg") = 10.0, py::arg("options") = py::none(),
      py::arg("normal_options") = py::none(),
      "(labels int32 (rows, cols), count): regions of grid neighbours whose normals differ by less than "
      "max_angle_deg (normals estimated with normal_options when the scan has none).");
}

void BindRegistration(py::module_& m) {
  m.def(
      "icp",
      [](const py::object& fixed, const py::object& moving, const py::object& initial,
         const py::object& options, const py::kwargs& kwargs) {
        const PointCloud fixed_cloud = CloudOf(fixed, "fixed"), moving_cloud = CloudOf(moving, "moving");
        const Eigen::Matrix4d start =
            initial.is_none() ? Eigen::Matrix4d::Identity() : ArrayToMatrix(initial, "initial");
        const IcpOptions icp_options = OptionsOf<IcpOptions>(options, kwargs);
        py::gil_scoped_release release;
        return IcpPointToPlane(fixed_cloud, moving_cloud, start, icp_options);
      },
      py::arg("fixed"), py::arg("moving"), py::arg("initial") = py::none(), py::arg("options") = py::none(),
      "Point-to-plane ICP of `moving` onto `fixed` (arrays or Scans) from `initial` fixed_from_moving. An "
      "IcpResult.");
  m.def(
      "align_globally",
      [](const py::object& fixed, const py::object& moving, const py::object& options,
         const py::kwargs& kwargs) {
        const PointCloud fixed_cloud = CloudOf(fixed, "fixed"), moving_cloud = CloudOf(moving, "moving");
        const GlobalAlignOptions align_options = OptionsOf<GlobalAlignOptions>(options, kwargs);
        py::gil_scoped_release release;
        return AlignGlobally(fixed_cloud, moving_cloud, align_options);
      },
      py::arg("fixed"), py::arg("moving"), py::arg("options") = py::none(),
      "A coarse fixed_from_moving without an initial guess (FPFH matches + RANSAC, seeded). A "
      "GlobalAlignResult.");
  m.def(
      "register_scans",
      [](const Scan& fixed, const Scan& moving, const py::object& options, const py::object& global_options,
         const py::kwargs& kwargs) {
        const IcpOptions icp_options = OptionsOf<IcpOptions>(options, kwargs);
        std::optional<GlobalAlignOptions> global;
        if (!global_options.is_none()) {
          global = py::isinstance<py::bool_>(global_options)
                       ? (global_options.cast<bool>() ? std::optional(GlobalAlignOptions{}) : std::nullopt)
                       : std::optional(OptionsOf<GlobalAlignOptions>(global_options));
        }
        ScanRegistration result;
        {
          py::gil_scoped_release release;
          result = RegisterScans(fixed, moving, icp_options, global ? &*global : nullptr);
        }
        return py::make_tuple(std::move(result.registered), result.icp);
      },
      py::arg("fixed"), py::arg("moving"), py::arg("options") = py::none(),
      py::arg("global_align") = py::none(),
      "(registered Scan, IcpResult): `moving` with a corrected world_from_scanner. global_align: True or "
      "GlobalAlignOptions for a coarse alignment first (scans whose poses are far off).");
  m.def(
      "register_site",
      [](const std::vector<Scan>& stations, int fixed, const py::object& icp, const py::object& options,
         const py::kwargs& kwargs) {
        const IcpOptions icp_options = OptionsOf<IcpOptions>(icp);
        const SiteRegistrationOptions site_options = OptionsOf<SiteRegistrationOptions>(options, kwargs);
        SiteRegistration result;
        {
          py::gil_scoped_release release;
          result = RegisterSite(stations, fixed, icp_options, site_options);
        }
        py::list registered, per_station, per_pair;
        for (size_t i = 0; i < stations.size(); ++i) {
          Scan moved = stations[i];  // shares the buffers; only the pose changes
          moved.world_from_scanner = result.stations[i].world_from_scanner;
          registered.append(moved);
          per_station.append(FromJsonValue(ToJson(result.stations[i])));
        }
        for (const SitePair& pair : result.pairs) per_pair.append(FromJsonValue(ToJson(pair)));
        return py::make_tuple(registered, per_station, per_pair);
      },
      py::arg("stations"), py::arg("fixed") = 0, py::arg("icp") = py::none(), py::arg("options") = py::none(),
      "Registers a site (docs/stations.md): pairwise point-to-plane ICP between overlapping stations and a "
      "pose "
      "graph over all pairs, stations[fixed] held. Returns (the stations with their registered "
      "world_from_scanner, a dict per station: moved_m, turned_deg, rms_m, graph residuals, pairs; a dict "
      "per "
      "pair). icp: IcpOptions or a dict; options: SiteRegistrationOptions, a dict or keywords.");
}

}  // namespace

void BindPointSets(py::module_& m) {
  BindPointSetResults(m);
  BindFilters(m);
  BindShapes(m);
  BindSurfaces(m);
  BindScanTools(m);
  BindRegistration(m);
}

}  // namespace lidarshop::python
