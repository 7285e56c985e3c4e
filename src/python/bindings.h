// What the parts of the `lidarshop` Python module share: each bind_*.cc adds one area of the library to the
// module (a thin layer: parse, check, call, return), with the conversions of convert.h and the generated
// option classes of options_py.h.
#pragma once

#include <cstring>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "convert.h"
#include "lidarshop/geometry/mesh.h"
#include "lidarshop/scan/scan.h"
#include "lidarshop/util/options.h"
#include "options_py.h"

namespace lidarshop {
struct SceneDescription;
}

namespace lidarshop::python {

namespace py = pybind11;

void BindErrors(py::module_& m);
void BindOptionStructs(py::module_& m);
void BindScan(py::module_& m);
void BindMesh(py::module_& m);
void BindFiles(py::module_& m);
void BindResults(py::module_& m);
void BindAlgorithms(py::module_& m);
void BindPointSets(py::module_& m);
void BindVerify(py::module_& m);
void BindRecolor(py::module_& m);

// The options of one call: `options` (None, an options object or a dict of its JSON form) with the keyword
// arguments applied on top, then validated (OptionsError naming the key).
template <class Options>
Options OptionsOf(const py::object& options, const py::kwargs& kwargs) {
  Options result{};
  if (!options.is_none()) {
    if (py::isinstance<Options>(options)) {
      result = options.cast<Options>();
    } else {
      ApplyDict(InfoOf<Options>(), options, &result);
    }
  }
  if (kwargs.size() > 0) ApplyDict(InfoOf<Options>(), kwargs, &result);
  Validate(result);
  return result;
}

// The same for an options argument without keywords (a call that takes several option structs).
template <class Options>
Options OptionsOf(const py::object& options) {
  return OptionsOf<Options>(options, py::kwargs());
}

// A synthetic scene from a scene file's path, a dict of the scene-file form or a built-in scene's name.
SceneDescription SceneOf(const py::object& scene);
// A (rows, cols) uint8 mask of the scan's grid (bool: True = 255).
cv::Mat MaskOf(const py::handle& mask, const Scan& scan, const std::string& what);
// CV_64F for float64 arrays, else CV_32F: the depth an image is solved in.
int ImageDepth(const py::handle& image);

// A point cloud from an (N, 3) array (any number type), or a Scan's valid points in the world frame with
// their attributes (colours, intensities, labels, normals). `what` names the argument in errors.
PointCloud CloudOf(const py::handle& points, const std::string& what = "points");
// float32 (N, 3).
py::array_t<float> PointsArray(const std::vector<Eigen::Vector3f>& points);
// (N, k) float64 of an array-like with `k` columns; ValueError naming `what` otherwise.
std::vector<Eigen::VectorXd> RowsOf(const py::handle& array, int k, const std::string& what);
// One 3-vector (a list or array of 3 numbers) as float; ValueError naming `what` otherwise.
Eigen::Vector3f Vector3Of(const py::handle& value, const std::string& what);
// Normals (N, 3) for the N points of `cloud` (ValueError naming the counts when they differ).
void SetNormals(const py::handle& normals, PointCloud* cloud);

// A 1-D numpy array (a copy) of a vector of numbers.
template <class T>
py::array_t<T> VectorArray(const std::vector<T>& values) {
  py::array_t<T> array(static_cast<py::ssize_t>(values.size()));
  if (!values.empty()) std::memcpy(array.mutable_data(), values.data(), values.size() * sizeof(T));
  return array;
}

// (N, K) float64 of fixed-size vectors, and back.
template <int K>
py::array_t<double> VectorsArray(const std::vector<Eigen::Matrix<double, K, 1>>& vectors) {
  py::array_t<double> array({static_cast<py::ssize_t>(vectors.size()), py::ssize_t{K}});
  auto view = array.mutable_unchecked<2>();
  for (size_t i = 0; i < vectors.size(); ++i) {
    for (int k = 0; k < K; ++k) view(i, k) = vectors[i][k];
  }
  return array;
}
template <int K>
std::vector<Eigen::Matrix<double, K, 1>> VectorsOf(const py::handle& values, const std::string& what) {
  const std::vector<Eigen::VectorXd> rows = RowsOf(values, K, what);
  return std::vector<Eigen::Matrix<double, K, 1>>(rows.begin(), rows.end());
}
// Flags as a bool numpy array (N,).
py::array BoolArray(const std::vector<uint8_t>& flags);

}  // namespace lidarshop::python
