#pragma once
// The per-pixel steps of the image-space estimator (paper section 5.1) in plain data, shared by
// the CPU reference (image_space.cpp) and the CUDA kernels (src/cuda/image_space.cu): one call
// per pixel, reading only the G-buffer (and, for the window, the first pass's operators), writing
// only the pixel's own output slot, so any thread count or launch shape gives the same result.

#include <cstdint>

#include "kernels/local_shape.h"
#include "kernels/triplet.h"
#include "kernels/vec3.h"

namespace focal::image_kernel {

using kernels::Vec3;

/// A G-buffer in place (see focal::GBuffer): row-major, pixel (x, y) at y * width + x.
struct ImageView {
  int width = 0, height = 0;
  const float* position = nullptr;     ///< 3 per pixel
  const float* normal = nullptr;       ///< 3 per pixel, any length
  const std::uint8_t* mask = nullptr;  ///< non-zero where covered
};

FOCAL_HD inline int pixel_index(const ImageView& v, int x, int y) { return y * v.width + x; }

FOCAL_HD inline bool covered(const ImageView& v, int x, int y) {
  return x >= 0 && y >= 0 && x < v.width && y < v.height && v.mask[pixel_index(v, x, y)] != 0;
}

FOCAL_HD inline Vec3<float> position_at(const ImageView& v, int x, int y) {
  return kernels::load3(v.position + 3 * pixel_index(v, x, y));
}

FOCAL_HD inline Vec3<float> normal_at(const ImageView& v, int x, int y) {
  return kernels::load3(v.normal + 3 * pixel_index(v, x, y));
}

/// Inserts `value` into the sorted len[0, n).
FOCAL_HD inline void insert_sorted(float* len, int& n, float value) {
  int i = n++;
  for (; i > 0 && len[i - 1] > value; --i) len[i] = len[i - 1];
  len[i] = value;
}

/// The median finite length of the edges from (px, py) to (px + dx, py + dy), both covered, for
/// px in [x0, x1], py in [y0, y1] (at most 15 edges); 0 where there are none.
FOCAL_HD inline float median_edge(const ImageView& v, int x0, int x1, int y0, int y1, int dx,
                                  int dy) {
  float len[15];
  int n = 0;
  for (int py = y0; py <= y1; ++py) {
    for (int px = x0; px <= x1; ++px) {
      if (!covered(v, px, py) || !covered(v, px + dx, py + dy)) continue;
      const float l = kernels::length(position_at(v, px + dx, py + dy) - position_at(v, px, py));
      if (kernels::is_finite(l)) insert_sorted(len, n, l);
    }
  }
  if (n == 0) return 0.0f;
  return n % 2 == 1 ? len[n / 2] : 0.5f * (len[n / 2 - 1] + len[n / 2]);
}

/// The longest the triplet's two edges at (x, y) may be: discontinuity_ratio times the local
/// pixel footprint along each image axis, the median length of the 15 parallel pixel edges
/// around the triplet's edge (3 along the edge's direction by 5 across it). Per axis, so that
/// anisotropic pixels (oblique views, geometry images near a pole) are not taken for
/// discontinuities; local, so that it follows perspective; a median, so that the edges a
/// discontinuity crosses (one per row or column, 5 of 15, for a straight one) do not move it.
struct EdgeLimits {
  float x, y;
};

FOCAL_HD inline EdgeLimits edge_limits(const ImageView& v, int x, int y, float ratio) {
  return {ratio * median_edge(v, x - 1, x + 1, y - 2, y + 2, 1, 0),
          ratio * median_edge(v, x - 2, x + 2, y - 1, y + 1, 0, 1)};
}

/// The characteristic equation of the triplet (x, y), (x + 1, y), (x, y + 1). Invalid where a
/// pixel of the triplet is not covered (the image's last row and column included) or one of its
/// two edges is longer than its limit (a depth discontinuity), and where solve_triplet is.
FOCAL_HD inline triplet::TripletSolution<float> pixel_triplet(const ImageView& v, int x, int y,
                                                              EdgeLimits limit) {
  if (!covered(v, x, y) || !covered(v, x + 1, y) || !covered(v, x, y + 1)) {
    return triplet::invalid_triplet<float>();
  }
  const Vec3<float> p[3] = {position_at(v, x, y), position_at(v, x + 1, y),
                            position_at(v, x, y + 1)};
  const Vec3<float> n[3] = {normal_at(v, x, y), normal_at(v, x + 1, y), normal_at(v, x, y + 1)};
  // NaN limits (ratio inf times footprint 0) compare false: no discontinuity test then.
  if (kernels::length(p[1] - p[0]) > limit.x || kernels::length(p[2] - p[0]) > limit.y) {
    return triplet::invalid_triplet<float>();
  }
  return triplet::solve_triplet(p, n);
}

/// One pixel's result, in the units of the G-buffer's positions.
struct PixelResult {
  bool valid = false;
  float k1, k2, H, K, lambda1, lambda2;
  Vec3<float> d1, d2;
};

FOCAL_HD inline PixelResult invalid_pixel() {
  const float nan = kernels::quiet_nan<float>();
  return {false, nan, nan, nan, nan, nan, nan, kernels::nan3<float>(), kernels::nan3<float>()};
}

FOCAL_HD inline PixelResult from_triplet(const triplet::TripletSolution<float>& s) {
  if (!s.valid) return invalid_pixel();
  return {true, s.k1, s.k2, s.H, s.K, s.lambda1, s.lambda2, s.d1, s.d2};
}

/// The per-pixel output arrays (see focal::ImageCurvature).
struct ImageFields {
  float *k1, *k2, *H, *K, *focal_depth1, *focal_depth2;
  float *d1, *d2;  ///< 3 per pixel
  std::uint8_t* valid;
};

FOCAL_HD inline void store_pixel(const ImageFields& out, int i, const PixelResult& r) {
  out.k1[i] = r.k1, out.k2[i] = r.k2, out.H[i] = r.H, out.K[i] = r.K;
  out.focal_depth1[i] = r.lambda1, out.focal_depth2[i] = r.lambda2;
  kernels::store3(out.d1 + 3 * i, r.d1);
  kernels::store3(out.d2 + 3 * i, r.d2);
  out.valid[i] = r.valid ? 1 : 0;
}

/// The result at (x, y) without a window: its own triplet's characteristic equation.
FOCAL_HD inline PixelResult pixel_result(const ImageView& v, int x, int y, float ratio) {
  return from_triplet(pixel_triplet(v, x, y, edge_limits(v, x, y, ratio)));
}

// ---------------------------------------------------------------------------------------------
// Triplet averaging over a (2 w + 1)^2 window: the first pass stores each pixel's symmetrised
// shape operator with its frame's normal; the second averages them in the centre's frame.

/// A pixel's triplet as the window needs it. weight = 0 marks an invalid triplet.
struct PixelOperator {
  float n[3];           ///< the triplet frame's normal
  float s00, s01, s11;  ///< symmetrised M = G X^-1 in frame_of(n)
  float weight;         ///< the triplet's relative_area (see TripletSolution)
  EdgeLimits limit;     ///< edge_limits at this pixel
};

FOCAL_HD inline PixelOperator pixel_operator(const ImageView& v, int x, int y, float ratio) {
  const EdgeLimits limit = edge_limits(v, x, y, ratio);
  const triplet::TripletSolution<float> s = pixel_triplet(v, x, y, limit);
  if (!s.valid) return {{0.0f, 0.0f, 0.0f}, 0.0f, 0.0f, 0.0f, 0.0f, limit};
  return {{s.frame.n.x, s.frame.n.y, s.frame.n.z},
          s.shape.a,
          0.5f * (s.shape.b + s.shape.c),
          s.shape.d,
          s.relative_area,
          limit};
}

/// The minimal rotation taking unit a to unit b (a.b > -1) applied to w (Rodrigues).
FOCAL_HD inline Vec3<float> rotate_between(Vec3<float> a, Vec3<float> b, Vec3<float> w) {
  const Vec3<float> axis = kernels::cross(a, b);
  const float c = kernels::dot(a, b);
  return w + kernels::cross(axis, w) +
         (1.0f / (1.0f + c)) * kernels::cross(axis, kernels::cross(axis, w));
}

/// A pixel's symmetric operator expressed in the frame `to`: its frame rotated onto to's tangent
/// plane (a rotation, not a projection, so that k I stays k I exactly, as on a sphere).
FOCAL_HD inline void operator_in_frame(const PixelOperator& o, const kernels::Frame<float>& to,
                                       float& a, float& b, float& c) {
  const kernels::Frame<float> from = kernels::frame_of(Vec3<float>{o.n[0], o.n[1], o.n[2]});
  const Vec3<float> x = rotate_between(from.n, to.n, from.x);
  const Vec3<float> y = rotate_between(from.n, to.n, from.y);
  // q: orthogonal change of basis from the rotated axes (x, y) to (to.x, to.y); S' = q S q^T.
  const float q00 = kernels::dot(to.x, x), q01 = kernels::dot(to.x, y);
  const float q10 = kernels::dot(to.y, x), q11 = kernels::dot(to.y, y);
  const float t00 = q00 * o.s00 + q01 * o.s01, t01 = q00 * o.s01 + q01 * o.s11;
  const float t10 = q10 * o.s00 + q11 * o.s01, t11 = q10 * o.s01 + q11 * o.s11;
  a = t00 * q00 + t01 * q01;
  b = t00 * q10 + t01 * q11;
  c = t10 * q10 + t11 * q11;
}

/// The principal curvatures of the symmetric [a b; b c] in frame f, as a pixel result.
FOCAL_HD inline PixelResult from_operator(const kernels::Frame<float>& f, float a, float b,
                                          float c) {
  const kernels::Principal<float> p = triplet::principal_of(a, b, c);
  return {true,
          p.k1,
          p.k2,
          0.5f * (p.k1 + p.k2),
          p.k1 * p.k2,
          -1.0f / p.k1,
          -1.0f / p.k2,
          f.from_plane(p.d1x, p.d1y),
          f.from_plane(-p.d1y, p.d1x)};
}

/// The weighted mean of the valid triplets' operators in the (2 w + 1)^2 window around
/// (x, y), in the frame of (x, y)'s triplet. Invalid where (x, y)'s own triplet is. A neighbour
/// counts only if its normal lies in the centre's hemisphere and it is no further from the centre
/// pixel than |i| + |j| edges of the centre's longer edge limit could reach: otherwise it lies
/// beyond a depth discontinuity, on another surface.
FOCAL_HD inline PixelResult window_result(const ImageView& v, const PixelOperator* ops, int x,
                                          int y, int w) {
  const PixelOperator& centre = ops[pixel_index(v, x, y)];
  if (!(centre.weight > 0.0f)) return invalid_pixel();
  const kernels::Frame<float> frame =
      kernels::frame_of(Vec3<float>{centre.n[0], centre.n[1], centre.n[2]});
  const Vec3<float> p = position_at(v, x, y);
  float sa = 0.0f, sb = 0.0f, sc = 0.0f, total = 0.0f;
  for (int j = -w; j <= w; ++j) {
    for (int i = -w; i <= w; ++i) {
      const int px = x + i, py = y + j;
      if (px < 0 || py < 0 || px >= v.width || py >= v.height) continue;
      const PixelOperator& o = ops[pixel_index(v, px, py)];
      if (!(o.weight > 0.0f)) continue;
      if (!(kernels::dot(frame.n, Vec3<float>{o.n[0], o.n[1], o.n[2]}) > 0.0f)) continue;
      const float steps = static_cast<float>((i < 0 ? -i : i) + (j < 0 ? -j : j));
      const float distance = kernels::length(position_at(v, px, py) - p);
      if (distance > steps * centre.limit.x && distance > steps * centre.limit.y) continue;
      float a, b, c;
      operator_in_frame(o, frame, a, b, c);
      sa += o.weight * a, sb += o.weight * b, sc += o.weight * c, total += o.weight;
    }
  }
  return from_operator(frame, sa / total, sb / total, sc / total);
}

}  // namespace focal::image_kernel
