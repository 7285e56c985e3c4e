#include "lidarshop/pointset/kdtree.h"

#include <algorithm>

namespace lidarshop {

PointKdTree::PointKdTree(std::vector<Eigen::Vector3f> points, int leaf_size) {
  cloud_ = std::make_unique<Cloud>();
  cloud_->points = std::move(points);
  index_ =
      std::make_unique<Index>(3, *cloud_, nanoflann::KDTreeSingleIndexAdaptorParams(std::max(1, leaf_size)));
}

PointKdTree::PointKdTree(PointKdTree&& other) noexcept = default;
PointKdTree& PointKdTree::operator=(PointKdTree&& other) noexcept = default;
PointKdTree::~PointKdTree() = default;

NearestResult PointKdTree::Nearest(const Eigen::Vector3f& query) const {
  NearestResult result;
  if (empty()) return result;
  uint32_t index = 0;
  float distance_sq = 0.0f;
  nanoflann::KNNResultSet<float, uint32_t> set(1);
  set.init(&index, &distance_sq);
  index_->findNeighbors(set, query.data(), nanoflann::SearchParams());
  if (set.size() == 0) return result;
  result.index = index;
  result.distance_sq = distance_sq;
  return result;
}

NearestResult PointKdTree::NearestWithin(const Eigen::Vector3f& query, float max_distance) const {
  NearestResult result;
  if (empty()) return result;
  // A one-element result set whose worst distance starts at the radius, so that branches beyond the
  // radius are pruned at once.
  struct Closest {
    float worst;
    uint32_t index = 0;
    bool any = false;
    bool full() const { return true; }
    size_t size() const { return any ? 1 : 0; }
    float worstDist() const { return worst; }
    bool addPoint(float distance_sq, uint32_t i) {
      if (distance_sq < worst) {
        worst = distance_sq;
        index = i;
        any = true;
      }
      return true;
    }
  } set{max_distance * max_distance};
  index_->findNeighbors(set, query.data(), nanoflann::SearchParams());
  if (!set.any) return result;
  result.index = set.index;
  result.distance_sq = set.worst;
  return result;
}

void PointKdTree::KNearest(const Eigen::Vector3f& query, int k, std::vector<uint32_t>* indices,
                           std::vector<float>* distances_sq) const {
  indices->clear();
  distances_sq->clear();
  if (empty() || k <= 0) return;
  const size_t count = std::min<size_t>(static_cast<size_t>(k), size());
  indices->resize(count);
  distances_sq->resize(count);
  nanoflann::KNNResultSet<float, uint32_t> set(count);
  set.init(indices->data(), distances_sq->data());
  index_->findNeighbors(set, query.data(), nanoflann::SearchParams());
  indices->resize(set.size());
  distances_sq->resize(set.size());
}

void PointKdTree::RadiusSearch(const Eigen::Vector3f& query, float radius,
                               std::vector<std::pair<uint32_t, float>>* matches, bool sorted) const {
  matches->clear();
  if (empty()) return;
  index_->radiusSearch(query.data(), radius * radius, *matches, nanoflann::SearchParams(32, 0.0f, sorted));
}

}  // namespace lidarshop
