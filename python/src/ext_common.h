#pragma once
// What the binding files of focal._focal_ext share: the array layouts they accept, views of them,
// results handed to NumPy, and the conversions of focal_ext.cpp that other files reuse.

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <cstdint>
#include <optional>
#include <utility>

#include "focal/core/fields.h"
#include "focal/core/mesh.h"
#include "focal/curvature/estimate.h"

namespace focal_ext {

namespace nb = nanobind;

using DoubleRows = nb::ndarray<const double, nb::ndim<2>, nb::c_contig, nb::device::cpu>;
using IntRows = nb::ndarray<const std::int32_t, nb::ndim<2>, nb::c_contig, nb::device::cpu>;

using ConstMapX3d = Eigen::Map<const focal::RowMatrixX3d>;
using ConstMapX3i = Eigen::Map<const focal::RowMatrixX3i>;

inline ConstMapX3d view(const DoubleRows& a) {
  return ConstMapX3d(a.data(), static_cast<Eigen::Index>(a.shape(0)), 3);
}
inline ConstMapX3i view(const IntRows& a) {
  return ConstMapX3i(a.data(), static_cast<Eigen::Index>(a.shape(0)), 3);
}

// A matrix or vector moved to the heap and given to NumPy, which frees it through the capsule.
template <class Matrix>
nb::object to_numpy(Matrix&& m) {
  using M = std::decay_t<Matrix>;
  using Scalar = typename M::Scalar;
  auto* owned = new M(std::forward<Matrix>(m));
  nb::capsule owner(owned, [](void* p) noexcept { delete static_cast<M*>(p); });
  if constexpr (M::ColsAtCompileTime == 1) {
    const size_t shape[1] = {static_cast<size_t>(owned->rows())};
    return nb::cast(nb::ndarray<nb::numpy, Scalar>(owned->data(), 1, shape, owner));
  } else {
    static_assert(M::IsRowMajor, "results are row-major n x 3");
    const size_t shape[2] = {static_cast<size_t>(owned->rows()),
                             static_cast<size_t>(owned->cols())};
    return nb::cast(nb::ndarray<nb::numpy, Scalar>(owned->data(), 2, shape, owner));
  }
}

template <class Matrix>
nb::object optional_to_numpy(std::optional<Matrix>&& m) {
  if (!m) return nb::none();
  return to_numpy(std::move(*m));
}

/// The per-vertex fields of a result as a dict of NumPy arrays (focal_ext.cpp).
nb::dict curvature_dict(focal::CurvatureResult&& r);

/// The options of focal::estimate from the keywords of focal.curvature (focal_ext.cpp).
focal::EstimateOptions estimate_options(const nb::dict& o);

/// focal._focal_ext's functions of focal/tiles (tiles.cpp).
void bind_tiles(nb::module_& m);

}  // namespace focal_ext
