#pragma once
// Per-lane versions of the pieces shared by the per-vertex fit and the per-triangle solve
// (curvature_detail.h, normal_rays_detail.h): the same operations in the same order on each lane.

#include <cstdint>

#include "curvature/detail.h"
#include "core/simd_lanes.h"

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"

namespace focal::detail {

/// frame_of (Duff et al. 2017) per lane: x and y of the frame of the unit normal n.
template <class L>
FOCAL_LANE_INLINE void frame_lanes(L nx, L ny, L nz, L& xx, L& xy, L& xz, L& yx, L& yy, L& yz) {
  const L sign = sign_of(nz);
  const L a = -1.0 / (sign + nz);
  const L b = nx * ny * a;
  xx = 1.0 + sign * nx * nx * a, xy = sign * b, xz = -sign * nx;
  yx = b, yy = sign + ny * ny * a, yz = -ny;
}

/// Per lane: k1 >= k2 and the unit d1 in the tangent plane (principal_from_symmetric's
/// operations; the isotropic case by select).
template <class L>
struct alignas(sizeof(L)) PrincipalLanes {
  L k1, k2, d1x, d1y;
};

template <class L>
FOCAL_LANE_INLINE PrincipalLanes<L> principal_lanes(L a, L b, L c) {
  const L mean = 0.5 * (a + c);
  const L d = 0.5 * (a - c);
  const L s = lane_max(lane_abs(d), lane_abs(b));
  const auto isotropic = s == 0.0;
  const L one = broadcast<L>(1.0), zero{};
  const L inv = 1.0 / (isotropic ? one : s);
  const L ds = d * inv, bs = b * inv;
  const L r = lane_sqrt(ds * ds + bs * bs);
  const auto positive = ds >= 0.0;
  L x = positive ? r + ds : lane_abs(bs);
  L y = positive ? bs : lane_copysign(r - ds, bs);
  const L length = lane_sqrt(2.0 * r * (r + lane_abs(ds)));
  const L inv_length = 1.0 / length;
  x *= inv_length, y *= inv_length;
  return {isotropic ? mean : mean + s * r, isotropic ? mean : mean - s * r, isotropic ? one : x,
          isotropic ? zero : y};
}

/// classify() per lane, as codes.
template <class L>
FOCAL_LANE_INLINE MaskOf<L> classify_lanes(L k1, L k2, const ClassTolerances& tol) {
  const auto code = [](PointClass p)
                        FOCAL_LANE_LAMBDA { return MaskOf<L>{} + static_cast<std::int64_t>(p); };
  const L a1 = lane_abs(k1), a2 = lane_abs(k2);
  const auto zero1 = a1 <= tol.zero, zero2 = a2 <= tol.zero;
  auto c = (k1 * k2 > 0.0) ? code(PointClass::elliptic) : code(PointClass::hyperbolic);
  c = (k1 - k2 <= tol.umbilic * lane_max(a1, a2)) ? code(PointClass::umbilic) : c;
  c = (zero1 | zero2) ? code(PointClass::parabolic) : c;
  c = (zero1 & zero2) ? code(PointClass::flat) : c;
  return (finite(k1) & finite(k2)) ? c : code(PointClass::undefined);
}

}  // namespace focal::detail

#pragma GCC diagnostic pop
