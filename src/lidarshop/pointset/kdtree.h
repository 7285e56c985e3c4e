// A 3-D KD-tree over a list of points (nanoflann), built once and queried many
// times from any number of threads.
//
//   PointKdTree tree(points_in_model);                  // #P points, copied; O(P log P)
//   NearestResult nearest = tree.Nearest(query);         // closest point and its squared distance
//   tree.ForEachInRadius(query, 0.05f, [&](uint32_t index, float distance_sq) { ... });
//
// Queries never allocate (except RadiusSearch, which fills a vector) and are const, so a built tree is safe
// to share between threads. Distances are squared Euclidean, in the units of the points (metres in
// lidarshop).
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <nanoflann.hpp>

namespace lidarshop {

struct NearestResult {
  int64_t index = -1;                                          // -1 when the tree is empty
  float distance_sq = std::numeric_limits<float>::infinity();  // squared distance to that point
  bool found() const { return index >= 0; }
};

class PointKdTree {
 public:
  PointKdTree() = default;
  // Copies the points and builds the tree. `leaf_size` trades build time against query
  // time (nanoflann's default is 10).
  explicit PointKdTree(std::vector<Eigen::Vector3f> points, int leaf_size = 10);
  PointKdTree(PointKdTree&&) noexcept;
  PointKdTree& operator=(PointKdTree&&) noexcept;
  PointKdTree(const PointKdTree&) = delete;
  PointKdTree& operator=(const PointKdTree&) = delete;
  ~PointKdTree();

  size_t size() const { return cloud_ ? cloud_->points.size() : 0; }
  bool empty() const { return size() == 0; }
  // The points as given (empty for a default-constructed tree).
  std::span<const Eigen::Vector3f> points() const {
    return cloud_ ? std::span<const Eigen::Vector3f>(cloud_->points) : std::span<const Eigen::Vector3f>();
  }

  // The closest point to `query`; index -1 when empty.
  NearestResult Nearest(const Eigen::Vector3f& query) const;
  // The closest point within `max_distance` (index -1 when none); faster than
  // Nearest when most queries are far.
  NearestResult NearestWithin(const Eigen::Vector3f& query, float max_distance) const;
  // The k closest points, nearest first (fewer when the tree is smaller). Indices and squared distances.
  void KNearest(const Eigen::Vector3f& query, int k, std::vector<uint32_t>* indices,
                std::vector<float>* distances_sq) const;
  // All points strictly closer than `radius`, sorted by distance when `sorted`.
  void RadiusSearch(const Eigen::Vector3f& query, float radius,
                    std::vector<std::pair<uint32_t, float>>* matches, bool sorted = false) const;

  // Calls visit(index, distance_sq) for every point strictly closer than `radius` (unordered). No allocation.
  template <typename Visit>
  void ForEachInRadius(const Eigen::Vector3f& query, float radius, Visit&& visit) const {
    if (empty()) return;
    CallbackResultSet<Visit> result{radius * radius, visit};
    index_->findNeighbors(result, query.data(), nanoflann::SearchParams(32, 0.0f, false));
  }

 private:
  struct Cloud {
    std::vector<Eigen::Vector3f> points;
    size_t kdtree_get_point_count() const { return points.size(); }
    float kdtree_get_pt(size_t index, size_t dim) const { return points[index][static_cast<int>(dim)]; }
    template <class Box>
    bool kdtree_get_bbox(Box&) const {
      return false;
    }
  };
  using Index =
      nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, Cloud, float, uint32_t>, Cloud,
                                          3, uint32_t>;

  template <typename Visit>
  struct CallbackResultSet {
    float radius_sq;
    Visit& visit;
    size_t count = 0;
    bool full() const { return true; }
    size_t size() const { return count; }
    float worstDist() const { return radius_sq; }
    bool addPoint(float distance_sq, uint32_t index) {
      if (distance_sq < radius_sq) {
        visit(index, distance_sq);
        ++count;
      }
      return true;
    }
  };

  // Both on the heap: the index keeps a reference to the cloud, which must not move when the tree does.
  std::unique_ptr<Cloud> cloud_;
  std::unique_ptr<Index> index_;
};

}  // namespace lidarshop
