#include "focal/normals/cloud_normals.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

#include "core/parallel.h"
#include "focal/core/error.h"
#include "focal/core/execution.h"
#include "focal/normals/jets.h"
#include "normals/cloud_jets.h"
#include "normals/jet_normals_from.h"
#include "normals/winding_orientation.h"

namespace focal {
namespace {

// The extreme-point vote of orient_normals_mst: the share of a component's points that vote per
// direction (at most kExtremeMost), and how decisive the vote must be to overrule the seed.
constexpr double kExtremeShare = 0.01;
constexpr double kExtremeMost = 50.0;
constexpr double kDecisiveVote = 0.5;

void check_sizes(PositionsRef V, const Neighbourhoods& neighbours, const char* what) {
  if (neighbours.vertex_count() != V.rows()) {
    throw InvalidInput(std::string(what) + ": the neighbourhoods have " +
                       std::to_string(neighbours.vertex_count()) + " points, the cloud " +
                       std::to_string(V.rows()));
  }
}

/// The neighbour graph made symmetric (j in i's list or i in j's) without a second copy of the
/// lists: each point's own list, and beside it the points that list it but are not in its list
/// (kNN lists are mostly mutual, so these are few; both directions of every edge held as a
/// second, sorted copy would cost about 1 KB a point with 64 neighbours). A point's neighbours
/// come in another order than sorted, and twice where a list repeats an entry: the tree takes
/// each point's best offer, the same whatever the order or repeats of the offers. `p`: null,
/// or the lists are a permuted copy's (copy row j is the cloud's row p->order[j]) and the graph
/// is over the cloud's own rows.
class SymmetricGraph {
 public:
  SymmetricGraph(const Neighbourhoods& lists, const detail::RowPermutation* p, int threads)
      : lists_(lists), p_(p) {
    const int n = lists.vertex_count();
    // Per list entry r -> e: whether the edge comes back (r in e's list); each list's own
    // entries (in parallel).
    std::vector<char> back(static_cast<std::size_t>(lists.indices.size()), 0);
    detail::parallel_for(n, threads, [&](std::int64_t r64) {
      const int r = static_cast<int>(r64);
      for (int k = lists.offsets[r]; k < lists.offsets[r + 1]; ++k)
        back[static_cast<std::size_t>(k)] = lists_back(lists, r, k - lists.offsets[r]) ? 1 : 0;
    });
    collect_one_way(back);
  }

  /// Calls f(j) for each neighbour j of the cloud's row i.
  template <class F>
  void each(int i, F&& f) const {
    const int r = p_ ? p_->position[static_cast<std::size_t>(i)] : i;
    for (const int* j = lists_.begin(r); j != lists_.end(r); ++j) f(own(*j));
    for (int k = extra_offsets_[i]; k < extra_offsets_[i + 1]; ++k)
      f(extra_[static_cast<std::size_t>(k)]);
  }

 private:
  /// Whether r is in the list of e, entry `at` of r's list. Sorted by distance, two mutual
  /// neighbours mostly stand at about the same place in each other's lists: looked for near
  /// `at` first, then counted through the whole list without a branch (it runs in vector lanes).
  static bool lists_back(const Neighbourhoods& lists, int r, int at) {
    const int e = lists.indices[lists.offsets[r] + at];
    const int* list = lists.begin(e);
    const int size = lists.size(e);
    for (int m = std::max(0, at - kNearPlace); m < std::min(size, at + kNearPlace + 1); ++m) {
      if (list[m] == r) return true;
    }
    int hits = 0;
    for (int m = 0; m < size; ++m) hits += list[m] == r ? 1 : 0;
    return hits > 0;
  }
  static constexpr int kNearPlace = 3;

  /// The one-way edges (`back` 0) listed at their far ends, in list order (serial: the same
  /// graph for any thread count).
  void collect_one_way(const std::vector<char>& back) {
    const Neighbourhoods& lists = lists_;
    const int n = lists.vertex_count();
    extra_offsets_.assign(static_cast<std::size_t>(n) + 1, 0);
    for (int r = 0; r < n; ++r) {
      for (int k = lists.offsets[r]; k < lists.offsets[r + 1]; ++k) {
        if (!back[static_cast<std::size_t>(k)]) ++extra_offsets_[own(lists.indices[k]) + 1];
      }
    }
    for (int i = 0; i < n; ++i) extra_offsets_[i + 1] += extra_offsets_[i];
    extra_.resize(static_cast<std::size_t>(extra_offsets_[n]));
    std::vector<int> fill(extra_offsets_.begin(), extra_offsets_.end() - 1);
    for (int r = 0; r < n; ++r) {
      for (int k = lists.offsets[r]; k < lists.offsets[r + 1]; ++k) {
        if (!back[static_cast<std::size_t>(k)])
          extra_[static_cast<std::size_t>(fill[own(lists.indices[k])]++)] = own(r);
      }
    }
  }

