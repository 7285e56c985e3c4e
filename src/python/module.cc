// The `lidarshop` Python module: a thin layer over the library (parse, check, call, return), like the CLI.
// Scans and images are numpy arrays; options are the generated classes of options_py.h; out-parameters come
// back as return values; the GIL is released around the library's long calls. Each area of the library is
// bound in its own bind_*.cc.
#include "bindings.h"
#include "lidarshop/fill/fill.h"
#include "lidarshop/fill/fill_metrics.h"
#include "lidarshop/fill/remove.h"
#include "lidarshop/inpaint/acceptance.h"
#include "lidarshop/inpaint/inpaint.h"
#include "lidarshop/io/e57.h"
#include "lidarshop/io/ptx.h"
#include "lidarshop/io/render_layout.h"
#include "lidarshop/io/render_view.h"
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
#include "lidarshop/poisson/poisson.h"
#include "lidarshop/recolor/align.h"
#include "lidarshop/recolor/auto_resection.h"
#include "lidarshop/recolor/recolor.h"
#include "lidarshop/recolor/resection.h"
#include "lidarshop/scanner/photo.h"
#include "lidarshop/scanner/scene.h"
#include "lidarshop/segment/segment.h"
#include "lidarshop/site/from_stations.h"
#include "lidarshop/site/transients.h"
#include "lidarshop/verify/sweep.h"
#include "lidarshop/verify/verify.h"

namespace lidarshop::python {

// Every described options struct as a Python class: adding a described struct is one line here.
void BindOptionStructs(py::module_& m) {
  // Editing
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
  BindStruct<TransientOptions>(m);
  BindStruct<SiteRegistrationOptions>(m);
  BindStruct<FromStationsOptions>(m);
  BindStruct<CleanOptions>(m);
  // The scanner and files
  BindStruct<ScannerOptions>(m);
  BindStruct<PhotoOptions>(m);
  BindStruct<PtxReadOptions>(m);
  BindStruct<E57WriteOptions>(m);
  BindStruct<PointViewOptions>(m);
  BindStruct<PictureLayoutOptions>(m);
  // Verification
  BindStruct<ModelOptions>(m);
  BindStruct<VerifyOptions>(m);
  BindStruct<SweepOptions>(m);
  // Recolouring
  BindStruct<ResectionOptions>(m);
  BindStruct<AlignOptions>(m);
  BindStruct<AutoResectionOptions>(m);
  BindStruct<RecolorOptions>(m);
  // Point sets
  BindStruct<StatisticalOutlierOptions>(m);
  BindStruct<RadiusOutlierOptions>(m);
  BindStruct<CropOptions>(m);
  BindStruct<RansacPlaneOptions>(m);
  BindStruct<HoughPlaneOptions>(m);
  BindStruct<EuclideanClusterOptions>(m);
  BindStruct<KMeansOptions>(m);
  BindStruct<NormalOptions>(m);
  BindStruct<RegionGrowingOptions>(m);
  BindStruct<SuperpixelOptions>(m);
  BindStruct<IcpOptions>(m);
  BindStruct<GlobalAlignOptions>(m);
  BindStruct<SurfaceOptions>(m);
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
  python::BindRecolor(m);
}
