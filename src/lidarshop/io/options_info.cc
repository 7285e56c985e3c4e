// Descriptions of the file options (util/options.h); the picture options are render/'s.
#include <fmt/format.h>

#include "lidarshop/io/e57.h"
#include "lidarshop/io/formats.h"
#include "lidarshop/io/las.h"
#include "lidarshop/io/ptx.h"
#include "lidarshop/io/scan_summary.h"
#include "lidarshop/io/scan_write_plan.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"

namespace lidarshop {

template <>
const StructInfo& InfoOf<PtxReadOptions>() {
  static const StructInfo info = [] {
    StructBuilder<PtxReadOptions> b("PtxReadOptions", "reading PTX");
    b.Field(&PtxReadOptions::fit_grid, "fit_grid", "fit the angular grid so every cell gets a direction");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<E57WriteOptions>() {
  static const StructInfo info = [] {
    StructBuilder<E57WriteOptions> b("E57WriteOptions", "writing E57");
    b.Field(&E57WriteOptions::coordinate_scale_m, "coordinate_scale_m",
            "0 = float coordinates; > 0 = scaled integers with this step")
        .Unit("m")
        .Min(0);
    b.Field(&E57WriteOptions::write_no_return_directions, "write_no_return_directions",
            "keep the directions of cells without a return (in lidarshop's E57 extension; never as points)");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<LasWriteOptions>() {
  static const StructInfo info = [] {
    StructBuilder<LasWriteOptions> b("LasWriteOptions", "writing LAS");
    b.Field(&LasWriteOptions::minor_version, "minor_version",
            "LAS 1.x: 4 (LAS 1.4) or 2 (LAS 1.2, formats 0-3)")
        .Range(2, 4);
    b.Field(&LasWriteOptions::point_format, "point_format",
            "point data record format 0-3 or 6-8; -1 = the source LAS's when it holds the attributes, else "
            "8 with NIR, 7 with colour, 6 (1.4); 3/2 with colour, 1/0 (1.2; GPS time decides)")
        .Range(-1, 8);
    b.Field(&LasWriteOptions::coordinate_scale_m, "coordinate_scale_m", "step of the stored coordinates")
        .Unit("m")
        .AboveZero()
        .Max(1);
    b.Field(&LasWriteOptions::keep_source_scale, "keep_source_scale",
            "keep the source LAS files' scale and offset when all scans share them (same integers back)");
    b.Check([](const LasWriteOptions& o) {
      CheckOption(
          o.minor_version == 2 || o.minor_version == 4,
          fmt::format("minor_version: {} is not written; 4 (LAS 1.4) or 2 (LAS 1.2)", o.minor_version));
      CheckOption(o.point_format != 4 && o.point_format != 5,
                  fmt::format("point_format: {} (waveform) is not written; 0-3 or 6-8", o.point_format));
      CheckOption(o.point_format < 6 || o.minor_version == 4,
                  fmt::format("point_format: {} needs LAS 1.4 (minor_version 4)", o.point_format));
    });
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ScanWriteSummary>() {
  static const StructInfo info = [] {
    StructBuilder<ScanWriteSummary> b("ScanWriteSummary", "what a conversion wrote (convert --json)");
    b.Field(&ScanWriteSummary::input, "input", "the file read");
    b.Field(&ScanWriteSummary::output, "output", "the file written");
    b.Field(&ScanWriteSummary::format, "format", "the target format: its extension (ptx, e57, las, ...)");
    b.Field(&ScanWriteSummary::scans, "scans", "scans written");
    b.Field(&ScanWriteSummary::returns, "returns", "valid returns written, all scans together")
        .Unit("points");
    b.Field(&ScanWriteSummary::images, "images", "photos written (E57 images2D; 0 for other targets)");
    b.Field(&ScanWriteSummary::channels, "channels",
            "the channels written, in the target's words where it renames them (label→classification)");
    b.Field(&ScanWriteSummary::dropped, "dropped",
            "what the target cannot hold, one sentence each starting with the output path");
    b.Field(&ScanWriteSummary::synthesized_left_out, "synthesized_left_out",
            "with --drop-synthesized: the synthesized returns left out")
        .Unit("points");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<LasRecordSummary>() {
  static const StructInfo info = [] {
    StructBuilder<LasRecordSummary> b("LasRecordSummary", "one variable length record of a LAS file");
    b.Field(&LasRecordSummary::user_id, "user_id", "the record's user id (LASF_Projection, ...)");
    b.Field(&LasRecordSummary::record_id, "record_id", "the record's id within its user id");
    b.Field(&LasRecordSummary::description, "description", "the record's description");
    b.Field(&LasRecordSummary::bytes, "bytes", "the payload's length").Unit("bytes");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<LasBoundsSummary>() {
  static const StructInfo info = [] {
    StructBuilder<LasBoundsSummary> b("LasBoundsSummary", "the bounds a LAS header states");
    b.Field(&LasBoundsSummary::min, "min", "x, y, z of the lowest corner").Unit("m");
    b.Field(&LasBoundsSummary::max, "max", "x, y, z of the highest corner").Unit("m");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<LasHeaderSummary>() {
  static const StructInfo info = [] {
    StructBuilder<LasHeaderSummary> b("LasHeaderSummary",
                                      "a LAS file's header block and VLRs as pdal info / lasinfo show them");
    using L = LasHeaderSummary;
    b.Field(&L::version, "version", "the LAS version, e.g. 1.4");
    b.Field(&L::point_format, "point_format", "the point data record format");
    b.Field(&L::record_length, "record_length", "bytes per point record").Unit("bytes");
    b.Field(&L::extra_bytes, "extra_bytes", "bytes of a record beyond its point format's fields")
        .Unit("bytes");
    b.Field(&L::scale, "scale", "x, y, z: coordinate = offset + scale x stored integer").Unit("m");
    b.Field(&L::offset, "offset", "x, y, z offsets of the coordinates").Unit("m");
    b.Field(&L::bounds, "bounds", "the bounds the header states");
    b.Field(&L::points_by_return, "points_by_return",
            "points per return number, from 1 (5, or 15 for LAS 1.4)")
        .Unit("points");
    b.Field(&L::gps_time, "gps_time", "standard or week, for point formats with a GPS time").OmitWhenEmpty();
    b.Field(&L::file_source_id, "file_source_id", "the header's file source id");
    b.Field(&L::vlrs, "vlrs", "the variable length records");
    b.Field(&L::crs, "crs",
            "the coordinate reference system: wkt and / or geotiff keys, in the file's order");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<E57MetadataSummary>() {
  static const StructInfo info = [] {
    StructBuilder<E57MetadataSummary> b(
        "E57MetadataSummary", "the E57 facts of a data3D or images2D entry, each left out when absent");
    using M = E57MetadataSummary;
    b.Field(&M::guid, "guid", "the entry's guid").OmitWhenEmpty();
    b.Field(&M::description, "description", "the entry's description").OmitWhenEmpty();
    b.Field(&M::sensor_vendor, "sensor_vendor", "sensor vendor").OmitWhenEmpty();
    b.Field(&M::sensor_model, "sensor_model", "sensor model").OmitWhenEmpty();
    b.Field(&M::sensor_serial_number, "sensor_serial_number", "sensor serial number").OmitWhenEmpty();
    b.Field(&M::sensor_hardware_version, "sensor_hardware_version", "sensor hardware version")
        .OmitWhenEmpty();
    b.Field(&M::sensor_software_version, "sensor_software_version", "sensor software version")
        .OmitWhenEmpty();
    b.Field(&M::sensor_firmware_version, "sensor_firmware_version", "sensor firmware version")
        .OmitWhenEmpty();
    b.Field(&M::acquisition_start_utc, "acquisition_start_utc", "start of the acquisition, UTC text")
        .OmitWhenEmpty();
    b.Field(&M::acquisition_start_gps_s, "acquisition_start_gps_s",
            "start of the acquisition, GPS seconds since 1980-01-06 00:00 UTC")
        .Unit("s");
    b.Field(&M::acquisition_end_utc, "acquisition_end_utc", "end of the acquisition, UTC text")
        .OmitWhenEmpty();
    b.Field(&M::acquisition_end_gps_s, "acquisition_end_gps_s",
            "end of the acquisition, GPS seconds since 1980-01-06 00:00 UTC")
        .Unit("s");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ScanSummary>() {
  static const StructInfo info = [] {
    StructBuilder<ScanSummary> b("ScanSummary", "one scan as its file's header describes it (info)");
    b.Field(&ScanSummary::index, "index", "the scan's place in the file, from 0");
    b.Field(&ScanSummary::name, "name", "the E57 data3D name").OmitWhenEmpty();
    b.Field(&ScanSummary::organized, "organized", "a grid of rays (else a cloud of 1 x points)");
    b.Field(&ScanSummary::rows, "rows", "rows of the grid; null when unknown").Unit("cells").NullWhenAbsent();
    b.Field(&ScanSummary::cols, "cols", "columns of the grid; null when unknown")
        .Unit("cells")
        .NullWhenAbsent();
    b.Field(&ScanSummary::cells, "cells", "rows x cols; null when either is unknown")
        .Unit("cells")
        .NullWhenAbsent();
    b.Field(&ScanSummary::points, "points", "records the file stores for the scan; null when unknown")
        .Unit("points")
        .NullWhenAbsent();
    b.Field(&ScanSummary::channels, "channels", "the channels the file declares, as ChannelNames names them");
    b.Field(&ScanSummary::coordinates, "coordinates", "E57: cartesian or spherical").OmitWhenEmpty();
    b.Field(&ScanSummary::world_from_scanner, "world_from_scanner", "the scan's pose, 4 rows of 4");
    b.Field(&ScanSummary::e57, "e57", "E57: the entry's sensor, dates and guid");
    b.Field(&ScanSummary::las, "las", "LAS: the header as pdal info / lasinfo show it");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<WorldBoundsSummary>() {
  static const StructInfo info = [] {
    StructBuilder<WorldBoundsSummary> b("WorldBoundsSummary", "the bounds of a scan's returns");
    b.Field(&WorldBoundsSummary::frame, "frame", "the frame of the bounds: world");
    b.Field(&WorldBoundsSummary::min, "min", "x, y, z of the lowest corner").Unit("m");
    b.Field(&WorldBoundsSummary::max, "max", "x, y, z of the highest corner").Unit("m");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<RangeSummary>() {
  static const StructInfo info = [] {
    StructBuilder<RangeSummary> b("RangeSummary", "the range of a scan's returns");
    b.Field(&RangeSummary::min, "min", "the shortest range").Unit("m");
    b.Field(&RangeSummary::max, "max", "the longest range").Unit("m");
    b.Field(&RangeSummary::mean, "mean", "the mean range").Unit("m");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<IntensitySummary>() {
  static const StructInfo info = [] {
    StructBuilder<IntensitySummary> b("IntensitySummary", "the intensity of a scan's returns");
    b.Field(&IntensitySummary::min, "min", "the lowest intensity, in the file's scale");
    b.Field(&IntensitySummary::max, "max", "the highest intensity, in the file's scale");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<GridSummary>() {
  static const StructInfo info = [] {
    StructBuilder<GridSummary> b("GridSummary", "a scan's angular grid");
    b.Field(&GridSummary::fitted, "fitted", "the grid was fitted to the points (not given by the file)");
    b.Field(&GridSummary::known, "known", "the grid's directions are known");
    b.Field(&GridSummary::azimuth_deg, "azimuth_deg", "[min, max] azimuth of the columns; when known")
        .Unit("deg")
        .OmitWhenEmpty();
    b.Field(&GridSummary::elevation_deg, "elevation_deg", "[min, max] elevation of the rows; when known")
        .Unit("deg")
        .OmitWhenEmpty();
    b.Field(&GridSummary::azimuth_step_deg, "azimuth_step_deg",
            "mean step between columns; 2 columns or more")
        .Unit("deg");
    b.Field(&GridSummary::elevation_step_deg, "elevation_step_deg", "mean step between rows; 2 rows or more")
        .Unit("deg");
    b.Field(&GridSummary::rms_residual_rad, "rms_residual_rad", "RMS angle between the points and the grid")
        .Unit("rad");
    b.Field(&GridSummary::max_residual_rad, "max_residual_rad", "largest angle between a point and the grid")
        .Unit("rad");
    b.Field(&GridSummary::rms_residual_deg, "rms_residual_deg", "rms_residual_rad in degrees").Unit("deg");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ScanStatisticsSummary>() {
  static const StructInfo info = [] {
    StructBuilder<ScanStatisticsSummary> b(
        "ScanStatisticsSummary",
        "one scan with what reading its points adds (info --stats); the header's keys first");
    using S = ScanStatisticsSummary;
    b.Flatten(&S::header);
    b.Field(&S::valid, "valid", "returns (valid cells)").Unit("points");
    b.Field(&S::attributes, "attributes", "the scan's per-cell attributes by name").OmitWhenEmpty();
    b.Field(&S::classes, "classes", "LAS: returns per classification, {\"2\": count, ...}");
    b.Field(&S::returns, "returns", "LAS: returns per return number, {\"1\": count, ...}");
    b.Field(&S::crs, "crs", "LAS: the coordinate reference system of its records (LasCrsJson)");
    b.Field(&S::bounds, "bounds", "world bounds of the returns; null without returns").NullWhenAbsent();
    b.Field(&S::range_m, "range_m", "range of the returns; with returns");
    b.Field(&S::intensity, "intensity", "intensity of the returns; with returns and an intensity channel");
    b.Field(&S::grid, "grid", "the angular grid");
    b.Field(&S::grid_fit_rms_residual_rad, "grid_fit_rms_residual_rad",
            "grid.rms_residual_rad (an earlier key)")
        .Unit("rad");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ScanImageSummary>() {
  static const StructInfo info = [] {
    StructBuilder<ScanImageSummary> b("ScanImageSummary",
                                      "one photo (E57 images2D) as its file's header describes it");
    using I = ScanImageSummary;
    b.Field(&I::index, "index", "the photo's place in the file, from 0");
    b.Field(&I::name, "name", "the entry's name");
    b.Field(&I::representation, "representation", "pinhole, spherical, cylindrical or visual");
    b.Field(&I::width_px, "width_px", "width").Unit("px");
    b.Field(&I::height_px, "height_px", "height").Unit("px");
    b.Field(&I::encoding, "encoding", "jpeg or png");
    b.Field(&I::encoded_bytes, "encoded_bytes", "the stored blob's length").Unit("bytes");
    b.Field(&I::scan, "scan", "the scan the photo belongs to; null when none").NullWhenAbsent();
    b.Field(&I::world_from_camera, "world_from_camera", "the camera's pose, 4 rows of 4");
    b.Field(&I::e57, "e57", "the entry's sensor, dates and guid");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<E57ImageIntrinsics>() {
  static const StructInfo info = [] {
    StructBuilder<E57ImageIntrinsics> b("E57ImageIntrinsics",
                                        "an E57 photo's intrinsics as stored; which are there depends on the "
                                        "representation");
    using K = E57ImageIntrinsics;
    b.Field(&K::focal_length_m, "focal_length_m", "pinhole: focal length").Unit("m");
    b.Field(&K::pixel_width_rad, "pixel_width_rad", "spherical, cylindrical: pixel width").Unit("rad");
    b.Field(&K::pixel_width_m, "pixel_width_m", "pinhole: pixel width").Unit("m");
    b.Field(&K::pixel_height_rad, "pixel_height_rad", "spherical: pixel height").Unit("rad");
    b.Field(&K::pixel_height_m, "pixel_height_m", "pinhole: pixel height; cylindrical: on the cylinder")
        .Unit("m");
    b.Field(&K::principal_point_px, "principal_point_px", "pinhole: principal point x, y").Unit("px");
    b.Field(&K::radius_m, "radius_m", "cylindrical: the cylinder's radius").Unit("m");
    b.Field(&K::principal_y_px, "principal_y_px", "cylindrical: the row of the horizon").Unit("px");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<E57ImageSummary>() {
  static const StructInfo info = [] {
    StructBuilder<E57ImageSummary> b("E57ImageSummary", "an E57 photo read whole (photos)");
    using I = E57ImageSummary;
    b.Field(&I::index, "index", "the photo's place in the file, from 0");
    b.Field(&I::name, "name", "the entry's name");
    b.Field(&I::representation, "representation", "pinhole, spherical, cylindrical or visual");
    b.Field(&I::width_px, "width_px", "width as stated, else the decoded photo's").Unit("px");
    b.Field(&I::height_px, "height_px", "height as stated, else the decoded photo's").Unit("px");
    b.Field(&I::decoded, "decoded", "the photo decodes");
    b.Field(&I::decode_error, "decode_error", "why it does not decode").OmitWhenEmpty();
    b.Field(&I::world_from_camera, "world_from_camera", "the camera's pose, 4 rows of 4");
    b.Field(&I::intrinsics, "intrinsics", "the intrinsics as stored");
    b.Field(&I::description, "description", "the entry's description").OmitWhenEmpty();
    b.Field(&I::scan, "scan", "the scan the photo belongs to");
    b.Field(&I::has_mask, "has_mask", "the entry has an image mask");
    b.Field(&I::model, "model", "the camera model's name; null for a visual reference").NullWhenAbsent();
    b.Field(&I::camera, "camera",
            "the camera model (its keys depend on the model), when the entry holds one");
    b.Field(&I::camera_error, "camera_error", "why the entry holds no full camera model").OmitWhenEmpty();
    b.Field(&I::recolor_ready, "recolor_ready", "recolour can use the photo as it is");
    b.Field(&I::extracted, "extracted", "images --extract: the file the photo's stored bytes were written to")
        .OmitWhenEmpty();
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ScanFormatSummary>() {
  static const StructInfo info = [] {
    StructBuilder<ScanFormatSummary> b(
        "ScanFormatSummary", "one scan format and what it holds (a channel: false, true or its name there)");
    using F = ScanFormatSummary;
    b.Field(&F::extension, "extension", "lower case, no dot");
    b.Field(&F::name, "name", "the format's name");
    b.Field(&F::description, "description", "one line");
    b.Field(&F::read, "read", "lidarshop reads it");
    b.Field(&F::write, "write", "lidarshop writes it");
    b.Field(&F::grid, "grid", "it holds rows x columns and the scanner's pose (an organized scan)");
    b.Field(&F::scans, "scans", "scans per file: one, several or merged (their union in the world frame)");
    b.Field(&F::write_refusal, "write_refusal", "read but not written: why, and what to write instead")
        .OmitWhenEmpty();
    b.Field(&F::intensity_required, "intensity_required",
            "the file needs an intensity column (a scan without one gets the no-information value)");
    b.Field(&F::intensity, "intensity", "intensity: false, true or the format's name for it");
    b.Field(&F::color, "color", "colour: false, true or the format's name for it");
    b.Field(&F::label, "label", "labels: false, true or the format's name for them");
    b.Field(&F::normal, "normal", "normals: false, true or the format's name for them");
    b.Field(&F::true_range, "true_range", "the range measured behind a filled cell: false, true or a name");
    b.Field(&F::synthesized, "synthesized", "the synthesized flag: false, true or the format's name for it");
    b.Field(&F::from_station, "from_station",
            "the cells filled from another station: false, true or the format's name for them");
    b.Field(&F::images, "images", "photos with their poses (E57 images2D)");
    b.Field(&F::layer_behind, "layer_behind",
            "a second layer of cells behind the first (remove --keep-object)");
    b.Field(&F::layer_behind_how, "layer_behind_how", "how that layer is kept, or why it cannot be")
        .OmitWhenEmpty();
    b.Field(&F::precision, "precision", "what the coordinates are stored as");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ScanFormatsSummary>() {
  static const StructInfo info = [] {
    StructBuilder<ScanFormatsSummary> b("ScanFormatsSummary", "the scan formats (formats --json)");
    b.Field(&ScanFormatsSummary::formats, "formats", "every format, in the order file dialogs list them");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<E57ImagesSummary>() {
  static const StructInfo info = [] {
    StructBuilder<E57ImagesSummary> b("E57ImagesSummary", "the photos of an E57 file (images --json)");
    b.Field(&E57ImagesSummary::file, "file", "the E57 file");
    b.Field(&E57ImagesSummary::images, "images", "its photos (images2D), in the file's order");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ScanImageStatisticsSummary>() {
  static const StructInfo info = [] {
    StructBuilder<ScanImageStatisticsSummary> b(
        "ScanImageStatisticsSummary",
        "one photo with what reading it adds (info --stats); the header's keys first");
    using I = ScanImageStatisticsSummary;
    b.Flatten(&I::header);
    b.Field(&I::decoded, "decoded", "the photo decodes");
    b.Field(&I::decode_error, "decode_error", "why it does not decode").OmitWhenEmpty();
    b.Field(&I::intrinsics, "intrinsics", "the intrinsics as stored");
    b.Field(&I::description, "description", "the entry's description").OmitWhenEmpty();
    b.Field(&I::has_mask, "has_mask", "the entry has an image mask");
    b.Field(&I::model, "model", "the camera model's name; null for a visual reference").NullWhenAbsent();
    b.Field(&I::camera, "camera",
            "the camera model (its keys depend on the model), when the entry holds one");
    b.Field(&I::camera_error, "camera_error", "why the entry holds no full camera model").OmitWhenEmpty();
    b.Field(&I::recolor_ready, "recolor_ready", "recolour can use the photo as it is");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ScanStationSummary>() {
  static const StructInfo info = [] {
    StructBuilder<ScanStationSummary> b("ScanStationSummary", "one station of a file of several scans");
    b.Field(&ScanStationSummary::index, "index", "the scan's place in the file, from 0");
    b.Field(&ScanStationSummary::name, "name", "the scan's name");
    b.Field(&ScanStationSummary::position, "position", "the scanner's centre x, y, z in the world").Unit("m");
    b.Field(&ScanStationSummary::heading_deg, "heading_deg",
            "the scanner's +y turned about the world z, positive to the left")
        .Unit("deg");
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ScanFileFacts>() {
  static const StructInfo info = [] {
    StructBuilder<ScanFileFacts> b("ScanFileFacts", "what a scan file is");
    b.Field(&ScanFileFacts::file, "file", "the file's path");
    b.Field(&ScanFileFacts::format, "format", "the extension: ptx, e57, ply, pcd, las, xyz, pts");
    b.Field(&ScanFileFacts::format_version, "format_version", "e.g. E57 1.0, LAS 1.4 point format 7")
        .OmitWhenEmpty();
    b.Field(&ScanFileFacts::size_bytes, "size_bytes", "the file's size").Unit("bytes");
    b.Field(&ScanFileFacts::guid, "guid", "E57: the root's guid").OmitWhenEmpty();
    b.Field(&ScanFileFacts::created_utc, "created_utc", "E57: creationDateTime, UTC text").OmitWhenEmpty();
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ScanFileSummary>() {
  static const StructInfo info = [] {
    StructBuilder<ScanFileSummary> b("ScanFileSummary", "what a scan file's header says (info --json)");
    b.Flatten(&ScanFileSummary::facts);
    b.Field(&ScanFileSummary::scans, "scans", "the scans, in the file's order");
    b.Field(&ScanFileSummary::images, "images", "E57: the photos (images2D)");
    b.Field(&ScanFileSummary::warnings, "warnings", "what the reader noticed, one sentence each")
        .OmitWhenEmpty();
    b.Field(&ScanFileSummary::stations, "stations", "a file of several scans: its stations").OmitWhenEmpty();
    return b.Build();
  }();
  return info;
}

template <>
const StructInfo& InfoOf<ScanFileStatistics>() {
  static const StructInfo info = [] {
    StructBuilder<ScanFileStatistics> b(
        "ScanFileStatistics",
        "a scan file's header with what reading every point adds (info --stats --json)");
    b.Flatten(&ScanFileStatistics::facts);
    b.Field(&ScanFileStatistics::scans, "scans", "the scans, in the file's order");
    b.Field(&ScanFileStatistics::images, "images", "E57: the photos (images2D)");
    b.Field(&ScanFileStatistics::warnings, "warnings", "what the header's reader noticed, one sentence each")
        .OmitWhenEmpty();
    b.Field(&ScanFileStatistics::stations, "stations", "a file of several scans: its stations")
        .OmitWhenEmpty();
    return b.Build();
  }();
  return info;
}

}  // namespace lidarshop
