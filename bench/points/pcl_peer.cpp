// PCL 1.13 (Debian libpcl-dev) as a peer of focal's cloud curvature: pcl::NormalEstimation (k
// nearest, when the cloud has no normals; oriented towards the centroid's far side is not
// available, so PCL's default viewpoint (0, 0, 0) orients them) and
// pcl::PrincipalCurvaturesEstimation (k nearest).
//
// Sign convention: PCL's pc1 >= pc2 are eigenvalues of the covariance of the neighbours' normals
// projected on the tangent plane: never negative, whatever the surface bends to, and not in
// 1/length units. They are written as they are (k1 = pc1, k2 = pc2, H = (pc1 + pc2) / 2).
//
// Usage: pcl_peer IN.xyz K OUT.csv   (IN: x y z [nx ny nz] per line). Writes k1,k2,H per point
// and prints "normals_s fit_s" (wall seconds) on stdout.

#include <pcl/features/normal_3d.h>
#include <pcl/features/principal_curvatures.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "xyz_rows.h"

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: pcl_peer IN.xyz K OUT.csv\n");
    return 1;
  }
  const int k = std::atoi(argv[2]);
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  pcl::PointCloud<pcl::Normal>::Ptr normals(new pcl::PointCloud<pcl::Normal>);
  const XyzRows input = read_xyz_rows(argv[1]);
  const bool has_normals = input.has_normals;
  for (const auto& v : input.rows) {
    cloud->push_back(pcl::PointXYZ(static_cast<float>(v[0]), static_cast<float>(v[1]),
                                   static_cast<float>(v[2])));
    if (has_normals) {
      normals->push_back(pcl::Normal(static_cast<float>(v[3]), static_cast<float>(v[4]),
                                     static_cast<float>(v[5])));
    }
  }
  pcl::search::KdTree<pcl::PointXYZ>::Ptr tree(new pcl::search::KdTree<pcl::PointXYZ>);
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  if (!has_normals) {
    pcl::NormalEstimation<pcl::PointXYZ, pcl::Normal> estimate;
    estimate.setInputCloud(cloud);
    estimate.setSearchMethod(tree);
    estimate.setKSearch(k);
    estimate.compute(*normals);
  }
  const auto t1 = Clock::now();
  pcl::PrincipalCurvaturesEstimation<pcl::PointXYZ, pcl::Normal, pcl::PrincipalCurvatures> pc;
  pc.setInputCloud(cloud);
  pc.setInputNormals(normals);
  pc.setSearchMethod(tree);
  pc.setKSearch(k);
  pcl::PointCloud<pcl::PrincipalCurvatures> curvatures;
  pc.compute(curvatures);
  const auto t2 = Clock::now();
  std::ofstream out(argv[3]);
  out << "k1,k2,H\n";
  out.precision(9);
  for (const auto& c : curvatures)
    out << c.pc1 << ',' << c.pc2 << ',' << 0.5 * (c.pc1 + c.pc2) << '\n';
  std::printf("%.4f %.4f\n", std::chrono::duration<double>(t1 - t0).count(),
              std::chrono::duration<double>(t2 - t1).count());
  return 0;
}