  /// The cloud's row of the lists' row r.
  int own(int r) const { return p_ ? p_->order[static_cast<std::size_t>(r)] : r; }

  const Neighbourhoods& lists_;
  const detail::RowPermutation* p_;
  std::vector<int> extra_offsets_;  ///< per cloud row, into extra_
  std::vector<int> extra_;          ///< the one-way edges' near ends, cloud rows
};

/// Prim's frontier: the points offered an edge to the tree and not in it yet, smallest
/// (weight, point) first, with the best (weight, parent) offered to each. An indexed binary heap
/// with decrease-key: each point is in it once, where a heap of every offer pops the same
/// points in the same order (an offer of a point is popped first only if it is that point's
/// best, and two points never tie on (weight, point)) but holds 24 B per offer and pops the
/// stale ones too.
class Frontier {
 public:
  explicit Frontier(int n)
      : best_(static_cast<std::size_t>(n), {std::numeric_limits<double>::infinity(), -1}),
        slot_(static_cast<std::size_t>(n), -1) {}

  bool empty() const { return heap_.empty(); }

  /// Offers point i the edge to `parent` of this weight; kept if better than its best so far
  /// ((weight, parent) order, as offers were compared before).
  void offer(int i, double weight, int parent) {
    const std::pair<double, int> o(weight, parent);
    if (!(o < best_[static_cast<std::size_t>(i)])) return;
    best_[static_cast<std::size_t>(i)] = o;
    if (slot_[static_cast<std::size_t>(i)] < 0) {
      slot_[static_cast<std::size_t>(i)] = static_cast<int>(heap_.size());
      heap_.push_back(i);
    }
    rise(static_cast<std::size_t>(slot_[static_cast<std::size_t>(i)]));
  }

  /// The next point and its parent, out of the frontier.
  std::pair<int, int> pop() {
    const int top = heap_.front();
    move_to(0, heap_.back());
    heap_.pop_back();
    if (!heap_.empty()) sink(0);
    slot_[static_cast<std::size_t>(top)] = -1;
    return {top, best_[static_cast<std::size_t>(top)].second};
  }

 private:
  bool before(int a, int b) const {
    const double wa = best_[static_cast<std::size_t>(a)].first;
    const double wb = best_[static_cast<std::size_t>(b)].first;
    return wa < wb || (wa == wb && a < b);
  }
  void move_to(std::size_t k, int i) {
    heap_[k] = i;
    slot_[static_cast<std::size_t>(i)] = static_cast<int>(k);
  }
  void rise(std::size_t k) {
    const int i = heap_[k];
    while (k > 0 && before(i, heap_[(k - 1) / 2])) {
      move_to(k, heap_[(k - 1) / 2]);
      k = (k - 1) / 2;
    }
    move_to(k, i);
  }
  void sink(std::size_t k) {
    const int i = heap_[k];
    for (;;) {
      std::size_t c = 2 * k + 1;
      if (c >= heap_.size()) break;
      if (c + 1 < heap_.size() && before(heap_[c + 1], heap_[c])) ++c;
      if (!before(heap_[c], i)) break;
      move_to(k, heap_[c]);
      k = c;
    }
    move_to(k, i);
  }

