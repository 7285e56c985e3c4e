#include "convert.h"

#include <cstdint>
#include <cstring>
#include <vector>

#include <fmt/format.h>

namespace lidarshop::python {

namespace {

template <class Json>
py::object FromJsonImpl(const Json& value) {
  switch (value.type()) {
    case nlohmann::json::value_t::null:
      return py::none();
    case nlohmann::json::value_t::boolean:
      return py::bool_(value.template get<bool>());
    case nlohmann::json::value_t::number_integer:
      return py::int_(value.template get<int64_t>());
    case nlohmann::json::value_t::number_unsigned:
      return py::int_(value.template get<uint64_t>());
    case nlohmann::json::value_t::number_float:
      return py::float_(value.template get<double>());
    case nlohmann::json::value_t::string:
      return py::str(value.template get<std::string>());
    case nlohmann::json::value_t::array: {
      py::list list;
      for (const auto& element : value) list.append(FromJsonImpl(element));
      return list;
    }
    case nlohmann::json::value_t::object: {
      py::dict dict;
      for (const auto& [key, element] : value.items()) dict[py::str(key)] = FromJsonImpl(element);
      return dict;
    }
    default:
      throw py::type_error("a JSON value that has no Python form");
  }
}

std::string TypeName(const py::handle& value) { return py::str(py::type::of(value).attr("__name__")); }

}  // namespace

py::object FromJsonValue(const nlohmann::ordered_json& value) { return FromJsonImpl(value); }
py::object FromJsonValue(const nlohmann::json& value) { return FromJsonImpl(value); }

nlohmann::json ToJsonValue(const py::handle& value) {
  if (value.is_none()) return nullptr;
  if (py::isinstance<py::bool_>(value)) return value.cast<bool>();
  // numpy.bool_ is not a Python bool; keep it a boolean.
  if (py::hasattr(value, "dtype") && py::hasattr(value, "item") && !py::isinstance<py::array>(value)) {
    return ToJsonValue(value.attr("item")());
  }
  if (py::isinstance<py::int_>(value)) {
    const py::int_ number = py::reinterpret_borrow<py::int_>(value);
    if (number.attr("__ge__")(0).cast<bool>()) return value.cast<uint64_t>();
    return value.cast<int64_t>();
  }
  if (py::isinstance<py::float_>(value)) return value.cast<double>();
  if (py::isinstance<py::str>(value)) return value.cast<std::string>();
  if (py::isinstance<py::dict>(value)) {
    nlohmann::json object = nlohmann::json::object();
    for (const auto& [key, element] : py::reinterpret_borrow<py::dict>(value)) {
      if (!py::isinstance<py::str>(key))
        throw py::type_error("option keys are strings, got " + TypeName(key));
      object[key.cast<std::string>()] = ToJsonValue(element);
    }
    return object;
  }
  if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value) ||
      py::isinstance<py::array>(value)) {
    nlohmann::json array = nlohmann::json::array();
    const py::list elements = py::isinstance<py::array>(value)
                                  ? py::list(value.attr("tolist")())
                                  : py::list(py::reinterpret_borrow<py::object>(value));
    for (const auto& element : elements) array.push_back(ToJsonValue(element));
    return array;
  }
  if (py::hasattr(value, "to_dict")) return ToJsonValue(value.attr("to_dict")());
  throw py::type_error(fmt::format("cannot use a {} as an option value", TypeName(value)));
}

py::object MatToArray(const cv::Mat& mat, bool writable) {
  if (mat.empty()) return py::none();
  py::dtype dtype;
  switch (mat.depth()) {
    case CV_8U:
      dtype = py::dtype::of<uint8_t>();
      break;
    case CV_8S:
      dtype = py::dtype::of<int8_t>();
      break;
    case CV_16U:
      dtype = py::dtype::of<uint16_t>();
      break;
    case CV_16S:
      dtype = py::dtype::of<int16_t>();
      break;
    case CV_32S:
      dtype = py::dtype::of<int32_t>();
      break;
    case CV_32F:
      dtype = py::dtype::of<float>();
      break;
    case CV_64F:
      dtype = py::dtype::of<double>();
      break;
    default:
      throw py::type_error("an image depth numpy has no type for");
  }
  std::vector<py::ssize_t> shape = {mat.rows, mat.cols};
  std::vector<py::ssize_t> strides = {static_cast<py::ssize_t>(mat.step[0]),
                                      static_cast<py::ssize_t>(mat.elemSize())};
  if (mat.channels() > 1) {
    shape.push_back(mat.channels());
    strides.push_back(static_cast<py::ssize_t>(mat.elemSize1()));
  }
  // The capsule owns a Mat header: the buffer's reference count keeps the pixels alive with the array.
  auto* keeper = new cv::Mat(mat);
  py::capsule base(keeper, [](void* pointer) { delete static_cast<cv::Mat*>(pointer); });
  py::array array(dtype, shape, strides, keeper->data, base);
  if (!writable) array.attr("flags").attr("writeable") = false;
  return array;
}

