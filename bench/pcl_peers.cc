// The PCL side of bench/pointset_peers.py (bench/results/pointset.md): the same tools as lidarshop's
// `points` operations, run by PCL 1.13 on the same cloud, timed call by call. Built only when CMake finds PCL
// (Debian libpcl-dev, about 325 packages; scripts/setup.sh does not install it): nothing in lidarshop uses it.
//
//   pcl_peers POINTS.f32 WORK_DIR [POISSON_POINTS.f32]
//
// POINTS.f32: #P x 3 float32, little-endian, no header (what the Python script wrote, so that every tool
// reads exactly the same numbers). POISSON_POINTS.f32: #Q x 6 float32 (x y z nx ny nz), the Poisson input.
// Writes WORK_DIR/pcl_normals.f32 (#P x 3), pcl_kept.i32, pcl_plane.i32 (indices into POINTS), and prints one
// JSON object: seconds per tool, counts, the plane, the Poisson mesh's size.
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include <pcl/features/normal_3d_omp.h>
#include <pcl/filters/statistical_outlier_removal.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/extract_clusters.h>
#include <pcl/segmentation/sac_segmentation.h>
#include <pcl/surface/poisson.h>

namespace {

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::vector<float> ReadFloats(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::vector<float> values(static_cast<size_t>(in.tellg()) / sizeof(float));
  in.seekg(0);
  in.read(reinterpret_cast<char*>(values.data()),
          static_cast<std::streamsize>(values.size() * sizeof(float)));
  return values;
}

template <class T>
void WriteArray(const std::string& path, const std::vector<T>& values) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(values.data()),
            static_cast<std::streamsize>(values.size() * sizeof(T)));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: pcl_peers POINTS.f32 WORK_DIR [POISSON_POINTS.f32]\n";
    return 2;
  }
  const std::string work = argv[2];
  const std::vector<float> xyz = ReadFloats(argv[1]);
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  cloud->resize(xyz.size() / 3);
  for (size_t i = 0; i < cloud->size(); ++i)
    (*cloud)[i] = pcl::PointXYZ(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
  std::string json = "{\"points\": " + std::to_string(cloud->size());

  // Normals from the 20 nearest points (the point itself included, as lidarshop and Open3D), both cores,
  // turned toward the origin (PCL's default viewpoint; lidarshop's for a plain cloud).
  {
    const auto start = std::chrono::steady_clock::now();
    pcl::NormalEstimationOMP<pcl::PointXYZ, pcl::Normal> estimation(2);
    estimation.setInputCloud(cloud);
    estimation.setSearchMethod(
        pcl::search::KdTree<pcl::PointXYZ>::Ptr(new pcl::search::KdTree<pcl::PointXYZ>));
    estimation.setKSearch(20);
    pcl::PointCloud<pcl::Normal> normals;
    estimation.compute(normals);
    json += ", \"normals_s\": " + std::to_string(SecondsSince(start));
    std::vector<float> out(3 * normals.size());
    for (size_t i = 0; i < normals.size(); ++i) {
      out[3 * i] = normals[i].normal_x;
      out[3 * i + 1] = normals[i].normal_y;
      out[3 * i + 2] = normals[i].normal_z;
    }
    WriteArray(work + "/pcl_normals.f32", out);
  }
  // Statistical outlier removal: mean distance to the 20 nearest above mean + 2 σ.
  {
    const auto start = std::chrono::steady_clock::now();
    pcl::StatisticalOutlierRemoval<pcl::PointXYZ> removal;
    removal.setInputCloud(cloud);
    removal.setMeanK(20);
    removal.setStddevMulThresh(2.0);
    pcl::Indices kept;
    removal.filter(kept);
    json += ", \"outliers_s\": " + std::to_string(SecondsSince(start)) +
            ", \"kept\": " + std::to_string(kept.size());
    WriteArray(work + "/pcl_kept.i32", std::vector<int32_t>(kept.begin(), kept.end()));
  }
  // RANSAC plane, 1 cm, at most 1000 hypotheses, coefficients refitted to the inliers (as lidarshop does).
  {
    const auto start = std::chrono::steady_clock::now();
    pcl::SACSegmentation<pcl::PointXYZ> segmentation;
    segmentation.setInputCloud(cloud);
    segmentation.setModelType(pcl::SACMODEL_PLANE);
    segmentation.setMethodType(pcl::SAC_RANSAC);
    segmentation.setDistanceThreshold(0.01);
    segmentation.setMaxIterations(1000);
    segmentation.setOptimizeCoefficients(true);
    pcl::PointIndices inliers;
    pcl::ModelCoefficients plane;
    segmentation.segment(inliers, plane);
    json += ", \"plane_s\": " + std::to_string(SecondsSince(start)) +
            ", \"plane_inliers\": " + std::to_string(inliers.indices.size()) + ", \"plane\": [";
    for (size_t k = 0; k < plane.values.size(); ++k)
      json += (k ? ", " : "") + std::to_string(plane.values[k]);
    json += "]";
    WriteArray(work + "/pcl_plane.i32", std::vector<int32_t>(inliers.indices.begin(), inliers.indices.end()));
  }
  // Euclidean clustering, 10 cm, clusters of any size (PCL's minimum cluster size is 1 here, as lidarshop's).
  {
    const auto start = std::chrono::steady_clock::now();
    pcl::search::KdTree<pcl::PointXYZ>::Ptr tree(new pcl::search::KdTree<pcl::PointXYZ>);
    tree->setInputCloud(cloud);
    pcl::EuclideanClusterExtraction<pcl::PointXYZ> extraction;
    extraction.setClusterTolerance(0.1);
    extraction.setMinClusterSize(1);
    extraction.setMaxClusterSize(static_cast<int>(cloud->size()));
    extraction.setSearchMethod(tree);
    extraction.setInputCloud(cloud);
    std::vector<pcl::PointIndices> clusters;
    extraction.extract(clusters);
    size_t largest = 0;
    for (const pcl::PointIndices& c : clusters) largest = std::max(largest, c.indices.size());
    json += ", \"cluster_s\": " + std::to_string(SecondsSince(start)) +
            ", \"clusters\": " + std::to_string(clusters.size()) +
            ", \"largest_cluster\": " + std::to_string(largest);
  }
  // Voxel grid, 5 cm, one centroid per occupied voxel.
  {
    const auto start = std::chrono::steady_clock::now();
    pcl::VoxelGrid<pcl::PointXYZ> grid;
    grid.setInputCloud(cloud);
    grid.setLeafSize(0.05f, 0.05f, 0.05f);
    pcl::PointCloud<pcl::PointXYZ> down;
    grid.filter(down);
    json += ", \"voxel_s\": " + std::to_string(SecondsSince(start)) +
            ", \"voxels\": " + std::to_string(down.size());
  }
  // Poisson (Kazhdan's reconstruction as PCL ships it), depth 8, on the oriented points given.
  if (argc > 3) {
    const std::vector<float> values = ReadFloats(argv[3]);
    pcl::PointCloud<pcl::PointNormal>::Ptr oriented(new pcl::PointCloud<pcl::PointNormal>);
    oriented->resize(values.size() / 6);
    for (size_t i = 0; i < oriented->size(); ++i) {
      pcl::PointNormal& p = (*oriented)[i];
      p.x = values[6 * i];
      p.y = values[6 * i + 1];
      p.z = values[6 * i + 2];
      p.normal_x = values[6 * i + 3];
      p.normal_y = values[6 * i + 4];
      p.normal_z = values[6 * i + 5];
    }
    const auto start = std::chrono::steady_clock::now();
    pcl::Poisson<pcl::PointNormal> poisson;
    poisson.setDepth(8);
    poisson.setThreads(2);
    poisson.setInputCloud(oriented);
    pcl::PolygonMesh mesh;
    poisson.reconstruct(mesh);
    json += ", \"poisson_s\": " + std::to_string(SecondsSince(start)) +
            ", \"poisson_vertices\": " + std::to_string(mesh.cloud.width * mesh.cloud.height) +
            ", \"poisson_triangles\": " + std::to_string(mesh.polygons.size());
    pcl::PointCloud<pcl::PointXYZ> vertices;
    pcl::fromPCLPointCloud2(mesh.cloud, vertices);
    std::vector<float> out;
    for (const pcl::PointXYZ& p : vertices) out.insert(out.end(), {p.x, p.y, p.z});
    WriteArray(work + "/pcl_poisson_vertices.f32", out);
  }
  std::cout << json << "}\n";
  return 0;
}
