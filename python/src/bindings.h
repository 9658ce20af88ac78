#pragma once
// What every part of the bindings shares (python/src/*.cpp): the input layout the package's
// Python code converts to (C-ordered float64 n x 3 rows, C-ordered int32 n x 3 faces), viewed
// without copying, and results handed to NumPy with a capsule that owns them (moved, never
// copied).

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "focal/core/error.h"
#include "focal/core/fields.h"
#include "focal/core/mesh.h"
#include "focal/curvature/estimate.h"

namespace focal_python {

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
// (Returned as an ndarray type, not an object, so that the generated stub says NDArray.)
template <class Matrix>
nb::ndarray<nb::numpy, typename std::decay_t<Matrix>::Scalar> to_numpy(Matrix&& m) {
  using M = std::decay_t<Matrix>;
  using Scalar = typename M::Scalar;
  auto* owned = new M(std::forward<Matrix>(m));
  nb::capsule owner(owned, [](void* p) noexcept { delete static_cast<M*>(p); });
  if constexpr (M::ColsAtCompileTime == 1) {
    const size_t shape[1] = {static_cast<size_t>(owned->rows())};
    return nb::ndarray<nb::numpy, Scalar>(owned->data(), 1, shape, owner);
  } else {
    static_assert(M::IsRowMajor, "results are row-major n x 3 (or n x 2)");
    const size_t shape[2] = {static_cast<size_t>(owned->rows()),
                             static_cast<size_t>(owned->cols())};
    return nb::ndarray<nb::numpy, Scalar>(owned->data(), 2, shape, owner);
  }
}

template <class Matrix>
nb::object optional_to_numpy(std::optional<Matrix>&& m) {
  if (!m) return nb::none();
  return nb::cast(to_numpy(std::move(*m)));
}

/// Global ids (tiles, focal/tiles/tiles.h) as an int32 array, and back.
using Ids = nb::ndarray<const std::int32_t, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
inline nb::object ids_to_numpy(const std::vector<int>& ids) {
  return nb::cast(to_numpy(Eigen::VectorXi(
      Eigen::Map<const Eigen::VectorXi>(ids.data(), static_cast<Eigen::Index>(ids.size())))));
}
inline std::vector<int> ids_from(const Ids& a) { return {a.data(), a.data() + a.shape(0)}; }

/// Crease flags (Estimate::crease) as an array, None when the estimator gives none (empty).
inline nb::object crease_or_none(focal::VectorXu8&& crease) {
  if (crease.size() == 0) return nb::none();
  return nb::cast(to_numpy(std::move(crease)));
}

template <class Enum, size_t n>
Enum parse_enum(const std::string& value, const char* argument,
                const std::pair<const char*, Enum> (&names)[n]) {
  std::string known;
  for (const auto& [name, e] : names) {
    if (value == name) return e;
    known += std::string(known.empty() ? "" : ", ") + "'" + name + "'";
  }
  throw focal::InvalidInput(std::string(argument) + ": unknown value '" + value + "' (expected " +
                            known + ")");
}

/// The per-vertex fields of a result as a dict of NumPy arrays (meshes.cpp).
nb::dict curvature_dict(focal::CurvatureResult&& r);

/// The options of focal::estimate from the keywords of focal.curvature (meshes.cpp).
focal::EstimateOptions estimate_options(const nb::dict& o);

/// A cloud's options from the dict of focal.curvature's (and cloud tiles') cloud keywords: k,
/// radius, adaptive_radius, normal_method, viewpoint, solver, outlier_ratio, off_surface_ratio
/// (clouds.cpp; its "threads" is the caller's ExecutionScope's).
focal::CloudOptions cloud_options_from(const nb::dict& d);

/// A file name as the package passes it: os.fsencode's bytes (str, bytes and os.PathLike; a
/// name that is not UTF-8 keeps its bytes), the bytes the operating system takes.
inline std::string path_of(const nb::bytes& path) { return {path.c_str(), path.size()}; }

inline std::optional<focal::NormalsRef> normals_ref(const std::optional<DoubleRows>& N) {
  if (!N) return std::nullopt;
  return focal::NormalsRef(view(*N));
}

/// An image of h * w * channels values as an (h, w) (one channel) or (h, w, channels) array over
/// its buffer, moved to the heap and freed with the last array.
template <class T>
nb::ndarray<nb::numpy, T> pixels(std::vector<T>&& values, int height, int width, int channels) {
  auto* owned = new std::vector<T>(std::move(values));
  nb::capsule owner(owned, [](void* p) noexcept { delete static_cast<std::vector<T>*>(p); });
  const size_t shape[3] = {static_cast<size_t>(height), static_cast<size_t>(width),
                           static_cast<size_t>(channels)};
  return nb::ndarray<nb::numpy, T>(owned->data(), channels == 1 ? 2 : 3, shape, owner);
}

}  // namespace focal_python
