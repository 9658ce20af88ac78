// The text clouds of the point-cloud peers (cgal_peer, pcl_peer): one point per line,
// `x y z [nx ny nz]`; lines with fewer than three numbers are skipped.
#pragma once

#include <array>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

struct XyzRows {
  std::vector<std::array<double, 6>> rows;  ///< x y z nx ny nz (normal 0 where none)
  bool has_normals = false;                 ///< the last row read had six numbers
};

inline XyzRows read_xyz_rows(const char* path) {
  XyzRows out;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) {
    std::istringstream s(line);
    std::array<double, 6> v{};
    int n = 0;
    while (n < 6 && s >> v[static_cast<std::size_t>(n)]) ++n;
    if (n < 3) continue;
    if (n < 6) v[3] = v[4] = v[5] = 0.0;
    out.has_normals = n == 6;
    out.rows.push_back(v);
  }
  return out;
}
