#include "lidarshop/recolor/distance_raster.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <vector>

#include <Eigen/Geometry>

#include "lidarshop/recolor/view_cull.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop::recolor_internal {
namespace {

constexpr int kStripRows = 128;  // rows per cast: bounded memory for 3072 x 2304 photos

struct BufferGeometry {
  int rows = 0, cols = 0;
  double sx = 1, sy = 1;  // photo pixels per buffer pixel
};

BufferGeometry BufferFor(const Camera& camera, double scale) {
  BufferGeometry g;
  g.rows = std::max(1, static_cast<int>(std::lround(camera.height_px() * scale)));
  g.cols = std::max(1, static_cast<int>(std::lround(camera.width_px() * scale)));
  g.sy = static_cast<double>(camera.height_px()) / g.rows;
  g.sx = static_cast<double>(camera.width_px()) / g.cols;
  return g;
}

// The ray of buffer pixel (row, col) in the camera frame: pinhole rays keep z = 1 (as the pinhole's own
// unprojection gives them), other models' are unit; zero where a pixel has no ray.
Eigen::Vector3f PixelRay(const Camera& camera, const BufferGeometry& g, int row, int col) {
  const Eigen::Vector2d pixel((col + 0.5) * g.sx, (row + 0.5) * g.sy);
  Eigen::Vector3d ray = Eigen::Vector3d::Zero();
  if (camera.model == CameraModel::kPinhole) {
    ray = UnprojectPixel(camera.pinhole, pixel);
  } else if (!UnprojectPixel(camera, pixel, &ray)) {
    ray.setZero();
  }
  return ray.cast<float>();
}

// Embree's geometric normal of a triangle, Ng = (v1 − v0) × (v2 − v0) (the test compares the two buffers'
// back-facing flags); a ray d sees the triangle from behind when d · Ng > 0.
Eigen::Vector3f EmbreeNormal(const Eigen::Vector3f& v0, const Eigen::Vector3f& v1,
                             const Eigen::Vector3f& v2) {
  return (v1 - v0).cross(v2 - v0);
}

// Trivially constructible: a photo's buffer of them is allocated for every mesh vertex but written only for
// the vertices of the blocks its view reaches (the pages of the others are never touched).
struct ProjectedVertex {
  Eigen::Vector3f in_camera;
  float x, y;       // continuous buffer pixels
  bool projects;    // false: the camera model gives the vertex no pixel
  bool behind;      // pinhole: z <= 0
  uint8_t outcode;  // ViewPlanes::Outcode
};

// The vertices of the blocks `blocks` (indices into the mesh's blocks of kCullBlockTriangles), projected; the
// other entries are left unwritten.
std::unique_ptr<ProjectedVertex[]> ProjectVertices(const TriangleMesh& mesh, const Camera& camera,
                                                   const BufferGeometry& g, const ViewPlanes& planes,
                                                   const std::vector<int32_t>& blocks) {
  const Eigen::Matrix3d camera_from_world = camera.world_from_camera.topLeftCorner<3, 3>().transpose();
  const Eigen::Vector3d center = camera.center_in_world();
  auto out = std::make_unique_for_overwrite<ProjectedVertex[]>(mesh.vertices.size());
  const int64_t triangles = static_cast<int64_t>(mesh.triangles.size());
  // Which vertices: a byte each (zero pages cost nothing until written), set from the blocks in parallel.
  std::vector<uint8_t> needed(mesh.vertices.size(), 0);
  ParallelFor(
      static_cast<int64_t>(blocks.size()),
      [&](int64_t i) {
        const int64_t begin = static_cast<int64_t>(blocks[i]) * kCullBlockTriangles;
        const int64_t end = std::min(triangles, begin + kCullBlockTriangles);
        for (int64_t f = begin; f < end; ++f) {
          for (int k = 0; k < 3; ++k)
            std::atomic_ref<uint8_t>(needed[mesh.triangles[f][k]]).store(1, std::memory_order_relaxed);
        }
      },
      16);
  ParallelForRange(
      static_cast<int64_t>(mesh.vertices.size()),
      [&](int64_t begin, int64_t end) {
        for (int64_t v = begin; v < end; ++v) {
          if (!needed[v]) continue;
          const Eigen::Vector3d p = camera_from_world * (mesh.vertices[v].cast<double>() - center);
          ProjectedVertex& pv = out[v];
          pv.in_camera = p.cast<float>();
          pv.x = pv.y = 0;
          pv.projects = false;
          pv.behind = camera.model == CameraModel::kPinhole && p.z() <= 0;
          pv.outcode = planes.Outcode(pv.in_camera);
          if (pv.behind) continue;
          Eigen::Vector2d pixel;
          if (!ProjectCameraPoint(camera, p, &pixel)) continue;
          pv.projects = true;
          pv.x = static_cast<float>(pixel.x() / g.sx);
          pv.y = static_cast<float>(pixel.y() / g.sy);
        }
      },
      4096);
  return out;
}

// The blocks of `mesh` whose box the view can reach (every block without planes), in order.
std::vector<int32_t> BlocksInView(const TriangleMesh& mesh, const ViewPlanes& planes,
                                  const std::vector<Eigen::AlignedBox3f>* boxes) {
  const int64_t blocks =
      (static_cast<int64_t>(mesh.triangles.size()) + kCullBlockTriangles - 1) / kCullBlockTriangles;
  std::vector<int32_t> out;
  if (planes.count == 0 || boxes == nullptr || static_cast<int64_t>(boxes->size()) != blocks) {
    out.resize(blocks);
    for (int64_t b = 0; b < blocks; ++b) out[b] = static_cast<int32_t>(b);
    return out;
  }
  std::vector<uint8_t> keep(blocks);
  ParallelFor(
      blocks, [&](int64_t b) { keep[b] = !planes.Outside((*boxes)[b]); }, 1024);
  for (int64_t b = 0; b < blocks; ++b) {
    if (keep[b]) out.push_back(static_cast<int32_t>(b));
  }
  return out;
}

// The key of a hit: the distance's bits (a non-negative float orders as its bits do) above the triangle's
// index, so that the smallest key is the nearest hit and ties go to the lower index.
uint64_t HitKey(float distance, uint32_t triangle) {
  return (static_cast<uint64_t>(std::bit_cast<uint32_t>(distance)) << 32) | triangle;
}
constexpr uint64_t kNoHit = std::numeric_limits<uint64_t>::max();

void AtomicMin(std::atomic<uint64_t>& slot, uint64_t key) {
  uint64_t current = slot.load(std::memory_order_relaxed);
  while (key < current && !slot.compare_exchange_weak(current, key, std::memory_order_relaxed)) {
  }
}

// Möller–Trumbore from the camera centre (the origin), with a small tolerance on the barycentric bounds so
// that a ray through an edge shared by two triangles hits one of them (no cracks): the distance along `ray`
// times |ray|, or a negative value for a miss.
float RayDistance(const Eigen::Vector3f& ray, float ray_norm, const Eigen::Vector3f& v0,
                  const Eigen::Vector3f& e1, const Eigen::Vector3f& e2) {
  constexpr float kEdge = 1e-6f;
  const Eigen::Vector3f p = ray.cross(e2);
  const float det = e1.dot(p);
  if (det == 0.0f || !std::isfinite(det)) return -1;
  const float inv = 1.0f / det;
  const Eigen::Vector3f s = -v0;
  const float u = s.dot(p) * inv;
  if (u < -kEdge || u > 1 + kEdge) return -1;
  const Eigen::Vector3f q = s.cross(e1);
  const float v = ray.dot(q) * inv;
  if (v < -kEdge || u + v > 1 + kEdge) return -1;
  const float t = e2.dot(q) * inv;
  return t > 0 ? t * ray_norm : -1;
}

// The ray of each buffer pixel (camera frame) and its length: from a table, or — an undistorted pinhole
// without skew, whose ray is (a(col), b(row), 1) — from a row and a column of normalized coordinates (the same
// arithmetic as PixelRay, so the same floats), which spares each photo a table of 16 bytes per pixel.
struct PixelRays {
  const BufferGeometry* g = nullptr;
  bool separable = false;
  std::vector<float> a_of_col, b_of_row;  // separable
  std::vector<Eigen::Vector3f> table;     // otherwise
  std::vector<float> norms;

