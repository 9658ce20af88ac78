#include "focal/surfaces/surfaces.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cmath>
#include <random>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/memory.h"
#include "focal/core/error.h"
#include "surfaces/triangulation.h"

namespace focal {
namespace {

/// Bytes per vertex checked against the machine's available memory before a surface is made:
/// the peak RSS of `focal generate sphere --vertices 1000000 -o s.ply --truth t.csv` over its
/// vertex count (regular 257, irregular 307 bytes, the process's own ~10 MB included) times 1.25.
constexpr std::uint64_t kRegularBytesPerVertex = 320;
constexpr std::uint64_t kIrregularBytesPerVertex = 385;

using detail::DomainStats;
using detail::Parametrisation;
using detail::Triangulated;
using Eigen::Vector2d;
using Eigen::Vector3d;

AnalyticSurface assemble(const Parametrisation& s, const ParameterDomain& d,
                         const Triangulated& t) {
  const auto nv = static_cast<Eigen::Index>(t.uv.size());
  const auto nf = static_cast<Eigen::Index>(t.faces.size());
  AnalyticSurface out;
  out.mesh.V.resize(nv, 3);
  out.mesh.N.resize(nv, 3);
  out.d1.resize(nv, 3);
  out.d2.resize(nv, 3);
  out.k1.resize(nv);
  out.k2.resize(nv);
  out.uv.resize(nv, 2);
  for (Eigen::Index i = 0; i < nv; ++i) {
    const SurfacePoint p = detail::evaluate(s, d, t.uv[i]);
    out.mesh.V.row(i) = p.position.transpose();
    out.mesh.N.row(i) = p.normal.transpose();
    out.d1.row(i) = p.d1.transpose();
    out.d2.row(i) = p.d2.transpose();
    out.k1[i] = p.k1;
    out.k2[i] = p.k2;
    out.uv.row(i) = t.uv[i].transpose();
  }
  out.mesh.F.resize(nf, 3);
  for (Eigen::Index f = 0; f < nf; ++f) {
    for (int c = 0; c < 3; ++c) out.mesh.F(f, c) = t.faces[f][c];
  }
  out.mesh.face_source = Eigen::VectorXi::LinSpaced(nf, 0, static_cast<int>(nf) - 1);
  return out;
}

constexpr std::array<std::pair<SurfaceKind, std::string_view>, 8> kNames{{
    {SurfaceKind::sphere, "sphere"},
    {SurfaceKind::ellipsoid, "ellipsoid"},
    {SurfaceKind::torus, "torus"},
    {SurfaceKind::cylinder, "cylinder"},
    {SurfaceKind::saddle, "saddle"},
    {SurfaceKind::monkey_saddle, "monkey-saddle"},
    {SurfaceKind::helix_tube, "helix-tube"},
    {SurfaceKind::pear, "pear"},
}};

void check_amplitude(double amplitude, const char* what) {
  if (!std::isfinite(amplitude) || amplitude < 0.0) {
    throw InvalidInput(std::string(what) + ": amplitude must be finite and >= 0, got " +
                       std::to_string(amplitude));
  }
}

}  // namespace

std::string_view surface_name(SurfaceKind kind) {
  for (const auto& [k, name] : kNames) {
    if (k == kind) return name;
  }
  throw InvalidInput("surface_name: unknown SurfaceKind " + std::to_string(static_cast<int>(kind)));
}

SurfaceKind surface_from_name(std::string_view name) {
  std::string known;
  for (const auto& [kind, n] : kNames) {
    if (n == name) return kind;
    known += (known.empty() ? "" : ", ") + std::string(n);
  }
  throw InvalidInput("unknown surface '" + std::string(name) + "'; known surfaces: " + known);
}

std::vector<SurfaceKind> all_surfaces() {
  std::vector<SurfaceKind> out;
  for (const auto& [kind, name] : kNames) out.push_back(kind);
  return out;
}

AnalyticSurface make_surface(const SurfaceOptions& options) {
  if (options.target_vertices < 16 || options.target_vertices > detail::kMaxTarget) {
    throw InvalidInput("make_surface: target_vertices must be in [16, " +
                       std::to_string(detail::kMaxTarget) + "], got " +
                       std::to_string(options.target_vertices));
  }
  if (!(options.aspect > 0.0) || !std::isfinite(options.aspect)) {
    throw InvalidInput("make_surface: aspect must be finite and > 0, got " +
                       std::to_string(options.aspect));
  }
  if (!(options.grading >= 1.0) || !std::isfinite(options.grading)) {
    throw InvalidInput("make_surface: grading must be finite and >= 1, got " +
                       std::to_string(options.grading));
  }
  // Refused before anything is allocated when the machine cannot hold it (kRegularBytesPerVertex).
  detail::require_memory(
      static_cast<std::uint64_t>(options.target_vertices) *
          (options.triangulation == Triangulation::irregular ? kIrregularBytesPerVertex
                                                             : kRegularBytesPerVertex),
      "a surface of " + std::to_string(options.target_vertices) + " vertices");
  const auto surface = detail::make_parametrisation(options);
  const ParameterDomain d = surface->domain();
  const DomainStats stats = detail::domain_stats(*surface, d);
  const int target = detail::effective_target(stats, options.target_vertices);
  switch (options.triangulation) {
    case Triangulation::regular:
      // Cells `aspect` times longer along u than along v: that many fewer u intervals.
      return assemble(
          *surface, d,
          d.disc ? detail::regular_disc(d.u_max, target)
                 : detail::regular_grid(d, target, stats.log_aspect - std::log(options.aspect)));
    case Triangulation::irregular:
      return assemble(*surface, d,
                      detail::irregular_triangulation(*surface, d, stats, target, options.seed,
                                                      options.grading));
  }
  throw InvalidInput("make_surface: unknown Triangulation " +
                     std::to_string(static_cast<int>(options.triangulation)));
}

ParameterDomain surface_domain(const SurfaceOptions& options) {
  return detail::make_parametrisation(options)->domain();
}

SurfacePoint evaluate_surface(const SurfaceOptions& options, double u, double v) {
  // Refused before anything is allocated when the machine cannot hold it (kRegularBytesPerVertex).
  detail::require_memory(
      static_cast<std::uint64_t>(options.target_vertices) *
          (options.triangulation == Triangulation::irregular ? kIrregularBytesPerVertex
                                                             : kRegularBytesPerVertex),
      "a surface of " + std::to_string(options.target_vertices) + " vertices");
  const auto surface = detail::make_parametrisation(options);
  const ParameterDomain d = surface->domain();
  if (!std::isfinite(u) || !std::isfinite(v)) {
    throw InvalidInput("evaluate_surface: parameters must be finite");
  }
  if (d.poles && (u < d.u_min || u > d.u_max)) {
    throw InvalidInput("evaluate_surface: u = " + std::to_string(u) + " outside [" +
                       std::to_string(d.u_min) + ", " + std::to_string(d.u_max) + "]");
  }
  return detail::evaluate(*surface, d, {u, v});
}

void add_position_noise(Mesh& mesh, double amplitude, std::uint64_t seed) {
  check_amplitude(amplitude, "add_position_noise");
  validate_mesh_arrays(mesh.V, mesh.F, mesh.N, "add_position_noise");
  const double scale = amplitude * mean_edge_length(mesh.V, mesh.F);
  std::mt19937_64 rng(seed);
  for (Eigen::Index i = 0; i < mesh.V.rows(); ++i) {
    for (int c = 0; c < 3; ++c) mesh.V(i, c) += scale * detail::uniform(rng, -1.0, 1.0);
  }
}

void add_normal_noise(Mesh& mesh, double amplitude, std::uint64_t seed) {
  check_amplitude(amplitude, "add_normal_noise");
  if (!mesh.has_normals()) throw InvalidInput("add_normal_noise: the mesh has no normals");
  std::mt19937_64 rng(seed);
  for (Eigen::Index i = 0; i < mesh.N.rows(); ++i) {
    // n + u can only vanish for amplitude >= 1/sqrt(3); draw again then rather than divide by 0.
    Vector3d noisy;
    do {
      const Vector3d u(detail::uniform(rng, -amplitude, amplitude),
                       detail::uniform(rng, -amplitude, amplitude),
                       detail::uniform(rng, -amplitude, amplitude));
      noisy = mesh.N.row(i).transpose() + u;
    } while (noisy.squaredNorm() == 0.0);
    mesh.N.row(i) = noisy.normalized().transpose();
  }
}

namespace {

/// round(fraction * n) distinct vertices in random order (a partial Fisher-Yates shuffle).
std::vector<Eigen::Index> random_vertices(Eigen::Index n, double fraction, std::mt19937_64& rng) {
  std::vector<Eigen::Index> order(static_cast<std::size_t>(n));
  for (Eigen::Index i = 0; i < n; ++i) order[static_cast<std::size_t>(i)] = i;
  const auto count = static_cast<std::size_t>(std::llround(fraction * static_cast<double>(n)));
  for (std::size_t k = 0; k < count; ++k) {
    const auto pick = k + static_cast<std::size_t>(detail::uniform01(rng) *
                                                   static_cast<double>(order.size() - k));
    std::swap(order[k], order[std::min(pick, order.size() - 1)]);
  }
  order.resize(count);
  return order;
}

void check_fraction(double fraction, const char* what) {
  if (!(fraction >= 0.0 && fraction <= 1.0)) {
    throw InvalidInput(std::string(what) + ": fraction must be in [0, 1], got " +
                       std::to_string(fraction));
  }
}

}  // namespace

void add_outlier_normals(Mesh& mesh, double fraction, std::uint64_t seed) {
  check_fraction(fraction, "add_outlier_normals");
  if (!mesh.has_normals()) throw InvalidInput("add_outlier_normals: the mesh has no normals");
  std::mt19937_64 rng(seed);
  for (const Eigen::Index i : random_vertices(mesh.N.rows(), fraction, rng)) {
    // Uniform on the sphere: z uniform in [-1, 1], azimuth uniform (Archimedes).
    const double z = detail::uniform(rng, -1.0, 1.0),
                 phi = detail::uniform(rng, 0.0, 2.0 * detail::kPi);
    const double rho = std::sqrt(std::max(0.0, 1.0 - z * z));
    mesh.N.row(i) = Vector3d(rho * std::cos(phi), rho * std::sin(phi), z).transpose();
  }
}

void add_spikes(Mesh& mesh, double fraction, double height, std::uint64_t seed) {
  check_fraction(fraction, "add_spikes");
  check_amplitude(height, "add_spikes");
  if (!mesh.has_normals()) throw InvalidInput("add_spikes: the mesh has no normals");
  validate_mesh_arrays(mesh.V, mesh.F, mesh.N, "add_spikes");
  const double length = height * mean_edge_length(mesh.V, mesh.F);
  std::mt19937_64 rng(seed);
  for (const Eigen::Index i : random_vertices(mesh.V.rows(), fraction, rng)) {
    const double side = detail::uniform01(rng) < 0.5 ? -1.0 : 1.0;
    mesh.V.row(i) += side * length * mesh.N.row(i).normalized();
  }
}

}  // namespace focal
