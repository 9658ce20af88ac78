#include "focal/mesh.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace focal {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

/// Two triangles of the unit square (0,0) (1,0) (1,1) (0,1) and a fifth vertex in no face.
struct Square {
  RowMatrixX3d V;
  RowMatrixX3i F;
  Square() : V(5, 3), F(2, 3) {
    V << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 3, 3, 3;
    F << 0, 1, 2, 0, 2, 3;
  }
};

TEST(MeanEdgeLength, CountsEachEdgeOncePerFace) {
  const Square s;
  EXPECT_DOUBLE_EQ(mean_edge_length(s.V, s.F), (4.0 + 2.0 * std::sqrt(2.0)) / 6.0);
  EXPECT_EQ(mean_edge_length(s.V, RowMatrixX3i(0, 3)), 0.0);
}

TEST(MeanEdgeLength, NonFiniteEdgesAreLeftOut) {
  // Vertex 3 broken: edges 2-3 and 3-0 drop out; 0-1, 1-2 (1 each), 2-0, 0-2 (sqrt 2) remain.
  for (const double bad : {kNaN, kInf}) {
    Square s;
    s.V(3, 0) = bad;
    EXPECT_DOUBLE_EQ(mean_edge_length(s.V, s.F), (2.0 + 2.0 * std::sqrt(2.0)) / 4.0);
  }
  Square all;
  all.V.topRows(4).setConstant(kNaN);
  EXPECT_EQ(mean_edge_length(all.V, all.F), 0.0);
}

TEST(BoundingBoxDiagonal, NonFiniteRowsAreLeftOut) {
  Square s;
  EXPECT_DOUBLE_EQ(bounding_box_diagonal(s.V), std::sqrt(27.0));
  s.V(4, 2) = kNaN;  // the far vertex no longer counts: the unit square remains
  EXPECT_DOUBLE_EQ(bounding_box_diagonal(s.V), std::sqrt(2.0));
  s.V(1, 0) = -kInf;
  EXPECT_DOUBLE_EQ(bounding_box_diagonal(s.V), std::sqrt(2.0));
  s.V.setConstant(kNaN);
  EXPECT_EQ(bounding_box_diagonal(s.V), 0.0);
  EXPECT_EQ(bounding_box_diagonal(RowMatrixX3d(0, 3)), 0.0);
}

}  // namespace
}  // namespace focal
