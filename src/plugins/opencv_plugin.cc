// The functions of the OpenCV plugin (src/plugins/CMakeLists.txt says why it is one), looked up by name
// (util/plugin.h). C names, C++ arguments: the plugin and lidarshop share libopencv_core and libstdc++, so a
// cv::Mat, a std::string and a cv::Exception cross the boundary as they are.
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/ximgproc/segmentation.hpp>
#include <opencv2/ximgproc/slic.hpp>

extern "C" {

void lidarshop_imread(const std::string* path, int flags, cv::Mat* image) {
  *image = cv::imread(*path, flags);
}

void lidarshop_imdecode(const cv::Mat* bytes, int flags, cv::Mat* image) {
  *image = cv::imdecode(*bytes, flags);
}

bool lidarshop_imwrite(const std::string* path, const cv::Mat* image) { return cv::imwrite(*path, *image); }

bool lidarshop_imencode(const std::string* extension, const cv::Mat* image, std::vector<uchar>* bytes) {
  return cv::imencode(*extension, *image, *bytes);
}

// SLICO superpixels: labels CV_32S, *count the number of superpixels.
void lidarshop_slic(const cv::Mat* image, int region_size, float ruler, int iterations, cv::Mat* labels,
                    int* count) {
  const cv::Ptr<cv::ximgproc::SuperpixelSLIC> slic =
      cv::ximgproc::createSuperpixelSLIC(*image, cv::ximgproc::SLICO, region_size, ruler);
  slic->iterate(iterations);
  slic->enforceLabelConnectivity();
  slic->getLabels(*labels);
  *count = slic->getNumberOfSuperpixels();
}

// Felzenszwalb–Huttenlocher graph segmentation: labels CV_32S.
void lidarshop_graph_segmentation(const cv::Mat* image, double sigma, float k, int min_size,
                                  cv::Mat* labels) {
  const cv::Ptr<cv::ximgproc::segmentation::GraphSegmentation> graph =
      cv::ximgproc::segmentation::createGraphSegmentation(sigma, k, min_size);
  graph->processImage(*image, *labels);
}

}  // extern "C"