  std::vector<std::pair<double, int>> best_;  ///< per point: its best offer (weight, parent)
  std::vector<int> slot_;                     ///< per point: its place in heap_, -1 if none
  std::vector<int> heap_;
};

/// The extreme points' vote on a component's side (see orient_normals_mst): for each of the six
/// axis directions d, the `count` points of `members` farthest along d (ties by index) add
/// n . d. Returns (sum, sum of |n . d|).
std::pair<double, double> extreme_vote(PositionsRef V, const RowMatrixX3d& N,
                                       std::vector<int> members, std::size_t count) {
  double vote = 0.0, weight = 0.0;
  count = std::min(count, members.size());
  for (int axis = 0; axis < 3; ++axis) {
    for (const double sign : {1.0, -1.0}) {
      const auto farther = [&](int a, int b) {
        const double ta = sign * V(a, axis), tb = sign * V(b, axis);
        return ta > tb || (ta == tb && a < b);
      };
      std::nth_element(members.begin(), members.begin() + static_cast<std::ptrdiff_t>(count) - 1,
                       members.end(), farther);
      for (std::size_t k = 0; k < count; ++k) {
        const double t = sign * N(members[k], axis);
        vote += t;
        weight += std::abs(t);
      }
    }
  }
  return {vote, weight};
}

/// The z components of the normals of the `count` highest points of `members` (ties by index).
double highest_vote(PositionsRef V, const RowMatrixX3d& N, std::vector<int> members,
                    std::size_t count) {
  count = std::min(count, members.size());
  std::nth_element(
      members.begin(), members.begin() + static_cast<std::ptrdiff_t>(count) - 1, members.end(),
      [&](int a, int b) { return V(a, 2) > V(b, 2) || (V(a, 2) == V(b, 2) && a < b); });
  double vote = 0.0;
  for (std::size_t k = 0; k < count; ++k) vote += N(members[k], 2);
  return vote;
}

}  // namespace

RowMatrixX3d pca_normals(PositionsRef V, const Neighbourhoods& neighbours) {
  check_sizes(V, neighbours, "pca_normals");
  RowMatrixX3d N(V.rows(), 3);
  detail::parallel_for(V.rows(), 0, [&](std::int64_t i64) {
    const int i = static_cast<int>(i64);
    N.row(i).setConstant(std::numeric_limits<double>::quiet_NaN());
    if (neighbours.size(i) < 2 || !V.row(i).allFinite()) return;
    // Offsets from the point itself (not the centroid first): the covariance about the mean is
    // the same, and the small offsets keep it accurate far from the origin.
    const Eigen::RowVector3d p = V.row(i);
    Eigen::RowVector3d sum = Eigen::RowVector3d::Zero();
    Eigen::Matrix3d moment = Eigen::Matrix3d::Zero();
    const double count = neighbours.size(i) + 1.0;
    for (const int* j = neighbours.begin(i); j != neighbours.end(i); ++j) {
      const Eigen::RowVector3d q = V.row(*j) - p;
      sum += q;
      moment += q.transpose() * q;
    }
    const Eigen::Matrix3d covariance = moment / count - sum.transpose() * sum / (count * count);
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
    eig.computeDirect(covariance);
    const Eigen::Vector3d n = eig.eigenvectors().col(0);  // of the smallest eigenvalue
    if (n.allFinite() && n.norm() > 0.0) N.row(i) = n.normalized().transpose();
  });
  return N;
}

int orient_normals_mst(PositionsRef V, const Neighbourhoods& neighbours, RowMatrixX3d& N) {
  return detail::orient_normals_mst(V, neighbours, N, 1);
}

namespace {

/// orient_normals_mst over the symmetric neighbour graph `graph` of V.
int orient_over_graph(PositionsRef V, const SymmetricGraph& graph, RowMatrixX3d& N) {
  const auto n = static_cast<int>(V.rows());
  std::vector<char> usable(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) usable[i] = N.row(i).allFinite() && V.row(i).allFinite();
  // Seeds in order of falling z (ties by index): the first unvisited point of a component is
  // its highest.
  std::vector<int> order(static_cast<std::size_t>(n));
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return V(a, 2) > V(b, 2); });
  std::vector<char> done(static_cast<std::size_t>(n), 0);
  Frontier frontier(n);
  int components = 0;
  std::vector<int> component(static_cast<std::size_t>(n), -1);
  for (const int seed : order) {
    if (done[static_cast<std::size_t>(seed)] || !usable[seed]) continue;
    const int label = components++;
    if (N(seed, 2) < 0.0) N.row(seed) *= -1.0;
    frontier.offer(seed, 0.0, seed);
    while (!frontier.empty()) {
      // Named variables, not a structured binding: the lambda below captures i.
      const std::pair<int, int> popped = frontier.pop();
      const int i = popped.first;
      const int parent = popped.second;
      done[static_cast<std::size_t>(i)] = 1;
      component[static_cast<std::size_t>(i)] = label;
      if (N.row(i).dot(N.row(parent)) < 0.0) N.row(i) *= -1.0;
      graph.each(i, [&](int j) {
        if (done[static_cast<std::size_t>(j)] || !usable[j]) return;
        frontier.offer(j, 1.0 - std::abs(N.row(i).dot(N.row(j))), i);
      });
    }
  }
  // The side of each component: the seed alone (its highest point) may be an outlier or a
  // point whose normal is nearly horizontal, so the extreme points vote (see the header).
  std::vector<std::vector<int>> members(static_cast<std::size_t>(components));
  for (int i = 0; i < n; ++i) {
    if (component[i] >= 0) members[static_cast<std::size_t>(component[i])].push_back(i);
  }
  for (const std::vector<int>& m : members) {
    const auto count = static_cast<std::size_t>(
        std::clamp(std::ceil(kExtremeShare * static_cast<double>(m.size())), 1.0, kExtremeMost));
    const auto [vote, weight] = extreme_vote(V, N, m, count);
    // Not decisive (an open, symmetric surface): the highest points vote on +z instead.
    const bool flip =
        std::abs(vote) > kDecisiveVote * weight ? vote < 0.0 : highest_vote(V, N, m, count) < 0.0;
    if (flip) {
      for (const int i : m) N.row(i) *= -1.0;
    }
  }
  return components;
}

}  // namespace

