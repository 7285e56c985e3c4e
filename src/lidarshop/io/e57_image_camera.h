// The camera model (geometry/camera_model.h) of a photo stored in an E57 file (io/e57.h: images2D), and the
// images2D entry of a rendered or given photo.
//
// E57 stores no camera frame convention of its own beyond the pose; lidarshop reads each representation in
// the frames of geometry/camera_model.h:
// - pinholeRepresentation: x along increasing columns, y along increasing rows, z the viewing direction;
//   fx = focalLength / pixelWidth, fy = focalLength / pixelHeight (metres), principal point as stored
//   (pixels), no distortion (E57 stores none).
// - sphericalRepresentation: z up, y the centre column's azimuth, columns increasing to the right (towards
//   +x), row 0 up, the horizon at the middle row; pixelWidth and pixelHeight in radians.
// - cylindricalRepresentation: the same axes; pixelWidth in radians, pixelHeight and radius in metres,
//   principalPointY the row of the horizon.
// - visualReferenceRepresentation: a picture for people, no camera model.
#pragma once

#include <string>

#include <opencv2/core.hpp>

#include "lidarshop/geometry/camera_model.h"
#include "lidarshop/io/e57.h"

namespace lidarshop {

// The model name an images2D entry describes: "pinhole", "spherical", "cylindrical", or "" for a visual
// reference (and unknown representations).
std::string E57ImageModel(const E57Image& image);

// True and `camera` filled when `image` holds a full camera model (a pinhole, spherical or cylindrical entry
// whose fields are there and in range, with a size, and a rigid pose); else false and `why` says what is
// missing. The size is the decoded photo's when it decodes (it must agree with imageWidth / imageHeight).
bool CameraModelOfE57Image(const E57Image& image, Camera* camera, std::string* why);

// The images2D entry of `rgb` (CV_8UC3, the camera's size) taken by `camera`: representation, intrinsics and
// pose; the photo is written as PNG. Throws InputError naming `what` when E57 cannot hold the camera (a
// fisheye; a pinhole with distortion or skew) or the photo does not have the camera's size.
E57Image E57ImageOfCamera(const Camera& camera, const cv::Mat& rgb, const std::string& name,
                          const std::string& what = "camera");

}  // namespace lidarshop
