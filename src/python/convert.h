// Conversions between Python objects and the library's plain data: JSON values (options), cv::Mat channels
// and images (numpy arrays, without a copy where the layout allows), 4x4 poses.
#pragma once

#include <string>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

namespace lidarshop::python {

namespace py = pybind11;

// Python value -> JSON: None, bool, int (and numpy integers), float, str, list/tuple, dict, and any object
// with a to_dict() method (the generated options classes), so a dict may hold nested options objects.
nlohmann::json ToJsonValue(const py::handle& value);
// JSON -> Python (dicts keep the JSON order).
py::object FromJsonValue(const nlohmann::ordered_json& value);
py::object FromJsonValue(const nlohmann::json& value);

// A numpy view of `mat` (shape rows x cols, or rows x cols x channels when channels > 1; the strides of the
// Mat): no copy. The array's base is a capsule holding a cv::Mat header that shares the buffer, so the memory
// lives as long as the array even when the Scan's channel is replaced. None for an empty Mat.
py::object MatToArray(const cv::Mat& mat, bool writable = true);

// A new cv::Mat (owning its memory, a copy) of `depth` and `channels` from a numpy array of shape rows x cols
// (channels == 1; a trailing axis of 1 is accepted) or rows x cols x channels. Values are converted to the
// depth (numpy casting rules); booleans become 0 / 255 for CV_8U masks. Throws ValueError naming `what` on a
// wrong shape. rows / cols < 0 = any.
cv::Mat ArrayToMat(const py::handle& array, int depth, int channels, int rows, int cols,
                   const std::string& what);
// Like ArrayToMat, keeping the array's channel count (2-D = 1 channel), for images of any channel count.
cv::Mat ArrayToMatAnyChannels(const py::handle& array, int depth, const std::string& what);

// 4x4 float64 numpy array <-> Eigen; ValueError unless the shape is 4 x 4.
py::array_t<double> MatrixToArray(const Eigen::Matrix4d& matrix);
Eigen::Matrix4d ArrayToMatrix(const py::handle& array, const std::string& what);

}  // namespace lidarshop::python