namespace {

/// Tells the verbose log (Execution::info) what the global orientation did, and `decided`
/// (when not null) whether its field decided.
void tell(const detail::WindingOrientationReport& r, bool* decided) {
  if (decided) *decided = r.decided;
  const Execution& execution = current_execution();
  if (!execution.info) return;
  const std::string verdict =
      r.decided ? std::to_string(r.flipped) + " normals turned (" + std::to_string(r.jump_turned) +
                      " turns by the jumps across points)"
      : r.residual_after <= detail::WindingOrientationOptions{}.closed_residual
          ? "the tree's signs kept (the field's fit them hardly better)"
          : "the tree's signs kept (the field does not decide: an open or noisy cloud)";
  char line[120];
  std::snprintf(line, sizeof line,
                "global orientation: winding-number residual %.3f -> %.3f: ", r.residual_before,
                r.residual_after);
  execution.info(line + verdict);
}

}  // namespace

int detail::orient_normals_mst(PositionsRef V, const Neighbourhoods& neighbours, RowMatrixX3d& N,
                               int threads, const CloudCopy* copy_of, bool global, bool* decided) {
  check_sizes(V, neighbours, "orient_normals_mst");
  if (N.rows() != V.rows()) throw InvalidInput("orient_normals_mst: N does not have #V rows");
  if (!copy_of) {
    const int components = orient_over_graph(V, SymmetricGraph(neighbours, nullptr, threads), N);
    if (global) orient_after_tree(V, neighbours, N, threads, nullptr, decided);
    return components;
  }
  // The tree over the cloud in its own order, whose ties it breaks by row: the graph renamed
  // from the copy's lists, N taken back (and the copy's N let go meanwhile), the cloud's own
  // positions.
  const RowPermutation& p = copy_of->permutation;
  RowMatrixX3d own;
  int components = 0;
  {
    const SymmetricGraph graph(neighbours, &p, threads);
    own = detail::rows_from(N, p.position, threads);
    N = RowMatrixX3d();
    components = orient_over_graph(copy_of->cloud, graph, own);
  }
  N = detail::rows_from(own, p.order, threads);
  own = RowMatrixX3d();  // not held through the global step, whose peak it raised by 24 B a point
  if (global) orient_after_tree(V, neighbours, N, threads, copy_of, decided);
  return components;
}

void detail::orient_after_tree(PositionsRef V, const Neighbourhoods& neighbours, RowMatrixX3d& N,
                               int threads, const CloudCopy* copy_of, bool* decided) {
  // The areas from the lists as given (sorted by distance); a normal's sign does not enter them.
  Eigen::VectorXd area = detail::patch_areas(V, neighbours, N, threads);
  if (!copy_of) {
    tell(detail::orient_by_winding(V, neighbours, nullptr, area, N, threads), decided);
    return;
  }
  // On the cloud in its own order, as the tree: the winding number's segments read the copy's
  // lists renamed.
  const RowPermutation& p = copy_of->permutation;
  area = detail::rows_from(area, p.position, threads);
  RowMatrixX3d own = detail::rows_from(N, p.position, threads);
  N = RowMatrixX3d();
  tell(detail::orient_by_winding(copy_of->cloud, neighbours, &p.order, area, own, threads),
       decided);
  N = detail::rows_from(own, p.order, threads);
}

