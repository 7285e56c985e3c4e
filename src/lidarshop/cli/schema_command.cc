// `lidarshop schema`: the described structs (util/options.h) as the TypeScript declarations of the editor's
// API (server/api_types.h; web/src/api_types.generated.ts, kept current by the ctest api_types_test), as the
// reference part of docs/options.md (every struct a command takes or answers; kept current by options_md_test)
// or as JSON descriptions (each field's key, kind, doc, unit, range, choices and nested struct).
#include <cstdio>
#include <filesystem>
#include <string>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "api_types.h"
#include "lidarshop/cli/command_line.h"
#include "lidarshop/cli/commands.h"
#include "lidarshop/cli/demo_page.h"
#include "lidarshop/cli/points_operations.h"
#include "lidarshop/fill/fill_metrics.h"
#include "lidarshop/inpaint/inpaint.h"
#include "lidarshop/inpaint/review.h"
#include "lidarshop/io/e57.h"
#include "lidarshop/io/formats.h"
#include "lidarshop/io/las.h"
#include "lidarshop/io/ptx.h"
#include "lidarshop/io/scan_summary.h"
#include "lidarshop/io/scan_write_plan.h"
#include "lidarshop/pointset/features.h"
#include "lidarshop/pointset/registration.h"
#include "lidarshop/pointset/site_registration.h"
#include "lidarshop/poisson/poisson.h"
#include "lidarshop/recolor/align.h"
#include "lidarshop/recolor/auto_resection.h"
#include "lidarshop/recolor/recolor.h"
#include "lidarshop/recolor/resection.h"
#include "lidarshop/recolor/station_recolor.h"
#include "lidarshop/render/render.h"
#include "lidarshop/render/render_layout.h"
#include "lidarshop/render/render_view.h"
#include "lidarshop/scan/scan_mesh.h"
#include "lidarshop/scanner/photo.h"
#include "lidarshop/scanner/scene.h"
#include "lidarshop/scanner/site_scan.h"
#include "lidarshop/site/from_stations.h"
#include "lidarshop/site/transients.h"
#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/input_file.h"
#include "lidarshop/util/options_markdown.h"
#include "lidarshop/verify/sweep.h"
#include "lidarshop/verify/verify.h"