namespace {

template <class T>
cv::Mat CopyArray(const py::handle& input, int depth, int channels, int rows, int cols,
                  const std::string& what) {
  py::array source = py::reinterpret_borrow<py::object>(input);
  if (!py::isinstance<py::array>(input)) source = py::module_::import("numpy").attr("asarray")(input);
  const bool is_bool = source.dtype().kind() == 'b';
  auto array = py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(source);
  if (!array) throw py::value_error(fmt::format("{}: cannot be read as an array of numbers", what));
  const int ndim = static_cast<int>(array.ndim());
  const bool shape_ok = (ndim == 2 && channels == 1) || (ndim == 3 && array.shape(2) == channels);
  const auto expected = [&] {
    const std::string r = rows < 0 ? "rows" : std::to_string(rows),
                      c = cols < 0 ? "cols" : std::to_string(cols);
    return channels == 1 ? fmt::format("({}, {})", r, c) : fmt::format("({}, {}, {})", r, c, channels);
  };
  std::string got = "(";
  for (int i = 0; i < ndim; ++i) got += (i ? ", " : "") + std::to_string(array.shape(i));
  got += ")";
  if (!shape_ok || (rows >= 0 && array.shape(0) != rows) || (cols >= 0 && array.shape(1) != cols)) {
    throw py::value_error(
        fmt::format("{}: expected an array of shape {}, got shape {}", what, expected(), got));
  }
  const int height = static_cast<int>(array.shape(0)), width = static_cast<int>(array.shape(1));
  cv::Mat mat(height, width, CV_MAKETYPE(depth, channels));
  std::memcpy(mat.data, array.data(), static_cast<size_t>(height) * width * channels * sizeof(T));
  if (is_bool && depth == CV_8U) mat *= 255;  // True -> 255, the project's mask convention
  return mat;
}

}  // namespace

cv::Mat ArrayToMat(const py::handle& array, int depth, int channels, int rows, int cols,
                   const std::string& what) {
  switch (depth) {
    case CV_8U:
      return CopyArray<uint8_t>(array, depth, channels, rows, cols, what);
    case CV_16U:
      return CopyArray<uint16_t>(array, depth, channels, rows, cols, what);
    case CV_32S:
      return CopyArray<int32_t>(array, depth, channels, rows, cols, what);
    case CV_32F:
      return CopyArray<float>(array, depth, channels, rows, cols, what);
    case CV_64F:
      return CopyArray<double>(array, depth, channels, rows, cols, what);
    default:
      throw py::type_error("unsupported image depth");
  }
}

cv::Mat ArrayToMatAnyChannels(const py::handle& input, int depth, const std::string& what) {
  py::array array = py::module_::import("numpy").attr("asarray")(input);
  if (array.ndim() == 2) return ArrayToMat(array, depth, 1, -1, -1, what);
  if (array.ndim() == 3 && array.shape(2) >= 1 && array.shape(2) <= 512) {
    return ArrayToMat(array, depth, static_cast<int>(array.shape(2)), -1, -1, what);
  }
  throw py::value_error(
      fmt::format("{}: expected an array of shape (rows, cols) or (rows, cols, channels)", what));
}

py::array_t<double> MatrixToArray(const Eigen::Matrix4d& matrix) {
  py::array_t<double> array({4, 4});
  auto view = array.mutable_unchecked<2>();
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) view(r, c) = matrix(r, c);
  }
  return array;
}

Eigen::Matrix4d ArrayToMatrix(const py::handle& input, const std::string& what) {
  auto array = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(input);
  if (!array || array.ndim() != 2 || array.shape(0) != 4 || array.shape(1) != 4) {
    throw py::value_error(fmt::format("{}: expected a 4 x 4 matrix", what));
  }
  Eigen::Matrix4d matrix;
  auto view = array.unchecked<2>();
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) matrix(r, c) = view(r, c);
  }
  if (!matrix.allFinite()) throw py::value_error(fmt::format("{}: not finite", what));
  return matrix;
}

}  // namespace lidarshop::python