int orient_normals_global(PositionsRef V, const Neighbourhoods& neighbours, RowMatrixX3d& N) {
  check_sizes(V, neighbours, "orient_normals_global");
  if (N.rows() != V.rows()) throw InvalidInput("orient_normals_global: N does not have #V rows");
  return detail::orient_by_winding(V, neighbours, nullptr, detail::patch_areas(V, neighbours, N, 0),
                                   N, 0)
      .flipped;
}

void orient_towards_viewpoint(PositionsRef V, const Eigen::Vector3d& viewpoint, RowMatrixX3d& N) {
  if (N.rows() != V.rows()) throw InvalidInput("orient_towards_viewpoint: N does not have #V rows");
  if (!viewpoint.allFinite()) throw InvalidInput("orient_towards_viewpoint: viewpoint not finite");
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    if ((viewpoint.transpose() - V.row(i)).dot(N.row(i)) < 0.0) N.row(i) *= -1.0;
  }
}

namespace {

void check_jet_options(PositionsRef V, const Neighbourhoods& neighbours,
                       const CloudNormalOptions& options) {
  check_sizes(V, neighbours, "cloud_normals");
  if (options.orientation == CloudOrientation::viewpoint && !options.viewpoint) {
    throw InvalidInput("cloud_normals: orientation viewpoint needs a viewpoint");
  }
  if (options.orientation == CloudOrientation::global && options.viewpoint) {
    throw InvalidInput("cloud_normals: orientation global and a viewpoint conflict");
  }
  if (options.jet_degree < 1 || options.jet_degree > 4) {
    throw InvalidInput("cloud_normals: jet_degree must be in [1, 4], got " +
                       std::to_string(options.jet_degree));
  }
}

/// Orients PCA normals N as `options` say (no viewpoint in orient_sided_jets' calls).
/// Returns whether the global orientation ran and its field decided.
bool orient(PositionsRef V, const Neighbourhoods& neighbours, const CloudNormalOptions& options,
            RowMatrixX3d& N, const detail::CloudCopy* copy_of) {
  bool decided = false;
  if (options.viewpoint) {
    orient_towards_viewpoint(V, *options.viewpoint, N);
  } else {
    detail::orient_normals_mst(V, neighbours, N, 0, copy_of,
                               options.orientation == CloudOrientation::global, &decided);
  }
  return decided;
}

/// Where the global orientation decided: the jets' sides by the field of the oriented PCA
/// normals N (detail::side_by_jumps), on the cloud in its own order as the orientation was; each
/// field let go once its copy in that order is made (this is the global plan's peak of memory).
void side_jets(PositionsRef V, const Neighbourhoods& neighbours, RowMatrixX3d N, RowMatrixX3d& jets,
               const detail::CloudCopy* copy_of) {
  Eigen::VectorXd area = detail::patch_areas(V, neighbours, N, 0);
  if (!copy_of) {
    detail::side_by_jumps(V, area, N, jets, 0);
    return;
  }
  const auto& p = copy_of->permutation;
  area = detail::rows_from(area, p.position, 0);
  N = detail::rows_from(N, p.position, 0);
  RowMatrixX3d own = detail::rows_from(jets, p.position, 0);
  jets = RowMatrixX3d();
  detail::side_by_jumps(copy_of->cloud, area, N, own, 0);
  N = RowMatrixX3d();
  jets = detail::rows_from(own, p.order, 0);
}

/// Whether cloud_jets_sided turns point i's PCA normal `n` over: towards its row of `side`.
bool turned_to_side(const Eigen::RowVector3d& n, NormalsRef side, Eigen::Index i) {
  return n.dot(side.row(i)) < 0.0;
}

/// The jets (CloudNormalMethod::jet) from oriented PCA normals N. `copy_of` as
/// detail::orient_normals_mst.
JetNormals jets_of(PositionsRef V, const Neighbourhoods& neighbours,
                   const CloudNormalOptions& options, NormalsRef N,
                   const detail::CloudCopy* copy_of) {
  // The neighbourhoods play the 1-ring of a mesh (rings = 1): the jet of each point is fitted
  // to exactly its neighbours and itself, in the frame of its oriented PCA normal.
  const JetOptions jet{.rings = 1, .degree = options.jet_degree, .iterations = 2};
  return detail::jet_normals_from(V, neighbours, N, jet, detail::SimdIsa::best,
                                  copy_of ? &copy_of->permutation.order : nullptr);
}

/// The jets (or, for CloudNormalMethod::pca, nothing more) from oriented PCA normals N.
JetNormals jets_from_start(PositionsRef V, const Neighbourhoods& neighbours,
                           const CloudNormalOptions& options, RowMatrixX3d N,
                           const detail::CloudCopy* copy_of) {
  if (options.method == CloudNormalMethod::pca) return {std::move(N), {}, {}};
  return jets_of(V, neighbours, options, N, copy_of);
}

}  // namespace