  Eigen::Vector3f Ray(int row, int col, float* norm) const {
    if (!separable) {
      const size_t pixel = static_cast<size_t>(row) * g->cols + col;
      *norm = norms[pixel];
      return table[pixel];
    }
    const Eigen::Vector3f ray(a_of_col[col], b_of_row[row], 1.0f);
    *norm = ray.norm();
    return ray;
  }
};

PixelRays RaysOf(const Camera& camera, const BufferGeometry& g) {
  PixelRays rays;
  rays.g = &g;
  const PinholeCamera& k = camera.pinhole;
  if (camera.model == CameraModel::kPinhole && !k.has_distortion() && k.skew_px == 0) {
    rays.separable = true;
    // UnprojectPixel's b = (y − cy) / fy and a = (x − cx − skew · b) / fx, with skew 0.
    for (int r = 0; r < g.rows; ++r)
      rays.b_of_row.push_back(static_cast<float>(((r + 0.5) * g.sy - k.cy_px) / k.fy_px));
    for (int c = 0; c < g.cols; ++c)
      rays.a_of_col.push_back(static_cast<float>(((c + 0.5) * g.sx - k.cx_px - k.skew_px * 0.0) / k.fx_px));
    return rays;
  }
  const int64_t pixels = static_cast<int64_t>(g.rows) * g.cols;
  rays.table.resize(pixels);
  rays.norms.resize(pixels);
  ParallelFor(g.rows, [&](int64_t r) {
    for (int c = 0; c < g.cols; ++c) {
      const size_t pixel = static_cast<size_t>(r) * g.cols + c;
      rays.table[pixel] = PixelRay(camera, g, static_cast<int>(r), c);
      rays.norms[pixel] = rays.table[pixel].norm();
    }
  });
  return rays;
}

struct RasterTarget {
  const BufferGeometry& g;
  const PixelRays& rays;
  std::vector<std::atomic<uint64_t>>& keys;
  bool panorama = false;        // spherical or cylindrical: a triangle across the seam is cast
  bool straight_edges = false;  // a pinhole without distortion maps a triangle's edges to straight lines
};

// Rasterizes one mesh; appends the triangles it leaves to the cast to `cast` (indices into the mesh).
// Only the triangles of `blocks`; a triangle with its corners outside one view plane meets no ray of the image.
void RasterMesh(const TriangleMesh& mesh, const ProjectedVertex* vertices, const std::vector<int32_t>& blocks,
                uint32_t index_base, const RasterTarget& target, const RasterOptions& options,
                std::vector<int32_t>* cast) {
  std::mutex cast_mutex;
  const BufferGeometry& g = target.g;
  const int64_t triangles = static_cast<int64_t>(mesh.triangles.size());
  ParallelForRange(
      static_cast<int64_t>(blocks.size()),
      [&](int64_t block_begin, int64_t block_end) {
        std::vector<int32_t> local_cast;
        for (int64_t i = block_begin; i < block_end; ++i) {
          const int64_t begin = static_cast<int64_t>(blocks[i]) * kCullBlockTriangles;
          const int64_t end = std::min(triangles, begin + kCullBlockTriangles);
          for (int64_t f = begin; f < end; ++f) {
            const Eigen::Vector3i& t = mesh.triangles[f];
            const ProjectedVertex& a = vertices[t[0]];
            const ProjectedVertex& b = vertices[t[1]];
            const ProjectedVertex& c = vertices[t[2]];
            if (a.behind && b.behind && c.behind) continue;  // every pinhole ray has z > 0
            if ((a.outcode & b.outcode & c.outcode) != 0) continue;
            if (!a.projects || !b.projects || !c.projects) {
              local_cast.push_back(static_cast<int32_t>(f));
              continue;
            }
            const float min_x = std::min({a.x, b.x, c.x}), max_x = std::max({a.x, b.x, c.x});
            const float min_y = std::min({a.y, b.y, c.y}), max_y = std::max({a.y, b.y, c.y});
            const float size = std::max(max_x - min_x, max_y - min_y);
            if (size > options.max_raster_px || (target.panorama && max_x - min_x > 0.5f * g.cols)) {
              local_cast.push_back(static_cast<int32_t>(f));
              continue;
            }
            // The corners' box holds the projection but for edges a camera model bends, and rounding.
            const float pad =
                0.01f + (target.straight_edges ? 0.0f : static_cast<float>(options.bend_margin) * size);
            // Pixel centres (col + 0.5, row + 0.5) inside the padded box.
            const int c0 = std::max(0, static_cast<int>(std::ceil(min_x - pad - 0.5f)));
            const int c1 = std::min(g.cols - 1, static_cast<int>(std::floor(max_x + pad - 0.5f)));
            const int r0 = std::max(0, static_cast<int>(std::ceil(min_y - pad - 0.5f)));
            const int r1 = std::min(g.rows - 1, static_cast<int>(std::floor(max_y + pad - 0.5f)));
            if (c0 > c1 || r0 > r1) continue;
            const Eigen::Vector3f& v0 = a.in_camera;
            const Eigen::Vector3f e1 = b.in_camera - v0, e2 = c.in_camera - v0;
            const uint32_t index = index_base + static_cast<uint32_t>(f);
            for (int r = r0; r <= r1; ++r) {
              for (int col = c0; col <= c1; ++col) {
                const size_t pixel = static_cast<size_t>(r) * g.cols + col;
                float norm;
                const Eigen::Vector3f ray = target.rays.Ray(r, col, &norm);
                if (norm == 0.0f) continue;
                const float distance = RayDistance(ray, norm, v0, e1, e2);
                if (distance > 0) AtomicMin(target.keys[pixel], HitKey(distance, index));
              }
            }
          }
        }
        if (!local_cast.empty()) {
          const std::lock_guard<std::mutex> lock(cast_mutex);
          cast->insert(cast->end(), local_cast.begin(), local_cast.end());
        }
      },
      8);
  std::sort(cast->begin(), cast->end());  // chunks finish in any order
}

// The triangles `indices` of `mesh` as a mesh of their own (only the vertices they use).
TriangleMesh Subset(const TriangleMesh& mesh, const std::vector<int32_t>& indices) {
  TriangleMesh out;
  std::vector<int32_t> new_index(mesh.vertices.size(), -1);
  out.triangles.reserve(indices.size());
  for (const int32_t f : indices) {
    Eigen::Vector3i t;
    for (int k = 0; k < 3; ++k) {
      int32_t& slot = new_index[mesh.triangles[f][k]];
      if (slot < 0) {
        slot = static_cast<int32_t>(out.vertices.size());
        out.vertices.push_back(mesh.vertices[mesh.triangles[f][k]]);
      }
      t[k] = slot;
    }
    out.triangles.push_back(t);
  }
  return out;
}

}  // namespace

