#include "focal/core/mesh.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <string>

#include "focal/core/error.h"
#include "test_threads.h"

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

TEST(MeanEdgeLength, IsTheSameForAnyThreadCount) {
  // 100000 faces: several blocks of the parallel sum, one vertex broken.
  const Eigen::Index nv = 30000;
  const Eigen::Index nf = 100000;
  RowMatrixX3d V = RowMatrixX3d::Random(nv, 3);
  V(17, 1) = kNaN;
  RowMatrixX3i F(nf, 3);
  for (Eigen::Index f = 0; f < nf; ++f) {
    for (int c = 0; c < 3; ++c) F(f, c) = static_cast<std::int32_t>((f * 7919 + c * 104729) % nv);
  }
  long double sum = 0.0L;
  std::int64_t count = 0;
  for (Eigen::Index f = 0; f < nf; ++f) {
    for (int c = 0; c < 3; ++c) {
      const double length = (V.row(F(f, c)) - V.row(F(f, (c + 1) % 3))).norm();
      if (std::isfinite(length)) {
        sum += length;
        ++count;
      }
    }
  }
  const auto expected = static_cast<double>(sum / static_cast<long double>(count));
  const char* env = std::getenv("FOCAL_NUM_THREADS");
  const std::string saved = env != nullptr ? env : "";
  double first = 0.0;
  for (const int threads : {1, 2, 3}) {
    const double mean = test::on_threads(threads, [&] { return mean_edge_length(V, F); });
    EXPECT_NEAR(mean, expected, 1e-12 * expected) << threads;
    if (threads == 1) first = mean;
    EXPECT_EQ(mean, first) << threads;  // bit for bit
    // No scope: FOCAL_NUM_THREADS.
    setenv("FOCAL_NUM_THREADS", std::to_string(threads).c_str(), 1);
    EXPECT_EQ(mean_edge_length(V, F), first) << threads;
  }
  if (saved.empty()) {
    unsetenv("FOCAL_NUM_THREADS");
  } else {
    setenv("FOCAL_NUM_THREADS", saved.c_str(), 1);
  }
}

TEST(ValidateMeshArrays, NamesTheFirstBadFaceForAnyThreadCount) {
  // Bad faces in two parallel blocks: the message names the first in face order.
  const RowMatrixX3d V = RowMatrixX3d::Zero(10, 3);
  RowMatrixX3i F = RowMatrixX3i::Zero(100000, 3);
  F(90000, 0) = -1;
  F(70000, 2) = 10;
  const char* env = std::getenv("FOCAL_NUM_THREADS");
  const std::string saved = env != nullptr ? env : "";
  for (const int threads : {1, 2, 3}) {
    try {
      test::on_threads(threads, [&] { validate_mesh_arrays(V, F, RowMatrixX3d(0, 3), "test"); });
      ADD_FAILURE() << "no exception";
    } catch (const InvalidInput& e) {
      EXPECT_STREQ(e.what(), "test: face 70000 refers to vertex 10, but there are 10 vertices");
    }
    // No scope: FOCAL_NUM_THREADS.
    setenv("FOCAL_NUM_THREADS", std::to_string(threads).c_str(), 1);
    EXPECT_THROW(validate_mesh_arrays(V, F, RowMatrixX3d(0, 3), "test"), InvalidInput);
  }
  F(70000, 2) = 9;
  F(90000, 0) = 9;
  EXPECT_NO_THROW(validate_mesh_arrays(V, F, RowMatrixX3d(0, 3), "test"));
  if (saved.empty()) {
    unsetenv("FOCAL_NUM_THREADS");
  } else {
    setenv("FOCAL_NUM_THREADS", saved.c_str(), 1);
  }
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