JetNormals detail::cloud_jets(PositionsRef V, const Neighbourhoods& neighbours,
                              const CloudNormalOptions& options, const CloudCopy* copy_of,
                              RowMatrixX3d* start) {
  check_jet_options(V, neighbours, options);
  RowMatrixX3d N = pca_normals(V, neighbours);
  const bool decided = orient(V, neighbours, options, N, copy_of);
  if (start && options.method == CloudNormalMethod::jet) *start = N;
  if (!decided || options.method == CloudNormalMethod::pca) {
    return jets_from_start(V, neighbours, options, std::move(N), copy_of);
  }
  JetNormals jets = jets_of(V, neighbours, options, N, copy_of);
  side_jets(V, neighbours, std::move(N), jets.N, copy_of);
  return jets;
}

void detail::orient_jets_globally(PositionsRef V, const Neighbourhoods& neighbours,
                                  const CloudNormalOptions& options, RowMatrixX3d start,
                                  JetNormals& jets, const CloudCopy* copy_of) {
  if (options.method == CloudNormalMethod::pca) {
    orient_after_tree(V, neighbours, jets.N, 0, copy_of, nullptr);
    return;
  }
  bool decided = false;
  orient_after_tree(V, neighbours, start, 0, copy_of, &decided);
  // Not decided: the tree's signs stay, and so do the jets fitted from them.
  if (decided) side_jets(V, neighbours, std::move(start), jets.N, copy_of);
}

JetNormals detail::cloud_jets_sided(PositionsRef V, const Neighbourhoods& neighbours,
                                    const CloudNormalOptions& options, NormalsRef side,
                                    const CloudCopy* copy_of) {
  if (options.viewpoint) return cloud_jets(V, neighbours, options, copy_of);
  check_jet_options(V, neighbours, options);
  if (side.rows() != V.rows()) throw InvalidInput("cloud_jets_sided: side does not have #V rows");
  RowMatrixX3d N = pca_normals(V, neighbours);
  detail::parallel_for(V.rows(), 0, [&](std::int64_t i) {
    if (turned_to_side(N.row(i), side, i)) N.row(i) *= -1.0;
  });
  return jets_from_start(V, neighbours, options, std::move(N), copy_of);
}

void detail::orient_sided_jets(PositionsRef V, const Neighbourhoods& neighbours,
                               const CloudNormalOptions& options, NormalsRef side, JetNormals& jets,
                               const CloudCopy* copy_of) {
  if (options.viewpoint) return;  // cloud_jets_sided was cloud_jets
  // The PCA normals again (cheap, parallel) rather than kept through the plan: 24 B a point.
  const RowMatrixX3d pca = pca_normals(V, neighbours);
  RowMatrixX3d mst = pca;
  const bool decided = orient(V, neighbours, options, mst, copy_of);
  detail::parallel_for(V.rows(), 0, [&](std::int64_t i) {
    // A unit row flipped by the MST is exactly -pca; NaN rows (no normal) never compare equal.
    const bool by_mst = (mst.row(i).array() == -pca.row(i).array()).all();
    // Only finite jets: an undefined one is the same NaN row whatever its start's sign.
    if (by_mst != turned_to_side(pca.row(i), side, i) && jets.N.row(i).allFinite()) {
      jets.N.row(i) *= -1.0;
    }
  });
  if (decided && options.method == CloudNormalMethod::jet)
    side_jets(V, neighbours, std::move(mst), jets.N, copy_of);
}

RowMatrixX3d cloud_normals(PositionsRef V, const Neighbourhoods& neighbours,
                           const CloudNormalOptions& options) {
  return detail::cloud_jets(V, neighbours, options).N;
}

}  // namespace focal