DistanceBuffer CastDistanceBuffer(const RaycastScene& scene, const Camera& camera, double scale) {
  const BufferGeometry g = BufferFor(camera, scale);
  DistanceBuffer out;
  out.distance.create(g.rows, g.cols, CV_32F);
  out.back_facing.create(g.rows, g.cols, CV_8U);
  const Eigen::Matrix3f rotation = camera.world_from_camera.topLeftCorner<3, 3>().cast<float>();
  RayHitImages hits;
  for (int row0 = 0; row0 < g.rows; row0 += kStripRows) {
    const int strip_rows = std::min(kStripRows, g.rows - row0);
    cv::Mat directions(strip_rows, g.cols, CV_32FC3);
    ParallelFor(strip_rows, [&](int64_t r) {
      for (int c = 0; c < g.cols; ++c) {
        const Eigen::Vector3f ray = PixelRay(camera, g, row0 + static_cast<int>(r), c);
        directions.at<cv::Vec3f>(static_cast<int>(r), c) = cv::Vec3f(ray.x(), ray.y(), ray.z());
      }
    });
    scene.CastImage(camera.world_from_camera, directions, 0.0f, std::numeric_limits<float>::infinity(),
                    CastMethod::kPacket16, &hits);
    for (int r = 0; r < strip_rows; ++r) {
      for (int c = 0; c < g.cols; ++c) {
        const cv::Vec3f d = directions.at<cv::Vec3f>(r, c);
        out.distance.at<float>(row0 + r, c) = d == cv::Vec3f()
                                                  ? std::numeric_limits<float>::infinity()
                                                  : hits.t_hit.at<float>(r, c) * std::sqrt(d.dot(d));
        const cv::Vec3f n = hits.normal.at<cv::Vec3f>(r, c);
        const Eigen::Vector3f w = rotation * Eigen::Vector3f(d[0], d[1], d[2]);
        // Skirts (geometry 1) are no surface of the scan: only the scan mesh's own back faces count.
        out.back_facing.at<uint8_t>(row0 + r, c) =
            hits.geometry_id.at<int32_t>(r, c) == 0 && w.dot(Eigen::Vector3f(n[0], n[1], n[2])) > 0 ? 255 : 0;
      }
    }
  }
  return out;
}

