// Descriptions of the point-set options (util/options.h). Not described (geometry, not options): CropOptions'
// box, polygon and origin, NormalOptions' and SurfaceOptions' viewpoint — their Check() keeps checking them.
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
#include "lidarshop/util/options.h"

namespace lidarshop {

template <>
const StructInfo& InfoOf<RansacPlaneOptions>() {
  static const StructInfo info = [] {
    StructBuilder<RansacPlaneOptions> b("RansacPlaneOptions", "RANSAC plane detection");
    b.Field(&RansacPlaneOptions::distance_threshold_m, "distance_threshold_m", "inlier distance to the plane")
        .Unit("m")
        .AboveZero();
    b.Field(&RansacPlaneOptions::max_iterations, "max_iterations", "hypotheses at most").Min(1);
    b.Field(&RansacPlaneOptions::confidence, "confidence", "stop when a better plane is this unlikely")
        .AboveZero()
        .Below(1);
    b.Field(&RansacPlaneOptions::min_inliers, "min_inliers", "sequential detection stops below this").Min(3);
    b.Field(&RansacPlaneOptions::max_planes, "max_planes", "planes at most").Min(1);
    b.Field(&RansacPlaneOptions::seed, "seed", "seed of every random choice");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<IcpOptions>() {
  static const StructInfo info = [] {
    StructBuilder<IcpOptions> b("IcpOptions", "point-to-plane ICP");
    b.Field(&IcpOptions::max_correspondence_m, "max_correspondence_m",
            "pairs farther apart are ignored at first")
        .Unit("m")
        .AboveZero();
    b.Field(&IcpOptions::min_correspondence_m, "min_correspondence_m",
            "the pair distance shrinks down to this")
        .Unit("m")
        .AboveZero();
    b.Field(&IcpOptions::min_normal_cos, "min_normal_cos", "pairs whose normals differ more are ignored")
        .Range(-1, 1);
    b.Field(&IcpOptions::max_iterations, "max_iterations", "iterations at most").Min(1);
    b.Field(&IcpOptions::min_translation_m, "min_translation_m", "converged when an update moves less")
        .Unit("m")
        .Min(0);
    b.Field(&IcpOptions::min_rotation_rad, "min_rotation_rad", "and turns less").Unit("rad").Min(0);
    b.Field(&IcpOptions::normal_neighbors, "normal_neighbors",
            "k of the fixed cloud's normals when it has none")
        .Min(3);
    b.Check([](const IcpOptions& o) {
      if (o.min_correspondence_m > o.max_correspondence_m) {
        throw OptionsFieldError("min_correspondence_m", "is above max_correspondence_m");
      }
    });
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<SiteRegistrationOptions>() {
  static const StructInfo info = [] {
    StructBuilder<SiteRegistrationOptions> b("SiteRegistrationOptions",
                                             "registration of a whole site (pose graph over station pairs)");
    b.Field(&SiteRegistrationOptions::max_moving_points, "max_moving_points",
            "points of a station moved onto another, at most")
        .Min(1);
    b.Field(&SiteRegistrationOptions::max_fixed_points, "max_fixed_points",
            "points of a station others are moved onto, at most")
        .Min(1);
    b.Field(&SiteRegistrationOptions::overlap_distance_m, "overlap_distance_m",
            "two stations overlap where their points lie this close at the poses given")
        .Unit("m")
        .AboveZero();
    b.Field(&SiteRegistrationOptions::min_overlap, "min_overlap",
            "share of a station's points near another's for the two to be a pair")
        .Range(0, 1);
    b.Field(&SiteRegistrationOptions::coarse_correspondence_m, "coarse_correspondence_m",
            "ICP pairing distance of the coarse pass (the poses' error)")
        .Unit("m")
        .AboveZero();
    b.Field(&SiteRegistrationOptions::min_fitness, "min_fitness",
            "a pair whose ICP matches less of its points is left out of the graph")
        .Range(0, 1);
    b.Field(&SiteRegistrationOptions::graph_iterations, "graph_iterations",
            "Gauss-Newton steps of the pose graph at most")
        .Min(1);
    b.Field(&SiteRegistrationOptions::rotation_scale_m, "rotation_scale_m",
            "metres per radian of rotation error in the graph")
        .Unit("m")
        .AboveZero();
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<IcpResult>() {
  static const StructInfo info = [] {
    StructBuilder<IcpResult> b("IcpResult", "a point-to-plane ICP's numbers");
    b.Field(&IcpResult::rms_m, "rms_m", "point-to-plane RMS of the last correspondences").Unit("m");
    b.Field(&IcpResult::fitness, "fitness", "share of the moving points with a correspondence at the end");
    b.Field(&IcpResult::correspondences, "correspondences", "point pairs at the end");
    b.Field(&IcpResult::iterations, "iterations", "iterations run");
    b.Field(&IcpResult::converged, "converged", "the last update moved and turned less than the thresholds");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ScanRegistrationSummary>() {
  static const StructInfo info = [] {
    using Summary = ScanRegistrationSummary;
    StructBuilder<Summary> b("ScanRegistrationSummary",
                             "the --json of register FIXED MOVING: MOVING's new pose and its ICP");
    b.Field(&Summary::world_from_scanner, "world_from_scanner",
            "the moving scan's registered pose, 4 rows of 4 (scanner to world)");
    b.Field(&Summary::rms_m, "rms_m", "point-to-plane RMS of the last correspondences").Unit("m");
    b.Field(&Summary::fitness, "fitness", "share of the moving points with a correspondence at the end");
    b.Field(&Summary::iterations, "iterations", "ICP iterations run");
    b.Field(&Summary::converged, "converged", "the last update moved and turned less than the thresholds");
    b.Field(&Summary::seconds, "seconds", "reading the scans and registering them").Unit("s");
    b.Field(&Summary::global_options, "global_options", "the global alignment's options (--global only)");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<RegisterSiteOptions>() {
  static const StructInfo info = [] {
    StructBuilder<RegisterSiteOptions> b(
        "RegisterSiteOptions", "a site's registration: the pairs' ICP (its keys here) and the site's");
    b.Flatten(&RegisterSiteOptions::icp);
    b.Field(&RegisterSiteOptions::site, "site", "the site's options");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<SiteStation>() {
  static const StructInfo info = [] {
    StructBuilder<SiteStation> b("SiteStation", "a station of a registered site");
    b.Field(&SiteStation::world_from_scanner, "world_from_scanner",
            "its registered pose, 4 rows of 4 (scanner to world)");
    b.Field(&SiteStation::moved_m, "moved_m", "how far the registration moved the scanner's origin")
        .Unit("m");
    b.Field(&SiteStation::turned_deg, "turned_deg", "and turned it").Unit("deg");
    b.Field(&SiteStation::pairs, "pairs", "its pairs in the graph");
    b.Field(&SiteStation::rms_m, "rms_m", "point-to-plane RMS over its pairs in the graph").Unit("m");
    b.Field(&SiteStation::graph_translation_m, "graph_translation_m",
            "the largest disagreement of its pairs with the graph")
        .Unit("m");
    b.Field(&SiteStation::graph_rotation_deg, "graph_rotation_deg", "and in rotation").Unit("deg");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<SitePair>() {
  static const StructInfo info = [] {
    StructBuilder<SitePair> b("SitePair", "a pair of overlapping stations, registered by the fine pass");
    b.Field(&SitePair::a, "a", "its first station's index");
    b.Field(&SitePair::b, "b", "its second station's index, > a");
    b.Field(&SitePair::overlap, "overlap", "share of b's sampled points near a's at the poses given");
    b.Field(&SitePair::in_graph, "in_graph", "its fitness reached min_fitness: the pose graph uses it");
    b.Flatten(&SitePair::icp);
    b.Field(&SitePair::graph_translation_m, "graph_translation_m",
            "after the graph: how far the poses disagree with the measurement")
        .Unit("m");
    b.Field(&SitePair::graph_rotation_deg, "graph_rotation_deg", "and by how much they turn from it")
        .Unit("deg");
    b.Field(&SitePair::a_from_b_measured, "a_from_b",
            "the measured pose, 4 rows of 4 (scanner b to scanner a)");
    b.Field(&SitePair::seconds, "seconds", "the pair's ICP").Unit("s");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<SiteStationSummary>() {
  static const StructInfo info = [] {
    StructBuilder<SiteStationSummary> b("SiteStationSummary",
                                        "a station of register --json: its files, then its "
                                        "registration (SiteStation's keys)");
    b.Field(&SiteStationSummary::index, "index", "its index, from 0 (0: FIXED)");
    b.Field(&SiteStationSummary::input, "input", "the scan read (FILE or FILE#N)");
    b.Field(&SiteStationSummary::output, "output", "the scan written; null for the fixed station")
        .NullWhenAbsent();
    b.Field(&SiteStationSummary::fixed, "fixed", "the station held");
    b.Flatten(&SiteStationSummary::registration);
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<SiteRegistrationSeconds>() {
  static const StructInfo info = [] {
    using Seconds = SiteRegistrationSeconds;
    StructBuilder<Seconds> b("SiteRegistrationSeconds", "where a site's registration spent its time");
    b.Field(&Seconds::reading, "reading", "reading the stations").Unit("s");
    b.Field(&Seconds::overlap, "overlap", "finding the overlapping pairs").Unit("s");
    b.Field(&Seconds::coarse, "coarse", "the coarse pass").Unit("s");
    b.Field(&Seconds::fine, "fine", "the fine pass").Unit("s");
    b.Field(&Seconds::graph, "graph", "the pose graph").Unit("s");
    b.Field(&Seconds::writing, "writing", "writing the moved stations").Unit("s");
    b.Field(&Seconds::total, "total", "everything").Unit("s");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<SiteRegistrationSummary>() {
  static const StructInfo info = [] {
    using Summary = SiteRegistrationSummary;
    StructBuilder<Summary> b("SiteRegistrationSummary",
                             "the --json of register FIXED MOVING1 MOVING2 ...: a site registered");
    b.Field(&Summary::stations, "stations", "every station, in order");
    b.Field(&Summary::pairs, "pairs", "every overlapping pair");
    b.Field(&Summary::graph_iterations, "graph_iterations", "Gauss-Newton steps of the pose graph taken");
    b.Field(&Summary::seconds, "seconds", "where the time went");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<EuclideanClusterOptions>() {
  static const StructInfo info = [] {
    StructBuilder<EuclideanClusterOptions> b("EuclideanClusterOptions", "Euclidean clustering");
    b.Field(&EuclideanClusterOptions::radius_m, "radius_m", "points closer than this are neighbours")
        .Unit("m")
        .AboveZero();
    b.Field(&EuclideanClusterOptions::min_points, "min_points", "smaller clusters become noise").Min(1);
    b.Field(&EuclideanClusterOptions::max_points, "max_points", "larger clusters become noise; 0 = no limit")
        .Min(0);
    b.Check([](const EuclideanClusterOptions& o) {
      if (o.max_points != 0 && o.max_points < o.min_points) {
        throw OptionsFieldError("max_points", "is below min_points");
      }
    });
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<KMeansOptions>() {
  static const StructInfo info = [] {
    StructBuilder<KMeansOptions> b("KMeansOptions", "k-means++ clustering");
    b.Field(&KMeansOptions::clusters, "clusters", "k").Min(1);
    b.Field(&KMeansOptions::max_iterations, "max_iterations", "Lloyd iterations at most").Min(1);
    b.Field(&KMeansOptions::tolerance_m, "tolerance_m", "stop when no centre moves more").Unit("m").Min(0);
    b.Field(&KMeansOptions::seed, "seed", "seed of the k-means++ seeding");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<GlobalAlignOptions>() {
  static const StructInfo info = [] {
    StructBuilder<GlobalAlignOptions> b("GlobalAlignOptions", "FPFH + RANSAC global alignment");
    b.Field(&GlobalAlignOptions::voxel_m, "voxel_m", "voxel size of the subsampling").Unit("m").AboveZero();
    b.Field(&GlobalAlignOptions::normal_radius_m, "normal_radius_m", "normal radius of the subsampled clouds")
        .Unit("m")
        .AboveZero();
    b.Field(&GlobalAlignOptions::feature_radius_m, "feature_radius_m", "FPFH radius").Unit("m").AboveZero();
    b.Field(&GlobalAlignOptions::inlier_distance_m, "inlier_distance_m",
            "a match agrees with a pose within this")
        .Unit("m")
        .AboveZero();
    b.Field(&GlobalAlignOptions::max_iterations, "max_iterations", "RANSAC triples").Min(1);
    b.Field(&GlobalAlignOptions::edge_ratio, "edge_ratio", "triples whose edges differ more are skipped")
        .AboveZero()
        .Max(1);
    b.Field(&GlobalAlignOptions::seed, "seed", "seed of the RANSAC triples");
    return b.Build();
  }();
  return info;
}

template <>
const EnumInfo& EnumInfoOf<SuperpixelMethod>() {
  static const EnumInfo info = MakeEnumInfo<SuperpixelMethod>(
      "superpixel method", {{SuperpixelMethod::kSlic, "slic", "SLIC (OpenCV ximgproc)"},
                            {SuperpixelMethod::kGraph, "graph", "Felzenszwalb graph segmentation"},
                            {SuperpixelMethod::kQuickShift, "quickshift", "QuickShift mode seeking"}});
  return info;
}

template <>
const StructInfo& InfoOf<SuperpixelOptions>() {
  static const StructInfo info = [] {
    StructBuilder<SuperpixelOptions> b("SuperpixelOptions", "superpixels of a scan's ray image");
    b.Field(&SuperpixelOptions::method, "method", "superpixel method");
    b.Field(&SuperpixelOptions::region_cells, "region_cells", "SLIC: superpixel side").Unit("cells").Min(2);
    b.Field(&SuperpixelOptions::ruler, "ruler", "SLIC: compactness").AboveZero();
    b.Field(&SuperpixelOptions::iterations, "iterations", "SLIC iterations").Min(1);
    b.Field(&SuperpixelOptions::graph_sigma, "graph_sigma", "graph: Gaussian smoothing").Unit("cells").Min(0);
    b.Field(&SuperpixelOptions::graph_k, "graph_k", "graph: larger = larger segments").AboveZero();
    b.Field(&SuperpixelOptions::graph_min_cells, "graph_min_cells", "graph: smallest segment")
        .Unit("cells")
        .Min(1);
    b.Field(&SuperpixelOptions::quickshift_kernel_size, "quickshift_kernel_size",
            "QuickShift: sigma of the density kernel")
        .Unit("cells")
        .AboveZero();
    b.Field(&SuperpixelOptions::quickshift_max_dist, "quickshift_max_dist",
            "QuickShift: longest link in the joint space of position and channels")
        .AboveZero();
    b.Field(&SuperpixelOptions::quickshift_ratio, "quickshift_ratio",
            "QuickShift: weight of the colour and range channels against position")
        .AboveZero();
    b.Field(&SuperpixelOptions::range_weight, "range_weight",
            "weight of the log-range channel against colour")
        .Min(0);
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<StatisticalOutlierOptions>() {
  static const StructInfo info = [] {
    StructBuilder<StatisticalOutlierOptions> b("StatisticalOutlierOptions", "statistical outlier removal");
    b.Field(&StatisticalOutlierOptions::neighbors, "neighbors", "k nearest neighbours").Min(1);
    b.Field(&StatisticalOutlierOptions::std_ratio, "std_ratio", "threshold in standard deviations")
        .AboveZero();
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<RadiusOutlierOptions>() {
  static const StructInfo info = [] {
    StructBuilder<RadiusOutlierOptions> b("RadiusOutlierOptions", "radius outlier removal");
    b.Field(&RadiusOutlierOptions::radius_m, "radius_m", "neighbourhood radius").Unit("m").AboveZero();
    b.Field(&RadiusOutlierOptions::min_neighbors, "min_neighbors", "other points needed within the radius")
        .Min(1);
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<CropOptions>() {
  static const StructInfo info = [] {
    StructBuilder<CropOptions> b("CropOptions",
                                 "crops by label, range and intensity (box and polygon: C++ only)");
    b.Field(&CropOptions::labels, "labels", "keep points with one of these labels; empty = any");
    b.Field(&CropOptions::min_range_m, "min_range_m", "keep points at least this far from the origin")
        .Unit("m")
        .Min(0);
    b.Field(&CropOptions::max_range_m, "max_range_m", "and at most this far; 0 = no upper bound")
        .Unit("m")
        .Min(0);
    b.Field(&CropOptions::min_intensity, "min_intensity", "keep intensities from this");
    b.Field(&CropOptions::max_intensity, "max_intensity", "up to this");
    b.Field(&CropOptions::invert, "invert", "keep the points outside instead");
    b.Check([](const CropOptions& o) {
      if (o.max_range_m != 0.0 && o.max_range_m < o.min_range_m) {
        throw OptionsFieldError("max_range_m", "is below min_range_m");
      }
      if (o.min_intensity > o.max_intensity)
        throw OptionsFieldError("max_intensity", "is below min_intensity");
    });
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<NormalOptions>() {
  static const StructInfo info = [] {
    StructBuilder<NormalOptions> b("NormalOptions", "normals and curvature (viewpoint: C++ only)");
    b.Field(&NormalOptions::neighbors, "neighbors", "k nearest points, used when radius_m is 0").Min(3);
    b.Field(&NormalOptions::radius_m, "radius_m", "all points within this radius instead; 0 = k nearest")
        .Unit("m")
        .Min(0);
    b.Field(&NormalOptions::max_neighbors, "max_neighbors", "radius mode: at most this many; 0 = all").Min(0);
    b.Field(&NormalOptions::window_cells, "window_cells", "grid mode: half-width of the window")
        .Unit("cells")
        .Min(1);
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<HoughPlaneOptions>() {
  static const StructInfo info = [] {
    StructBuilder<HoughPlaneOptions> b("HoughPlaneOptions", "Hough plane detection");
    b.Field(&HoughPlaneOptions::angle_step_deg, "angle_step_deg", "normal direction resolution")
        .Unit("deg")
        .AboveZero()
        .Max(30);
    b.Field(&HoughPlaneOptions::distance_step_m, "distance_step_m", "plane offset resolution")
        .Unit("m")
        .AboveZero();
    b.Field(&HoughPlaneOptions::max_voters, "max_voters", "points sampled to vote").Min(3);
    b.Field(&HoughPlaneOptions::max_planes, "max_planes", "planes at most").Min(1);
    b.Field(&HoughPlaneOptions::min_inliers, "min_inliers", "stop when the next plane has fewer points")
        .Min(3);
    b.Field(&HoughPlaneOptions::seed, "seed", "seed of the sample of voters");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<RegionGrowingOptions>() {
  static const StructInfo info = [] {
    StructBuilder<RegionGrowingOptions> b("RegionGrowingOptions", "region growing over the scan grid");
    b.Field(&RegionGrowingOptions::max_range_jump_ratio, "max_range_jump_ratio",
            "neighbours join when their ranges differ by at most this times the nearer")
        .AboveZero();
    b.Field(&RegionGrowingOptions::min_region_cells, "min_region_cells", "smaller regions get no label")
        .Unit("cells")
        .Min(1);
    return b.Build();
  }();
  return info;
}

template <>
const EnumInfo& EnumInfoOf<SurfaceMethod>() {
  static const EnumInfo info = MakeEnumInfo<SurfaceMethod>(
      "surface reconstruction method",
      {{SurfaceMethod::kPoisson, "poisson", "Poisson reconstruction (CGAL), watertight, needs normals"},
       {SurfaceMethod::kScaleSpace, "scale-space", "jet smoothing + advancing front (CGAL), interpolating"}});
  return info;
}

template <>
const StructInfo& InfoOf<SurfaceOptions>() {
  static const StructInfo info = [] {
    StructBuilder<SurfaceOptions> b("SurfaceOptions", "surface reconstruction from points");
    b.Field(&SurfaceOptions::method, "method", "reconstruction method");
    b.Field(&SurfaceOptions::poisson_angle_deg, "poisson_angle_deg", "Poisson: smallest triangle angle")
        .Unit("deg")
        .Range(1, 30);
    b.Field(&SurfaceOptions::poisson_radius_spacings, "poisson_radius_spacings",
            "Poisson: largest triangle size, in mean point spacings")
        .AboveZero();
    b.Field(&SurfaceOptions::poisson_distance_spacings, "poisson_distance_spacings",
            "Poisson: largest distance to the implicit surface, in mean point spacings")
        .AboveZero();
    b.Field(&SurfaceOptions::keep_within_m, "keep_within_m",
            "drop triangles farther than this from every point; 0 = keep all")
        .Unit("m")
        .Min(0);
    b.Field(&SurfaceOptions::normal_neighbors, "normal_neighbors", "k for estimated normals").Min(3);
    b.Field(&SurfaceOptions::scale_space_iterations, "scale_space_iterations", "scale-space: smoothing steps")
        .Min(0);
    b.Field(&SurfaceOptions::scale_space_neighbors, "scale_space_neighbors",
            "scale-space: neighbours per jet fit")
        .Min(6);
    b.Field(&SurfaceOptions::max_edge_m, "max_edge_m", "scale-space: longest triangle edge; 0 = no limit")
        .Unit("m")
        .Min(0);
    b.Field(&SurfaceOptions::seed, "seed", "CGAL's random choices");
    return b.Build();
  }();
  return info;
}

}  // namespace lidarshop
