// focal::smooth (focal/smoothing/smooth.h): passes of robust local surface fits
// (smoothing/surface_fit.h) over mesh rings or cloud neighbours, kept while the measured noise
// falls.
#include "focal/smoothing/smooth.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "core/parallel.h"
#include "focal/core/error.h"
#include "focal/curvature/recommended.h"
#include "focal/mesh/neighbourhood.h"
#include "focal/normals/cloud_normals.h"
#include "focal/points/neighbours.h"
#include "mesh/prepared_access.h"
#include "mesh/topology.h"
#include "normals/jet_points.h"
#include "normals/vertex_normals_from.h"
#include "smoothing/creases.h"
#include "smoothing/surface_fit.h"

namespace focal {
namespace {

using detail::smoothing::FitScratch;
using detail::smoothing::LocalSurface;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Cloud neighbours of a fit on clean clouds, and above kCloudNoisyNeighbours' noise.
constexpr int kCloudNeighbours = 16;
constexpr int kCloudNoisyNeighbours = 64;
/// Cloud position noise (median residual / mean spacing) above which fits take
/// kCloudNoisyNeighbours (the cloud default's threshold, docs/METHOD.md).
constexpr double kCloudNoisy = 0.03;
/// Mesh rings of a fit where the recommended plan keeps the 1-ring (clean or slightly noisy):
/// a quadric over 2 rings (about 19 points) averages the noise, 1 ring (7) too few.
constexpr int kCleanRings = 2;
/// No point is an outlier of a fit within this many mean edge lengths of it (reject_far_points'
/// floor): clean surfaces' truncation residuals are far below it (O(h^3) relative), a spike of
/// the evaluations is 2 edges.
constexpr double kOutlierFloor = 0.05;

/// A point lies within the noise of a side's surface: within this many of its fit's residuals.
constexpr double kOnSideResiduals = 1.5;

/// A crease point's move onto its sides' planes is at most this many of their fits' residuals
/// (the noise: uniform noise of amplitude a has an RMS of a / sqrt(3), and moves up to a).
constexpr double kMaxCreaseMove = 4.0;

/// Each mesh vertex's vertices within its rings (jets::gather_ring: itself included, ascending),
/// gathered once for all passes (the positions move, the neighbourhoods do not) and packed: the
/// gaps between consecutive entries (the first: v minus it) as LEB128 varints, one byte each for
/// gaps below 128 (a few bytes an entry where nearby vertices have nearby indices, at most five).
/// In blocks of kBlock vertices, each block's bytes their own array (gathered in parallel, kept
/// as they are: no joined copy).
struct PackedRings {
  static constexpr std::int64_t kBlock = 4096;
  /// #V: the end of each vertex's bytes in its block (a vertex starts where the one before ends,
  /// the first of a block at 0).
  std::vector<std::uint32_t> ends;
  std::vector<std::vector<std::uint8_t>> blocks;