DistanceBuffer RasterDistanceBuffer(const TriangleMesh& mesh, const TriangleMesh& skirts,
                                    const Camera& camera, double scale, const RasterOptions& options,
                                    const RasterBlockBoxes& block_boxes) {
  const BufferGeometry g = BufferFor(camera, scale);
  const int64_t pixels = static_cast<int64_t>(g.rows) * g.cols;
  if (mesh.triangles.size() + skirts.triangles.size() >= std::numeric_limits<uint32_t>::max())
    throw std::length_error("RasterDistanceBuffer: more than 2^32 - 1 triangles");

  const PixelRays rays = RaysOf(camera, g);
  std::vector<std::atomic<uint64_t>> keys(pixels);
  for (auto& key : keys) key.store(kNoHit, std::memory_order_relaxed);

  // An undistorted pinhole maps a triangle to the triangle of its corners' pixels: its box needs no padding
  // for bent edges (the flag was declared but never set before).
  const RasterTarget target{
      g, rays, keys, camera.model == CameraModel::kSpherical || camera.model == CameraModel::kCylindrical,
      camera.model == CameraModel::kPinhole && !camera.pinhole.has_distortion()};
  const ViewPlanes planes = options.cull_outside_view ? ImageViewPlanes(camera) : ViewPlanes();
  std::vector<Eigen::AlignedBox3f> own_mesh_boxes, own_skirt_boxes;
  const std::vector<Eigen::AlignedBox3f>* mesh_boxes = block_boxes.mesh;
  const std::vector<Eigen::AlignedBox3f>* skirt_boxes = block_boxes.skirts;
  if (planes.count > 0 && mesh_boxes == nullptr) mesh_boxes = &(own_mesh_boxes = TriangleBlockBoxes(mesh));
  if (planes.count > 0 && skirt_boxes == nullptr)
    skirt_boxes = &(own_skirt_boxes = TriangleBlockBoxes(skirts));
  const std::vector<int32_t> mesh_blocks = BlocksInView(mesh, planes, mesh_boxes);
  const std::vector<int32_t> skirt_blocks = BlocksInView(skirts, planes, skirt_boxes);
  const std::unique_ptr<ProjectedVertex[]> mesh_vertices =
      ProjectVertices(mesh, camera, g, planes, mesh_blocks);
  std::vector<int32_t> cast_mesh, cast_skirts;
  RasterMesh(mesh, mesh_vertices.get(), mesh_blocks, 0, target, options, &cast_mesh);
  const std::unique_ptr<ProjectedVertex[]> skirt_vertices =
      ProjectVertices(skirts, camera, g, planes, skirt_blocks);
  RasterMesh(skirts, skirt_vertices.get(), skirt_blocks, static_cast<uint32_t>(mesh.triangles.size()), target,
             options, &cast_skirts);

  DistanceBuffer out;
  out.distance.create(g.rows, g.cols, CV_32F);
  out.back_facing.create(g.rows, g.cols, CV_8U);
  const uint32_t mesh_triangles = static_cast<uint32_t>(mesh.triangles.size());
  ParallelFor(g.rows, [&](int64_t r) {
    for (int c = 0; c < g.cols; ++c) {
      const size_t pixel = static_cast<size_t>(r) * g.cols + c;
      const uint64_t key = keys[pixel].load(std::memory_order_relaxed);
      float& distance = out.distance.at<float>(static_cast<int>(r), c);
      uint8_t& back = out.back_facing.at<uint8_t>(static_cast<int>(r), c);
      back = 0;
      if (key == kNoHit) {
        distance = std::numeric_limits<float>::infinity();
        continue;
      }
      distance = std::bit_cast<float>(static_cast<uint32_t>(key >> 32));
      const uint32_t triangle = static_cast<uint32_t>(key & 0xffffffffu);
      if (triangle >= mesh_triangles) continue;  // a skirt
      const Eigen::Vector3i& t = mesh.triangles[triangle];
      const Eigen::Vector3f n = EmbreeNormal(mesh_vertices[t[0]].in_camera, mesh_vertices[t[1]].in_camera,
                                             mesh_vertices[t[2]].in_camera);
      float norm;
      back = rays.Ray(static_cast<int>(r), c, &norm).dot(n) > 0 ? 255 : 0;
    }
  });

  out.cast_triangles = static_cast<int64_t>(cast_mesh.size() + cast_skirts.size());
  if (out.cast_triangles > 0) {
    RaycastScene scene;
    if (!cast_mesh.empty()) scene.AddMesh(Subset(mesh, cast_mesh), 0);
    if (!cast_skirts.empty()) scene.AddMesh(Subset(skirts, cast_skirts), 1);
    scene.Commit();
    const DistanceBuffer cast = CastDistanceBuffer(scene, camera, scale);
    for (int r = 0; r < g.rows; ++r) {
      for (int c = 0; c < g.cols; ++c) {
        const float d = cast.distance.at<float>(r, c);
        if (d < out.distance.at<float>(r, c)) {
          out.distance.at<float>(r, c) = d;
          out.back_facing.at<uint8_t>(r, c) = cast.back_facing.at<uint8_t>(r, c);
        }
      }
    }
  }
  return out;
}

}  // namespace lidarshop::recolor_internal
