#include "lidarshop/scanner/photo.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "lidarshop/raycast/raycast.h"
#include "lidarshop/scanner/shade.h"
#include "lidarshop/scanner/texture.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/options.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop {

void PhotoOptions::Check() const { Validate(*this); }

namespace {

// Ray directions (camera frame) of a sub-pixel grid: samples x samples rays per pixel. Pinhole rays have
// z = 1 (as photos were always rendered); other models' rays are unit vectors, and a pixel without a ray
// (beyond a fisheye's reach, past a panorama's pole) gets the zero vector.
cv::Mat SampleDirections(const Camera& camera, int samples) {
  cv::Mat directions(camera.height_px() * samples, camera.width_px() * samples, CV_32FC3);
  ParallelFor(directions.rows, [&](int64_t row) {
    cv::Vec3f* out = directions.ptr<cv::Vec3f>(static_cast<int>(row));
    for (int col = 0; col < directions.cols; ++col) {
      const Eigen::Vector2d pixel((col + 0.5) / samples, (row + 0.5) / samples);
      Eigen::Vector3d ray = Eigen::Vector3d::Zero();
      if (camera.model == CameraModel::kPinhole) {
        ray = UnprojectPixel(camera.pinhole, pixel);
      } else if (!UnprojectPixel(camera, pixel, &ray)) {
        ray.setZero();
      }
      out[col] =
          cv::Vec3f(static_cast<float>(ray.x()), static_cast<float>(ray.y()), static_cast<float>(ray.z()));
    }
  });
  return directions;
}

}  // namespace

PhotoSummary SummarizePhoto(const Photo& photo, const Camera& camera) {
  PhotoSummary summary;
  summary.model = CameraModelName(camera.model);
  summary.width_px = photo.image.cols;
  summary.height_px = photo.image.rows;
  summary.scene_pixels = cv::countNonZero(photo.label != kNoLabel);
  return summary;
}

Photo RenderPhoto(const SceneDescription& scene, const PinholeCamera& camera, const PhotoOptions& options) {
  camera.Check("camera");
  return RenderPhoto(scene, CameraFromPinhole(camera), options);
}

Photo RenderPhoto(const SceneDescription& scene, const Camera& camera, const PhotoOptions& options) {
  options.Check();
  camera.Check("camera");
  std::vector<scanner_internal::ObjectData> objects(scene.objects.size());
  ParallelFor(static_cast<int64_t>(objects.size()),
              [&](int64_t i) { objects[i] = scanner_internal::MakeObjectData(scene.objects[i]); });
  RaycastScene raycast;
  for (size_t i = 0; i < objects.size(); ++i)
    raycast.AddMesh(objects[i].mesh_in_world, static_cast<int32_t>(i));
  raycast.Commit();

  const int samples = options.samples_per_axis;
  const cv::Mat directions = SampleDirections(camera, samples);
  const RayHitImages hits = raycast.CastImage(camera.world_from_camera, directions, 0.0f, 1e30f);
  const Eigen::Matrix3f rotation = camera.world_from_camera.topLeftCorner<3, 3>().cast<float>();
  const Eigen::Vector3f origin = camera.center_in_world().cast<float>();
  // Angular size of a sample: the texture footprint at distance t is t · pixel_angle / cos(incidence).
  const float sample_angle = static_cast<float>(camera.PixelAngleRad() / samples);

  cv::Mat fine(directions.size(), CV_32FC3);
  ParallelFor(directions.rows, [&](int64_t row_index) {
    const int row = static_cast<int>(row_index);
    for (int col = 0; col < directions.cols; ++col) {
      const cv::Vec3f d = directions.at<cv::Vec3f>(row, col);
      const int32_t id = d == cv::Vec3f() ? kInvalidId : hits.geometry_id.at<int32_t>(row, col);
      const Eigen::Vector3f w = rotation * Eigen::Vector3f(d[0], d[1], d[2]);
      const float t = hits.t_hit.at<float>(row, col);
      Rgb8 rgb = options.background;
      if (id != kInvalidId && t * w.norm() <= options.max_range_m) {
        const scanner_internal::ObjectData& object = objects[id];
        const cv::Vec3f n = hits.normal.at<cv::Vec3f>(row, col);
        const cv::Vec2f uv = hits.barycentric.at<cv::Vec2f>(row, col);
        Eigen::Vector3f normal(n[0], n[1], n[2]);
        rgb = UnpackRgb(scanner_internal::PerCellSurface(object, hits.primitive_id.at<int32_t>(row, col),
                                                         uv[0], uv[1], &normal));
        if (object.material.texture != TextureKind::kNone) {
          const Eigen::Vector3f hit = origin + t * w;
          const Eigen::Vector3f q =
              object.texture_from_world_rotation * (hit - object.world_origin_of_object);
          const Eigen::Vector3f m = object.texture_from_world_rotation * normal;
          const Eigen::Vector2f st = TriplanarCoordinates(q, m);
          const float cos_incidence = std::abs(normal.normalized().dot(w.normalized()));
          const float footprint = t * w.norm() * sample_angle / std::max(cos_incidence, 0.02f);
          const float inverse_scale = 1.0f / object.material.texture_scale;
          rgb = EvaluateTexture(object.material.texture, st.x() * inverse_scale, st.y() * inverse_scale, rgb,
                                1.0f, footprint * inverse_scale);
        }
      }
      fine.at<cv::Vec3f>(row, col) = cv::Vec3f(rgb[0], rgb[1], rgb[2]);
    }
  });

  Photo photo;
  cv::Mat averaged = fine;
  if (samples > 1)
    cv::resize(fine, averaged, cv::Size(camera.width_px(), camera.height_px()), 0, 0, cv::INTER_AREA);
  averaged.convertTo(photo.image, CV_8UC3);  // rounds and saturates
  // Label and depth of the pixel centres: the middle sample for odd counts, else re-cast the centres.
  const RayHitImages centre_hits =
      samples == 1 ? hits
                   : raycast.CastImage(camera.world_from_camera, SampleDirections(camera, 1), 0.0f, 1e30f);
  const cv::Mat centre_directions = samples == 1 ? directions : SampleDirections(camera, 1);
  photo.label.create(camera.height_px(), camera.width_px(), CV_32S);
  photo.depth_m.create(camera.height_px(), camera.width_px(), CV_32F);
  for (int row = 0; row < camera.height_px(); ++row) {
    for (int col = 0; col < camera.width_px(); ++col) {
      const cv::Vec3f d = centre_directions.at<cv::Vec3f>(row, col);
      const int32_t id = d == cv::Vec3f() ? kInvalidId : centre_hits.geometry_id.at<int32_t>(row, col);
      const float distance = centre_hits.t_hit.at<float>(row, col) * std::sqrt(d.dot(d));
      const bool seen = id != kInvalidId && distance <= options.max_range_m;
      photo.label.at<int32_t>(row, col) = seen ? scene.objects[id].label : kNoLabel;
      photo.depth_m.at<float>(row, col) = seen ? distance : std::numeric_limits<float>::infinity();
    }
  }
  return photo;
}

}  // namespace lidarshop