  void unpack(int v, std::vector<int>& ring) const {
    const auto k = static_cast<std::size_t>(v);
    const std::uint8_t* block = blocks[k / kBlock].data();
    const std::uint8_t* p = block + (k % kBlock == 0 ? 0 : ends[k - 1]);
    const std::uint8_t* end = block + ends[k];
    ring.resize(static_cast<std::size_t>(end - p));  // at most one entry a byte
    int* out = ring.data();
    const auto gap = [&p] {
      std::uint32_t value = *p++;
      if (value < 0x80) return value;
      value &= 0x7f;
      for (unsigned shift = 7;; shift += 7) {
        const std::uint8_t byte = *p++;
        value |= static_cast<std::uint32_t>(byte & 0x7f) << shift;
        if (byte < 0x80) return value;
      }
    };
    int last = v;
    if (p != end) *out++ = last = v - static_cast<int>(gap());
    while (p != end) *out++ = last += static_cast<int>(gap());
    ring.resize(static_cast<std::size_t>(out - ring.data()));
  }
};

void pack_ring(int v, const std::vector<int>& ring, std::vector<std::uint8_t>& out) {
  int last = v;
  bool first = true;
  for (const int w : ring) {
    auto gap = static_cast<std::uint32_t>(first ? v - w : w - last);
    first = false;
    last = w;
    for (; gap >= 0x80; gap >>= 7) out.push_back(static_cast<std::uint8_t>(gap | 0x80));
    out.push_back(static_cast<std::uint8_t>(gap));
  }
}

/// Where each point's neighbourhood comes from: a mesh's rings, or a cloud's lists.
struct Neighbours {
  /// A mesh's 1-ring (its nearest neighbours) and its vertices' rings; null for clouds.
  const Neighbourhoods* one_ring = nullptr;
  const PackedRings* rings = nullptr;
  /// A cloud's nearest neighbours.
  const Neighbourhoods* lists = nullptr;
  bool oriented = true;  ///< frame normals on one side (meshes); clouds compare lines
  /// The input's normals (Max's, or the cloud's), which group a crease's sides in every pass:
  /// the fitted normals of a pass that rounded a crease would round it further in the next.
  const RowMatrixX3d* sides_of = nullptr;
};

struct Scratch {
  std::vector<int> ring, side[detail::smoothing::kMaxSides];
  std::vector<Eigen::Vector3d> normals;  ///< crease_sides' scratch
  FitScratch fit;
  detail::smoothing::LaneFits lanes;  ///< the fits over a whole neighbourhood or one side
};

void neighbourhood_of(const Neighbours& nb, int i, Scratch& s) {
  if (nb.rings) {
    nb.rings->unpack(i, s.ring);
  } else {
    s.ring.assign(nb.lists->begin(i), nb.lists->end(i));
  }
}

/// The rings of every vertex, packed (PackedRings), a block of vertices at a time.
PackedRings gathered_rings(const Neighbourhoods& one, int rings) {
  const int n = one.vertex_count();
  constexpr std::int64_t kBlock = PackedRings::kBlock;
  struct Gather {
    std::vector<std::uint64_t> in_ring;
    std::vector<int> ring;
  };
  detail::PerThread<Gather> scratch(0);
  PackedRings out;
  out.ends.resize(static_cast<std::size_t>(n));
  out.blocks.resize(static_cast<std::size_t>((n + kBlock - 1) / kBlock));
  detail::parallel_for_blocks(n, kBlock, 0, [&](std::int64_t begin, std::int64_t end) {
    Gather& g = scratch.local();
    std::vector<std::uint8_t>& bytes = out.blocks[static_cast<std::size_t>(begin / kBlock)];
    for (std::int64_t v = begin; v < end; ++v) {
      detail::jets::gather_ring(one, static_cast<int>(v), rings, g.in_ring, nullptr, g.ring);
      pack_ring(static_cast<int>(v), g.ring, bytes);
      out.ends[static_cast<std::size_t>(v)] = static_cast<std::uint32_t>(bytes.size());
    }
    bytes.shrink_to_fit();
  });
  return out;
}

/// One pass: every point's surface, in the frame of its row of `frames`.
struct Pass {
  RowMatrixX3d V;
  /// The fitted normals; at points without a fit their frames (so that N is the next pass's
  /// frames as it is: a point without a fit keeps its frame), `fitted` 0 there.
  RowMatrixX3d N;
  Eigen::VectorXd residual;       ///< per point, while the pass runs (freed after: its median kept)
  double median_residual = kNaN;  ///< of the fitted points
  std::vector<char> fitted;       ///< the point had a well-posed fit
  std::vector<char> outlier;      ///< the point itself lay far off its surface
  VectorXu8 crease;               ///< on several sides of a crease
  int crease_points = 0, unfitted = 0;
};

/// A pass's normals as a result: NaN rows at the points without a fit.
RowMatrixX3d result_normals(RowMatrixX3d N, const std::vector<char>& fitted) {
  for (Eigen::Index i = 0; i < N.rows(); ++i) {
    if (!fitted[static_cast<std::size_t>(i)]) N.row(i).setConstant(kNaN);
  }
  return N;
}

/// The surface of point i: over its whole neighbourhood; or, where its neighbours' normals fall
/// into sides of a crease (keep_creases), each side's surface, the point moved onto the one it
/// lies on, or onto the planes of all it lies on (the crease line, a corner). A point lies on
/// the sides its nearest neighbours are members of. A fit of o.degree over the whole
/// neighbourhood or one side is queued in s.lanes (`queued`), for the caller to run.
enum class Fit { plain, crease, queued };

Fit surface_of(PositionsRef V, const RowMatrixX3d& frames, const Neighbours& nb,
               const SmoothOptions& o, double floor, int i, Scratch& s, LocalSurface& out) {
  using namespace detail::smoothing;
  neighbourhood_of(nb, i, s);
  Eigen::Vector3d mean[kMaxSides];
  const int sides = o.keep_creases && nb.sides_of->row(i).allFinite()
                        ? crease_sides(*nb.sides_of, i, s.ring, std::cos(o.crease_angle),
                                       nb.oriented, s.side, mean, s.normals)
                        : 0;
  if (sides < 2) {
    const bool one = sides == 1;
    const Eigen::Vector3d n = one ? mean[0] : Eigen::Vector3d(frames.row(i).transpose());
    const std::vector<int>& members = one ? s.side[0] : s.ring;
    const int degree = one ? side_degree(s.side[0].size(), o.degree) : o.degree;
    if (degree == o.degree) {
      s.lanes.queue(V, i, n, members);
      return Fit::queued;
    }
    out = fit_local_surface(V, i, n, members, degree, o.robust, floor, s.fit);
    return Fit::plain;
  }
  const Eigen::Vector3d ni = nb.sides_of->row(i).transpose();
  // The sides the point lies on: those its nearest neighbours (1-ring) are members of.
  int nearest = 0;
  for (int k = 1; k < sides; ++k) {
    if (std::abs(ni.dot(mean[k])) > std::abs(ni.dot(mean[nearest]))) nearest = k;
  }
  const int* near_begin = nb.one_ring ? nb.one_ring->begin(i) : nb.lists->begin(i);
  const int* near_end =
      nb.one_ring ? nb.one_ring->end(i) : std::min(nb.lists->end(i), near_begin + kSideNeighbours);
  // ... and whose mean normal its own normal is within 3/4 of the sides' widest angle of (a
  // point beside the crease has a neighbour on the crease that may have been counted to the
  // other side, but its own normal is that of its side).
  double widest = 1.0;
  for (int a = 0; a < sides; ++a) {
    for (int b = a + 1; b < sides; ++b) widest = std::min(widest, mean[a].dot(mean[b]));
  }
  const double cos_on = std::cos(0.75 * std::acos(std::clamp(widest, -1.0, 1.0)));
  LocalSurface fit[kMaxSides];
  const LocalSurface* on[kMaxSides];
  int count = 0;
  for (int k = 0; k < sides; ++k) {
    const auto& members = s.side[k];
    bool meets = false;
    for (const int* j = near_begin; j != near_end && !meets; ++j) {
      meets = std::binary_search(members.begin(), members.end(), *j);
    }
    if (!meets) continue;
    fit[k] = fit_local_surface(V, i, mean[k], members, side_degree(members.size(), o.degree),
                               o.robust, floor, s.fit);
    // A noisy own normal may lean to one side: the point is on the other too when it lies
    // within the noise of that side's surface.
    const double along = nb.oriented ? ni.dot(mean[k]) : std::abs(ni.dot(mean[k]));
    const bool close = std::abs(fit[k].height) <= kOnSideResiduals * fit[k].residual;
    if (fit[k].ok && (along >= cos_on || close)) on[count++] = &fit[k];
  }
  if (count < 2) {
    // One side, or none met (only crease points around): the side of the point's own normal.
    const int k = count == 1 ? static_cast<int>(on[0] - fit) : nearest;
    out = count == 1
              ? fit[k]
              : fit_local_surface(V, i, mean[k], s.side[k], side_degree(s.side[k].size(), o.degree),
                                  o.robust, floor, s.fit);
    return Fit::plain;
  }
  // A point on a crease moves onto the sides' planes, as far as its noise lets it: a move
  // beyond kMaxCreaseMove residuals (a side's surface extrapolated, or sides met by mistake)
  // takes the side of its own normal instead.
  const Eigen::Vector3d p = V.row(i).transpose();
  const Eigen::Vector3d moved = onto_planes(p, on, count);
  double residual = 0.0;
  for (int k = 0; k < count; ++k) residual = std::max(residual, on[k]->residual);
  if (!((moved - p).norm() <= std::max(kMaxCreaseMove * residual, floor))) {
    out = fit_local_surface(V, i, mean[nearest], s.side[nearest],
                            side_degree(s.side[nearest].size(), o.degree), o.robust, floor, s.fit);
    return Fit::plain;
  }
  out = *on[0];
  out.point = moved;
  out.residual = residual;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  out.centre_rejected = true;
  for (int k = 0; k < count; ++k) {
    normal += on[k]->normal;
    out.centre_rejected = out.centre_rejected && on[k]->centre_rejected;
  }
  out.normal = normal.normalized();
  out.ok = out.point.allFinite() && out.normal.allFinite();
  return Fit::crease;
}

Pass run_pass(PositionsRef V, const RowMatrixX3d& frames, const Neighbours& nb,
              const SmoothOptions& o, double scale) {
  const double floor = kOutlierFloor * scale;
  const Eigen::Index n = V.rows();
  Pass p;
  p.V.resize(n, 3);
  p.N.resize(n, 3);
  p.residual.resize(n);
  p.fitted.assign(static_cast<std::size_t>(n), 0);
  p.outlier.assign(static_cast<std::size_t>(n), 0);
  p.crease = VectorXu8::Zero(n);
  detail::PerThread<Scratch> scratch(0);
  detail::parallel_for_blocks(n, 256, 0, [&](std::int64_t begin, std::int64_t end) {
    Scratch& s = scratch.local();
    const auto store = [&](int i, const LocalSurface& f) {
      if (!f.ok) {
        p.V.row(i) = V.row(i);
        p.N.row(i) = frames.row(i);
        p.residual[i] = kNaN;
        return;
      }
      p.V.row(i) = f.point.transpose();
      p.N.row(i) = f.normal.transpose();
      p.residual[i] = f.residual;
      p.fitted[static_cast<std::size_t>(i)] = 1;
      p.outlier[static_cast<std::size_t>(i)] = f.centre_rejected;
    };
    int row[detail::jets::kMaxLanes];
    LocalSurface fits[detail::jets::kMaxLanes];
    const auto run_queued = [&] {
      const int queued = s.lanes.queued;
      s.lanes.run(V, o.degree, o.robust, floor, fits);
      for (int l = 0; l < queued; ++l) store(row[l], fits[l]);
    };
    for (std::int64_t k = begin; k < end; ++k) {
      const int i = static_cast<int>(k);
      LocalSurface f;
      if (frames.row(i).allFinite() && V.row(i).allFinite()) {
        row[s.lanes.queued] = i;
        const Fit fit = surface_of(V, frames, nb, o, floor, i, s, f);
        if (fit == Fit::queued) {
          if (s.lanes.queued == s.lanes.width) run_queued();
          continue;
        }
        p.crease[i] = fit == Fit::crease;
      }
      store(i, f);
    }
    if (s.lanes.queued > 0) run_queued();
  });
  // The median of the finite residuals, in place (the vector is not needed afterwards).
  double* const r = p.residual.data();
  std::ptrdiff_t finite = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    p.crease_points += p.crease[i];
    if (std::isfinite(r[i])) r[finite++] = r[i];
  }
  p.unfitted = static_cast<int>(n - finite);
  if (finite > 0) {
    std::nth_element(r, r + finite / 2, r + finite);
    p.median_residual = r[finite / 2];
  }
  p.residual = Eigen::VectorXd();
  return p;
}

void validate(const SmoothOptions& o) {
  const auto fail = [](const std::string& what) { throw InvalidInput("smooth: " + what); };
  if (o.iterations < 0) fail("iterations must be >= 0, got " + std::to_string(o.iterations));
  if (!(o.min_noise_fall > 0.0 && o.min_noise_fall <= 1.0))
    fail("min_noise_fall must be in (0, 1]");
  if (o.rings < 0) fail("rings must be >= 0, got " + std::to_string(o.rings));
  if (o.neighbours < 0 || o.neighbours > kMaxNeighbourhoodSize)
    fail("neighbours must be in [0, " + std::to_string(kMaxNeighbourhoodSize) + "]");
  if (o.degree < 1 || o.degree > 4)
    fail("degree must be in [1, 4], got " + std::to_string(o.degree));
  if (!(o.crease_angle > 0.0 && o.crease_angle < 3.14159265358979))
    fail("crease_angle must be in (0, pi) radians");
}

void check_cancel(const Execution& e, int pass) {
  if (e.cancel != nullptr && e.cancel->load())
    throw Cancelled("smooth: cancelled before pass " + std::to_string(pass + 1));
}

/// Turns each normal to the majority side of `reference` (rows compared where both are finite).
void to_side_of(NormalsRef reference, RowMatrixX3d& N) {
  std::int64_t along = 0, against = 0;
  for (Eigen::Index i = 0; i < N.rows(); ++i) {
    const double d = N.row(i).dot(reference.row(i));
    along += d > 0.0;
    against += d < 0.0;
  }
  if (against > along) N = -N;
}

/// The result of a pass as the smoothing's result (the pass is not needed after).
void keep(Pass&& p, SmoothResult& out) {
  out.V = std::move(p.V);
  out.N = result_normals(std::move(p.N), p.fitted);
  out.crease = std::move(p.crease);
  out.crease_points = p.crease_points;
  out.unfitted = p.unfitted;
}

/// The passes over `V` from `frames` (unit rows, NaN: not moved) with the neighbourhoods of `nb`,
/// `scale` the mean edge length or spacing. Pass t fits P_t (measuring its noise r_t) and gives
/// P_t+1 with its normals. Automatic stop: P_t is kept while r_t <= min_noise_fall x r_t-1; the
/// first P_t that is not stops the passes with P_t-1 (P_0, the input, but for the first pass's
/// outliers, which are moved whatever the noise). Held while a pass runs: the kept result, the
/// pass's input P_t with its normals (its frames) and its output.
SmoothResult run(PositionsRef V, RowMatrixX3d frames, const Neighbours& nb, const SmoothOptions& o,
                 double scale, bool refine_frames) {
  const Execution& e = current_execution();
  SmoothResult out;
  out.V = V;
  out.crease = VectorXu8::Zero(V.rows());
  const bool automatic = o.iterations == 0;
  const int passes = automatic ? kMaxSmoothIterations + 1 : o.iterations;
  if (refine_frames) {
    // Noisy input: Max's normals tilt with the faces (beyond 45 degrees under noise of an edge),
    // and a quadric over a tilted frame fits the surface badly; the first pass then runs in the
    // frame of a first fit's normals (the recommended jets' second fit, recommended.h).
    frames = run_pass(V, frames, nb, o, scale).N;
  }
  Pass next;  // the last pass: P_t+1 and its normals, the frames of the next pass
  for (int t = 0; t < passes; ++t) {
    check_cancel(e, t);
    if (e.progress) e.progress({"smooth", static_cast<double>(t) / passes});
    Pass p = t == 0 ? run_pass(V, frames, nb, o, scale) : run_pass(next.V, next.N, nb, o, scale);
    const double noise = p.median_residual / scale;
    if (t == 0) {
      frames = RowMatrixX3d();  // p.N from now on
      out.N = result_normals(p.N, p.fitted);
      out.unfitted = p.unfitted;
      for (const char c : p.outlier) out.outliers_moved += c;
      if (automatic) {
        // The outliers move at once; the rest once the next pass shows the noise fell.
        for (Eigen::Index i = 0; i < V.rows(); ++i) {
          if (p.outlier[static_cast<std::size_t>(i)]) out.V.row(i) = p.V.row(i);
        }
      }
    } else if (automatic) {
      if (!(noise <= o.min_noise_fall * out.noise.back())) break;
      keep(std::move(next), out);  // P_t is kept
      out.iterations = t;
    }
    out.noise.push_back(noise);
    next = std::move(p);
  }
  if (!automatic) {
    keep(std::move(next), out);
    out.iterations = passes;
  }
  if (e.progress) e.progress({"smooth", 1.0});
  return out;
}

/// Max's normals of the mesh's faces (unit; NaN at vertices in no face).
RowMatrixX3d face_normals(const PreparedMesh& mesh) {
  return detail::vertex_normals_from(mesh.V(), mesh.F(), *detail::incidence(mesh),
                                     NormalWeighting::max, 0);
}

SmoothResult smooth_mesh(const PreparedMesh& mesh, const SmoothOptions& o) {
  const double h = mesh.mean_edge_length();
  std::shared_ptr<const Neighbourhoods> one = detail::one_ring(mesh);
  const RecommendedPlan plan = recommended_plan(mesh.with_normals(std::nullopt));
  RowMatrixX3d max = face_normals(mesh);
  // The passes need neither the incidence nor (but for the crease sides) the 1-ring: their
  // memory goes to the passes' arrays (it is built again if the mesh's owner asks for it).
  detail::PreparedAccess::release_incidence(mesh);
  const int rings = o.rings > 0 ? o.rings : plan.rings > 1 ? plan.jet_rings : kCleanRings;
  const PackedRings packed = gathered_rings(*one, rings);
  if (!o.keep_creases) one.reset();
  Neighbours nb;
  nb.one_ring = one.get();
  nb.rings = &packed;
  // Without keep_creases the input's normals are the first frames only (no copy kept).
  nb.sides_of = o.keep_creases ? &max : nullptr;
  SmoothResult out = run(mesh.V(), o.keep_creases ? RowMatrixX3d(max) : std::move(max), nb, o, h,
                         plan.jet_iterations > 1);
  out.rings = rings;
  if (const auto N = mesh.normals()) to_side_of(*N, out.N);
  return out;
}

SmoothResult smooth_cloud(const PreparedMesh& cloud, const SmoothOptions& o) {
  const PositionsRef& V = cloud.V();
  int k = o.neighbours;
  Neighbourhoods lists = nearest_neighbours(V, k > 0 ? k : kCloudNeighbours);
  const double spacing = mean_spacing(V, lists);
  RowMatrixX3d frames = pca_normals(V, lists);
  orient_normals_mst(V, lists, frames);
  Neighbours nb;
  nb.lists = &lists;
  nb.oriented = false;
  const RowMatrixX3d input_frames = frames;
  nb.sides_of = &input_frames;
  if (k == 0) {
    // The noise of the 16-neighbour fits decides the neighbourhood, as in the cloud default.
    SmoothOptions measure = o;
    measure.iterations = 1;
    const Pass p = run_pass(V, frames, nb, measure, spacing);
    k = p.median_residual / spacing > kCloudNoisy ? kCloudNoisyNeighbours : kCloudNeighbours;
    if (k != kCloudNeighbours) lists = nearest_neighbours(V, k);
  }
  SmoothResult out = run(V, std::move(frames), nb, o, spacing, false);
  out.neighbours = k;
  if (const auto N = cloud.normals()) to_side_of(*N, out.N);
  return out;
}

}  // namespace

SmoothResult smooth(const PreparedMesh& mesh, const SmoothOptions& options) {
  const ExecutionScope scope(options.execution);
  validate(options);
  if (mesh.vertex_count() == 0) return {};
  return mesh.face_count() == 0 ? smooth_cloud(mesh, options) : smooth_mesh(mesh, options);
}

SmoothResult smooth(const Mesh& mesh, const SmoothOptions& options) {
  const ExecutionScope scope(options.execution);
  validate(options);
  return smooth(PreparedMesh(mesh), options);
}

}  // namespace focal