namespace lidarshop::cli {
namespace {

// The structs docs/options.md describes: the editor's API (the same list as the TypeScript types), then what
// the commands take and answer beyond it, in the order of the page's table of commands. Nested structs follow
// their holders by themselves.
std::vector<TypeScriptStruct> DocumentedStructs() {
  std::vector<TypeScriptStruct> structs = server::ApiTypes();
  for (const TypeScriptStruct& entry : {
           OptionsType<ScannerOptions>(),           // scan
           ResultType<SceneScanSummary>(),          // scan --json
           ResultType<FromStationsResult>(),        // fill --stations --json
           ResultType<RemoveFromStationsResult>(),  // remove --stations --json
           OptionsType<ScanMeshOptions>(),          // scan --mesh-jump, points mesh
           ResultType<ScanFileSummary>(),           // info --json
           ResultType<ScanFileStatistics>(),        // info --stats --json
           ResultType<E57ImagesSummary>(),          // images --json
           OptionsType<PtxReadOptions>(),           // reading PTX
           OptionsType<E57WriteOptions>(),          // convert, E57 output
           ResultType<ScanWriteSummary>(),          // convert --json
           ResultType<ScanFormatsSummary>(),        // formats --json
           OptionsType<LasWriteOptions>(),          // LAS output
           OptionsType<PointViewOptions>(),         // render
           OptionsType<PictureLayoutOptions>(),     // render
           ResultType<PictureSummary>(),            // render --json
           ResultType<PointViewResult>(),           // render --eye, --orbit, --camera --json
           OptionsType<VerifyOptions>(),            // verify, sweep
           OptionsType<SweepOptions>(),             // sweep
           ResultType<VerifyReport>(),              // verify --json
           ResultType<SweepReport>(),               // sweep --json
           ResultType<SweepSummary>(),              // sweep's detections.json
           ResultType<DemoSummary>(),               // demo's summary.json, demo --json
           ResultType<PointsKeptReport>(),          // points outliers | sample | crop --json
           ResultType<PointsCloudReport>(),         // points voxel | merge --json
           ResultType<PointsScansReport>(),         // points transform | normals --json
           ResultType<PointsPlanesReport>(),        // points planes --json
           ResultType<PointsClusterReport>(),       // points cluster --json
           ResultType<PointsKMeansReport>(),        // points kmeans --json
           ResultType<PointsMeshReport>(),          // points mesh --json
           ResultType<PointsRegionsReport>(),       // points regions --json
           ResultType<PointsSuperpixelsReport>(),   // points superpixels --json
           ResultType<PointsSampleMeshReport>(),    // points sample-mesh --json
           ResultType<InpaintResult>(),             // inpaint
           ResultType<ReviewFolderSummary>(),       // inpaint --review DIR: review.json
           OptionsType<PoissonOptions>(),           // poisson
           ResultType<PoissonResult>(),             // poisson
           OptionsType<FillMetricsOptions>(),       // fill_eval
           OptionsType<ResectionOptions>(),         // resection, recolor
           ResultType<ResectionSummary>(),          // resection
           OptionsType<AutoResectionOptions>(),     // resection --auto
           ResultType<AutoResectionSummary>(),      // resection --auto
           OptionsType<RecolorOptions>(),           // recolor
           ResultType<RecolorSummary>(),            // recolor, one photo
           ResultType<PhotosRecolorSummary>(),      // recolor, several photos
           OptionsType<PhotoOptions>(),             // photo
           ResultType<PhotoSummary>(),              // photo
           OptionsType<AlignOptions>(),             // align
           ResultType<LandmarkAlignment>(),         // align, landmarks
           ResultType<PhotoPairModel>(),            // align, photo pairs
           OptionsType<PointsOptions>(),            // points
           OptionsType<IcpOptions>(),               // register
           OptionsType<GlobalAlignOptions>(),       // register --global
           ResultType<ScanRegistrationSummary>(),   // register --json
           OptionsType<SiteRegistrationOptions>(),  // register, several MOVING
           OptionsType<RegisterSiteOptions>(),      // register, several MOVING: --json's "options"
           ResultType<SiteRegistrationSummary>(),   // register, several MOVING --json
           ResultType<CleanSummary>(),              // clean --json
           ResultType<cli::StepsReport>(),          // steps --json
           ResultType<cli::CommandOptions>(),       // every command's --json: "options"
       }) {
    structs.push_back(entry);
  }
  return structs;
}

}  // namespace

int RunSchema(int argc, char** argv) {
  CLI::App app{
      "The option and result structs as the library describes them: TypeScript declarations of the editor's "
      "API for the front end (--typescript, src/server/api_types.cc), the reference part of docs/options.md "
      "(--markdown) or their descriptions as JSON (--json).",
      "schema"};
  std::string json_path, output;
  bool typescript = false, markdown = false;
  AddJsonOption(app, &json_path);
  app.add_flag("--typescript", typescript,
               "write the TypeScript declarations (web/src/api_types.generated.ts)");
  app.add_flag("--markdown", markdown,
               "write the reference of every described struct: with -o, into that page below its line "
               "\"<!-- Generated below ... -->\" (the hand-written part above it stays); else on stdout");
  app.add_option("-o,--output", output,
                 "with --typescript or --markdown: the file to write (default: stdout)");
  return RunCommand(app, argc, argv, [&]() {
    if (int(typescript) + int(markdown) + int(!json_path.empty()) > 1)
      throw OptionsError("--typescript, --markdown and --json: give one");
    if (!output.empty() && !typescript && !markdown)
      throw OptionsError("--output goes with --typescript or --markdown");
    if (typescript) {
      if (!output.empty()) CheckOutputFile("--output", output, {"ts"}, {});
      const std::string text = server::ApiTypesTypeScript();
      if (output.empty()) {
        fmt::print("{}", text);
      } else {
        WriteTextAtomically(output, text);
        Summarize(fmt::format("{} structs -> {}", server::ApiTypes().size(), output));
      }
    } else if (markdown) {
      const std::string reference = MarkdownReference(DocumentedStructs());
      if (output.empty()) {
        fmt::print("{}", reference);
      } else {
        // The page is updated in place, like a formatter: its hand-written part is read from it.
        CheckOutputFile("--output", output, {"md"}, {});
        const std::string page = ReadRegularFile(output);
        const std::string text = ReplaceGeneratedPart(page, reference);
        WriteTextAtomically(output, text);
        Summarize(fmt::format("{} structs -> {}", DocumentedStructs().size(), output));
      }
    } else if (!json_path.empty()) {
      WriteJsonOutput(json_path, SchemaJson(server::ApiTypes()));
    } else {
      throw OptionsError("give --typescript, --markdown or --json FILE");
    }
    return kExitOk;
  });
}

}  // namespace lidarshop::cli
