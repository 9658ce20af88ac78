// The winding-number tree (points/winding_number.h) and the global orientation on it
// (normals/winding_orientation.h, CloudOrientation::global) on thin closed solids.

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <random>
#include <string>

#include "focal/core/error.h"
#include "focal/io/mesh_io.h"
#include "focal/normals/cloud_normals.h"
#include "focal/points/neighbours.h"
#include "normals/cloud_jets.h"
#include "normals/winding_orientation.h"
#include "points/winding_number.h"
#include "test_threads.h"
#include "thin_solids.h"

namespace focal {
namespace {

test::Solid sphere_cloud(double r, std::uint64_t seed) {
  test::SolidBuilder b(seed);
  b.sphere(Eigen::Vector3d::Zero(), r);
  return b.take();
}

/// Dipoles a n of a sphere sample, its area shared equally.
RowMatrixX3d sphere_dipoles(const test::Solid& s, double r) {
  return s.N * (4.0 * std::numbers::pi * r * r / static_cast<double>(s.V.rows()));
}

// At the samples of a closed surface with outward normals the winding number is 1/2 (Gauss's
// theorem for the double layer), less what the sampling leaves out: each point's own patch
// (radius 0.56 on a sphere of radius 10 sampled at 1 point per unit area: about 0.03) and the
// smoothing's share of the nearest terms. Measured (seed 1): mean 0.455, every point within
// 0.061 of 1/2; inward normals the same with the sign turned.
TEST(WindingTree, HalfOnTheSamplesOfASphere) {
  const test::Solid s = sphere_cloud(10.0, 1);
  const detail::WindingTree tree(s.V, Eigen::VectorXd::Constant(s.V.rows(), 0.5), 2.0);
  const Eigen::VectorXd w = tree.winding(sphere_dipoles(s, 10.0), {}, 0);
  EXPECT_NEAR(w.mean(), 0.455, 0.01);
  EXPECT_LT((w.array() - 0.5).abs().maxCoeff(), 0.08);
  const RowMatrixX3d inward = -sphere_dipoles(s, 10.0);
  EXPECT_NEAR(tree.winding(inward, {}, 0).mean(), -0.455, 0.01);
}

// The far field to second order against every pair summed (beta so large that no cell is far):
// measured at beta = 2, the largest error of w 0.035 (of the 1/2 the orientation reads) and of
// the field 9% of its largest value; asserted with margin.
TEST(WindingTree, FarFieldAgreesWithTheDirectSum) {
  const test::Solid s = sphere_cloud(10.0, 2);
  const Eigen::VectorXd smoothing = Eigen::VectorXd::Constant(s.V.rows(), 0.5);
  const detail::WindingTree fast(s.V, smoothing, 2.0), exact(s.V, smoothing, 1e9);
  const RowMatrixX3d M = sphere_dipoles(s, 10.0);
  EXPECT_LT((fast.winding(M, {}, 0) - exact.winding(M, {}, 0)).cwiseAbs().maxCoeff(), 0.05);
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd q(s.V.rows());
  for (Eigen::Index i = 0; i < q.size(); ++i) q[i] = u(rng);
  const RowMatrixX3d gf = fast.field(q, 0), ge = exact.field(q, 0);
  EXPECT_LT((gf - ge).cwiseAbs().maxCoeff(), 0.12 * ge.cwiseAbs().maxCoeff());
  // The field is the transpose: q . K s = (K^T q) . s, exactly for the direct sums.
  const Eigen::VectorXd Ks = exact.winding(M, {}, 0);
  const double left = q.dot(Ks), right = (M.array() * ge.array()).sum();
  EXPECT_NEAR(left, right, 1e-10 * std::abs(left));
}

TEST(WindingTree, SameBitsForAnyThreadCount) {
  const test::Solid s = sphere_cloud(20.0, 3);  // 5000 points: parallel loops
  const detail::WindingTree tree(s.V, Eigen::VectorXd::Constant(s.V.rows(), 0.5), 2.0);
  const RowMatrixX3d M = sphere_dipoles(s, 20.0);
  const Eigen::VectorXd q = M.col(0);
  const Eigen::VectorXd w1 = test::on_threads(1, [&] { return tree.winding(M, {}, 0); });
  const Eigen::VectorXd w2 = test::on_threads(2, [&] { return tree.winding(M, {}, 0); });
  EXPECT_EQ(w1, w2);
  const RowMatrixX3d g1 = test::on_threads(1, [&] { return tree.field(q, 0); });
  const RowMatrixX3d g2 = test::on_threads(2, [&] { return tree.field(q, 0); });
  EXPECT_EQ(g1, g2);
}

TEST(WindingTree, RejectsBadSettings) {
  const test::Solid s = sphere_cloud(3.0, 1);
  EXPECT_THROW(detail::WindingTree(s.V, Eigen::VectorXd::Zero(3), 2.0), InvalidInput);
  EXPECT_THROW(detail::WindingTree(s.V, Eigen::VectorXd::Zero(s.V.rows()), 1.0), InvalidInput);
}

enum class Shape { plate, thick_plate, coin, ring, touching_spheres };

const char* shape_name(Shape s) {
  switch (s) {
    case Shape::plate:
      return "plate 40x40x2";
    case Shape::thick_plate:
      return "plate 40x40x6";
    case Shape::coin:
      return "coin R15 t2";
    case Shape::ring:
      return "ring R12 r1";
    case Shape::touching_spheres:
      return "touching spheres r8";
  }
  return "";
}

test::Solid solid(Shape shape, std::uint64_t seed, double noise) {
  test::SolidBuilder b(seed);
  switch (shape) {
    case Shape::plate:
      b.box({40, 40, 2});
      break;
    case Shape::thick_plate:
      b.box({40, 40, 6});
      break;
    case Shape::coin:
      b.coin(15, 2);
      break;
    case Shape::ring:
      b.ring(12, 1);
      break;
    case Shape::touching_spheres:
      b.sphere({-8, 0, 0}, 8);
      b.sphere({8, 0, 0}, 8);
      break;
  }
  return b.take(noise);
}

int flipped(const test::Solid& s, CloudOrientation orientation) {
  const RowMatrixX3d N =
      cloud_normals(s.V, nearest_neighbours(s.V, 16), {.orientation = orientation});
  return test::flipped_against(N, s.N);
}

// The two small cases, clean and with noise of 0.1 spacing, seeds 1-3: the tree alone turns a
// whole side (plate: 1729-1845 of 3520 points flipped; spheres: one sphere, 800-802 of 1600);
// the global orientation leaves 10-19 (0.3-0.5%) and 11-19 (0.7-1.2%, where the spheres are
// within a fraction of a spacing of each other) flipped, NaN counted (docs/notes/points-log.md,
// "Global orientation"). Asserted: the 1% on the plate, 1.5% on the spheres (whose 1% is
// not reached on every seed), and the tree's failure itself (at least 45%), so that the case
// stays a hard one.
TEST(GlobalOrientation, ThinPlateAndTouchingSpheres) {
  for (const Shape shape : {Shape::plate, Shape::touching_spheres}) {
    for (std::uint64_t seed : {1, 2, 3}) {
      for (const double noise : {0.0, 0.1}) {
        const test::Solid s = solid(shape, seed, noise);
        const auto n = static_cast<int>(s.V.rows());
        EXPECT_GE(flipped(s, CloudOrientation::mst), n * 45 / 100)
            << shape_name(shape) << " seed " << seed << " noise " << noise;
        const int limit = shape == Shape::plate ? n / 100 : n * 3 / 200;
        EXPECT_LE(flipped(s, CloudOrientation::global), limit)
            << shape_name(shape) << " seed " << seed << " noise " << noise;
      }
    }
  }
}

// A closed surface that the tree orients right stays right (the sphere, the clean plate six
// spacings thick: measured 0 flipped either way; with noise 0.1 the thick plate has 0-2 with
// the tree and 1-2 with the global orientation).
TEST(GlobalOrientation, ThickSolidsStayRight) {
  for (std::uint64_t seed : {1, 2}) {
    const test::Solid plate = solid(Shape::thick_plate, seed, 0.0);
    EXPECT_EQ(flipped(plate, CloudOrientation::global), 0) << "seed " << seed;
    const test::Solid ball = sphere_cloud(15.0, seed);
    EXPECT_EQ(flipped(ball, CloudOrientation::global), 0) << "seed " << seed;
  }
}

TEST(GlobalOrientation, SameBitsForAnyThreadCount) {
  const test::Solid s = solid(Shape::plate, 4, 0.1);
  const Neighbourhoods nb = nearest_neighbours(s.V, 16);
  const auto run = [&] {
    return cloud_normals(s.V, nb, {.orientation = CloudOrientation::global});
  };
  EXPECT_EQ(test::on_threads(1, run), test::on_threads(2, run));
}

// The plan's global orientation after a fit from the tree's signs (orient_jets_globally) gives
// the jets of the global orientation itself, bit for bit, for jets and PCA normals.
TEST(GlobalOrientation, AfterTheTreeAsDirect) {
  for (const CloudNormalMethod method : {CloudNormalMethod::jet, CloudNormalMethod::pca}) {
    for (const Shape shape : {Shape::plate, Shape::touching_spheres, Shape::thick_plate}) {
      const test::Solid s = solid(shape, 2, 0.1);
      const Neighbourhoods nb = nearest_neighbours(s.V, 16);
      const CloudNormalOptions global{.method = method, .orientation = CloudOrientation::global};
      CloudNormalOptions tree = global;
      tree.orientation = CloudOrientation::mst;
      RowMatrixX3d start;
      JetNormals jets = detail::cloud_jets(s.V, nb, tree, nullptr, &start);
      detail::orient_jets_globally(s.V, nb, global, std::move(start), jets);
      const JetNormals direct = detail::cloud_jets(s.V, nb, global);
      EXPECT_EQ(jets.N, direct.N) << shape_name(shape);
      EXPECT_EQ(jets.residual, direct.residual) << shape_name(shape);
    }
  }
}

TEST(GlobalOrientation, RejectsConflictingOptions) {
  const test::Solid s = solid(Shape::plate, 1, 0.0);
  const Neighbourhoods nb = nearest_neighbours(s.V, 8);
  EXPECT_THROW((void)cloud_normals(s.V, nb, {.orientation = CloudOrientation::viewpoint}),
               InvalidInput);
  EXPECT_THROW((void)cloud_normals(s.V, nb,
                                   {.viewpoint = Eigen::Vector3d(0, 0, 50),
                                    .orientation = CloudOrientation::global}),
               InvalidInput);
  RowMatrixX3d N(3, 3);
  EXPECT_THROW((void)orient_normals_global(s.V, nb, N), InvalidInput);
}

// The lab table (docs/notes/points-log.md, "Global orientation"): run with
// --gtest_also_run_disabled_tests --gtest_filter='*Table*'.
TEST(GlobalOrientation, DISABLED_Table) {
  for (const Shape shape :
       {Shape::plate, Shape::thick_plate, Shape::coin, Shape::ring, Shape::touching_spheres}) {
    for (const double noise : {0.0, 0.1}) {
      for (std::uint64_t seed : {1, 2, 3}) {
        const test::Solid s = solid(shape, seed, noise);
        const auto t0 = std::chrono::steady_clock::now();
        const int mst = flipped(s, CloudOrientation::mst);
        const auto t1 = std::chrono::steady_clock::now();
        const int global = flipped(s, CloudOrientation::global);
        const auto t2 = std::chrono::steady_clock::now();
        std::printf("%-22s noise %.1f seed %d  points %6d  mst %5d  global %5d  (%.2f s, %.2f s)\n",
                    shape_name(shape), noise, static_cast<int>(seed), static_cast<int>(s.V.rows()),
                    mst, global, std::chrono::duration<double>(t1 - t0).count(),
                    std::chrono::duration<double>(t2 - t1).count());
      }
    }
  }
}

// The thicknesses of the cases (docs/notes/points-log.md, "Global orientation"): plates
// 40 x 40, coins of radius 15 and rings of major radius 12, t = 2, 3, 5, 7 spacings thick (the
// ring's tube t / 2 in radius), clean and with noise of 0.1 spacing, seeds 1-3.
TEST(GlobalOrientation, DISABLED_Thickness) {
  const char* names[] = {"plate", "coin", "ring"};
  for (int kind = 0; kind < 3; ++kind) {
    for (const double t : {2.0, 3.0, 5.0, 7.0}) {
      for (const double noise : {0.0, 0.1}) {
        for (std::uint64_t seed : {1, 2, 3}) {
          test::SolidBuilder b(seed);
          if (kind == 0) b.box({40, 40, t});
          if (kind == 1) b.coin(15, t);
          if (kind == 2) b.ring(12, 0.5 * t);
          const test::Solid s = b.take(noise);
          std::printf("%-5s t %.0f noise %.1f seed %d  points %6d  mst %5d  global %5d\n",
                      names[kind], t, noise, static_cast<int>(seed), static_cast<int>(s.V.rows()),
                      flipped(s, CloudOrientation::mst), flipped(s, CloudOrientation::global));
        }
      }
    }
  }
}

double env(const char* name, double otherwise) {
  const char* v = std::getenv(name);
  return v ? std::atof(v) : otherwise;
}

// Settings explored by hand (FOCAL_WO_* variables): the residual of the truth's signs, of the
// tree's, and of the signs taken, and the flipped counts.
TEST(GlobalOrientation, DISABLED_Explore) {
  detail::WindingOrientationOptions o;
  o.damping = env("FOCAL_WO_DAMPING", o.damping);
  o.iterations = static_cast<int>(env("FOCAL_WO_ITERATIONS", o.iterations));
  o.rounds = static_cast<int>(env("FOCAL_WO_ROUNDS", o.rounds));
  o.sweeps = static_cast<int>(env("FOCAL_WO_SWEEPS", o.sweeps));
  o.smoothing = env("FOCAL_WO_SMOOTHING", o.smoothing);
  o.beta = env("FOCAL_WO_BETA", o.beta);
  o.jump_offset = env("FOCAL_WO_JUMP_OFFSET", o.jump_offset);
  o.jump_rounds = static_cast<int>(env("FOCAL_WO_JUMP_ROUNDS", o.jump_rounds));
  const int k = static_cast<int>(env("FOCAL_WO_K", 16));
  const int only = static_cast<int>(env("FOCAL_WO_SHAPE", -1));
  for (const Shape shape :
       {Shape::plate, Shape::thick_plate, Shape::coin, Shape::ring, Shape::touching_spheres}) {
    if (only >= 0 && static_cast<int>(shape) != only) continue;
    for (const double noise : {0.0, 0.1}) {
      for (std::uint64_t seed : {1, 2, 3}) {
        const test::Solid s = solid(shape, seed, noise);
        const Neighbourhoods nb = nearest_neighbours(s.V, k);
        RowMatrixX3d N = pca_normals(s.V, nb);
        RowMatrixX3d T = N;
        for (Eigen::Index i = 0; i < N.rows(); ++i) {
          if (T.row(i).dot(s.N.row(i)) < 0.0) T.row(i) *= -1.0;
        }
        orient_normals_mst(s.V, nb, N);
        const int mst = test::flipped_against(N, s.N);
        const Eigen::VectorXd area = detail::patch_areas(s.V, nb, N, 0);
        detail::WindingOrientationOptions zero = o;
        zero.iterations = 0;
        zero.damping = 1e300;
        const double truth =
            detail::orient_by_winding(s.V, nb, nullptr, area, T, 0, zero).residual_before;
        const auto r = detail::orient_by_winding(s.V, nb, nullptr, area, N, 0, o);
        int bad_lines = 0, good_flipped = 0;
        for (Eigen::Index i = 0; i < N.rows(); ++i) {
          const double c = N.row(i).dot(s.N.row(i));
          if (std::abs(c) < 0.5)
            ++bad_lines;
          else if (c < 0.0)
            ++good_flipped;
        }
        std::printf("lines %s %d %d: %d of %d off by > 60 deg; flipped among the rest %d\n",
                    shape_name(shape), static_cast<int>(noise * 10), static_cast<int>(seed),
                    bad_lines, static_cast<int>(N.rows()), good_flipped);
        std::printf(
            "%-22s noise %.1f seed %d mst %5d global %5d residual truth %.3f mst %.3f "
            "global %.3f jumps %d\n",
            shape_name(shape), noise, static_cast<int>(seed), mst, test::flipped_against(N, s.N),
            truth, r.residual_before, r.residual_after, r.jump_turned);
      }
    }
  }
}

}  // namespace
}  // namespace focal
namespace focal {
namespace {
// Timings (docs/POINTS.md): a sphere of about FOCAL_WO_POINTS points, oriented globally.
TEST(GlobalOrientation, DISABLED_Speed) {
  const double points = env("FOCAL_WO_POINTS", 1e5);
  test::SolidBuilder b(1);
  b.sphere(Eigen::Vector3d::Zero(), std::sqrt(points / (4.0 * std::numbers::pi)));
  const test::Solid s = b.take(0.1);
  const Neighbourhoods nb = nearest_neighbours(s.V, 16);
  RowMatrixX3d N = pca_normals(s.V, nb);
  auto t0 = std::chrono::steady_clock::now();
  orient_normals_mst(s.V, nb, N);
  auto t1 = std::chrono::steady_clock::now();
  detail::WindingOrientationOptions o;
  o.beta = env("FOCAL_WO_BETA", o.beta);
  o.iterations = static_cast<int>(env("FOCAL_WO_ITERATIONS", o.iterations));
  const int turned =
      detail::orient_by_winding(s.V, nb, nullptr, detail::patch_areas(s.V, nb, N, 0), N, 0, o)
          .flipped;
  auto t2 = std::chrono::steady_clock::now();
  std::printf("speed %d points: mst %.2f s, global %.2f s, turned %d, flipped %d\n",
              static_cast<int>(s.V.rows()), std::chrono::duration<double>(t1 - t0).count(),
              std::chrono::duration<double>(t2 - t1).count(), turned,
              test::flipped_against(N, s.N));
}
}  // namespace
}  // namespace focal
namespace focal {
namespace {
// A WNNC-like iteration for comparison (Lin et al. 2024: normals <- -normalised gradient of the
// smoothed winding number, annealed width), by direct sums on the small cases: the PCA lines
// take the sign of the iterate. FOCAL_WO_SEED=1 starts from the tree's normals, else from
// the PCA lines' arbitrary signs.
TEST(GlobalOrientation, DISABLED_Wnnc) {
  const int iterations = static_cast<int>(env("FOCAL_WO_ITERATIONS", 40));
  const bool seeded = env("FOCAL_WO_SEED", 1) > 0;
  for (const Shape shape :
       {Shape::plate, Shape::thick_plate, Shape::coin, Shape::ring, Shape::touching_spheres}) {
    for (std::uint64_t seed : {1, 2}) {
      const test::Solid s = solid(shape, seed, 0.0);
      const Neighbourhoods nb = nearest_neighbours(s.V, 16);
      const RowMatrixX3d pca = pca_normals(s.V, nb);
      RowMatrixX3d N = pca;
      if (seeded) orient_normals_mst(s.V, nb, N);
      const Eigen::VectorXd a = detail::patch_areas(s.V, nb, N, 0);
      const Eigen::Index n = s.V.rows();
      for (int it = 0; it < iterations; ++it) {
        // width from 4 spacings down to 0.5, geometrically
        const double t = iterations > 1 ? static_cast<double>(it) / (iterations - 1) : 1.0;
        const double sigma = 4.0 * std::pow(0.125, t);
        RowMatrixX3d G(n, 3);
        for (Eigen::Index i = 0; i < n; ++i) {
          Eigen::Vector3d g = Eigen::Vector3d::Zero();
          for (Eigen::Index j = 0; j < n; ++j) {
            if (j == i) continue;
            const Eigen::Vector3d r = (s.V.row(j) - s.V.row(i)).transpose();
            const Eigen::Vector3d m = a[j] * N.row(j).transpose();
            const double rho2 = r.squaredNorm() + sigma * sigma;
            const double inv3 = 1.0 / (rho2 * std::sqrt(rho2));
            g += -m * inv3 + 3.0 * m.dot(r) * r * inv3 / rho2;
          }
          G.row(i) = g.transpose();
        }
        for (Eigen::Index i = 0; i < n; ++i) {
          const double norm = G.row(i).norm();
          if (norm > 0.0) N.row(i) = -G.row(i) / norm;
        }
      }
      RowMatrixX3d signed_lines = pca;
      for (Eigen::Index i = 0; i < n; ++i) {
        if (signed_lines.row(i).dot(N.row(i)) < 0.0) signed_lines.row(i) *= -1.0;
      }
      std::printf("wnnc %-22s seed %d: flipped %d of %d\n", shape_name(shape),
                  static_cast<int>(seed), test::flipped_against(signed_lines, s.N),
                  static_cast<int>(n));
    }
  }
}

// What a cloud's flipped count needs (docs/notes/points-log.md, "What the remaining counts
// need"): on the cloud FOCAL_WO_CLOUD (a file with normals, e.g. CGAL's oni.pwn), the global
// orientation from the file's own lines with random signs and from PCA's, with the field's
// verdict and forced through it; then the winding number of the file's oriented points at each
// sample (direct sums) against the points the forced orientation from the file's lines gets
// wrong.
TEST(GlobalOrientation, DISABLED_WhatTheCountsNeed) {
  const char* path = std::getenv("FOCAL_WO_CLOUD");
  ASSERT_NE(path, nullptr) << "set FOCAL_WO_CLOUD to a cloud with normals";
  const Mesh m = read_mesh(path);
  RowMatrixX3d truth = m.N;
  truth.rowwise().normalize();
  std::mt19937_64 rng(1);
  RowMatrixX3d random_signs = truth;
  for (Eigen::Index i = 0; i < truth.rows(); ++i) {
    if ((rng() & 1U) != 0) random_signs.row(i) *= -1.0;
  }
  const auto orient = [&](const Neighbourhoods& nb, RowMatrixX3d N, bool force) {
    orient_normals_mst(m.V, nb, N);
    const int mst = test::flipped_against(N, truth);
    detail::WindingOrientationOptions o;
    if (force) o.closed_residual = o.closed_gain = 10.0;
    const auto r =
        detail::orient_by_winding(m.V, nb, nullptr, detail::patch_areas(m.V, nb, N, 0), N, 0, o);
    std::printf("  mst %5d  global %5d  decided %d  residual %.3f -> %.3f\n", mst,
                test::flipped_against(N, truth), static_cast<int>(r.decided), r.residual_before,
                r.residual_after);
    return N;
  };
  for (const int k : {8, 12, 16, 24}) {
    const Neighbourhoods nb = nearest_neighbours(m.V, k);
    const RowMatrixX3d pca = pca_normals(m.V, nb);
    int off = 0;
    for (Eigen::Index i = 0; i < pca.rows(); ++i)
      off += !(std::abs(pca.row(i).dot(truth.row(i))) >= 0.5);
    for (const bool force : {false, true}) {
      std::printf("k %d, the file's lines%s:\n", k, force ? ", forced" : "");
      orient(nb, random_signs, force);
      std::printf("k %d, PCA's lines (%d more than 60 deg off)%s:\n", k, off,
                  force ? ", forced" : "");
      orient(nb, pca, force);
    }
  }
  const Neighbourhoods nb = nearest_neighbours(m.V, 16);
  const Eigen::VectorXd area = detail::patch_areas(m.V, nb, truth, 0);
  const detail::WindingTree direct(m.V, 0.5 * area.cwiseSqrt(), 1e9);
  const Eigen::VectorXd w =
      direct.winding(truth.array().colwise() * area.array(), Eigen::VectorXd::Ones(m.V.rows()), 0);
  std::printf("the file's lines, k 16, forced:\n");
  const RowMatrixX3d N = orient(nb, random_signs, true);
  const double bands[] = {-INFINITY, 0.3, 0.7, 1.1, INFINITY};
  for (int b = 0; b < 4; ++b) {
    int right = 0, wrong = 0;
    for (Eigen::Index i = 0; i < w.size(); ++i) {
      if (!(w[i] >= bands[b] && w[i] < bands[b + 1])) continue;
      (N.row(i).dot(truth.row(i)) > 0.0 ? right : wrong) += 1;
    }
    std::printf("  the file's w in [%.1f, %.1f): right %5d wrong %5d\n", bands[b], bands[b + 1],
                right, wrong);
  }
}

}  // namespace
}  // namespace focal
