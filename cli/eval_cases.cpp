// The cases of `focal eval` (eval_cases.h): today's suite (paper Fig. 10's noise models) and the
// hard cases, each an analytic surface, a triangulation and a perturbation.
#include "eval_cases.h"

#include <cctype>
#include <sstream>

#include "focal/core/error.h"
#include "focal/io/mesh_io.h"

namespace focal::cli::eval {
namespace {

std::string percent(double fraction) {
  std::ostringstream s;
  s << fraction * 100.0 << "%";
  return s.str();
}

std::string noise_name(const Perturbation& p) {
  std::vector<std::string> parts;
  if (p.vertex_noise > 0) parts.push_back("vertex noise " + percent(p.vertex_noise));
  if (p.normal_noise > 0) parts.push_back("normal noise " + percent(p.normal_noise));
  if (p.outlier_normals > 0) parts.push_back(percent(p.outlier_normals) + " outlier normals");
  if (p.spikes > 0) parts.push_back(percent(p.spikes) + " spikes");
  if (parts.empty()) return "clean";
  std::string out = parts[0];
  for (std::size_t k = 1; k < parts.size(); ++k) out += " + " + parts[k];
  return out;
}

/// An analytic surface of the suite, `vertices` (0: --vertices) and `shape` adjusting the options.
std::function<AnalyticSurface(const EvalFlags&)> surface_maker(
    SurfaceKind kind, Triangulation triangulation, int vertices = 0,
    std::function<void(SurfaceOptions&)> shape = {}) {
  return [=](const EvalFlags& f) {
    SurfaceOptions o;
    o.kind = kind;
    o.triangulation = triangulation;
    o.target_vertices = vertices > 0 ? vertices : f.vertices;
    o.seed = f.seed;
    if (shape) shape(o);
    return make_surface(o);
  };
}

std::string triangulation_name(Triangulation t) {
  return t == Triangulation::regular ? "regular" : "irregular";
}

/// Today's suite: every surface, regular and irregular, clean and with the paper's Fig. 10 noise
/// (10% vertex noise with the exact normals; 5% normal noise on exact positions).
std::vector<Case> standard_cases() {
  std::vector<Case> out;
  const std::pair<Perturbation, const char*> noises[] = {{{}, "clean"},
                                                         {{.vertex_noise = 0.1}, "vertex-noise"},
                                                         {{.normal_noise = 0.05}, "normal-noise"}};
  for (SurfaceKind k : all_surfaces()) {
    for (auto t : {Triangulation::regular, Triangulation::irregular}) {
      for (const auto& [p, slug] : noises) {
        const std::string surface(surface_name(k));
        out.push_back({"standard", surface, triangulation_name(t), noise_name(p),
                       surface_maker(k, t), p, false,
                       surface + "-" + triangulation_name(t) + "-" + slug});
      }
    }
  }
  return out;
}

/// The hard cases of issue 16 (docs/ACCURACY.md, "Hard cases"): meshes and data as real files
/// have them, each category on several surfaces so that no choice is tuned to one.
std::vector<Case> hard_cases() {
  using enum SurfaceKind;
  constexpr auto regular = Triangulation::regular, irregular = Triangulation::irregular;
  std::vector<Case> out;
  const auto add = [&out](const std::string& category, SurfaceKind kind, const std::string& mesh,
                          std::function<AnalyticSurface(const EvalFlags&)> make,
                          Perturbation p = {}, bool band = false) {
    const std::string surface(surface_name(kind));
    out.push_back({category, surface, mesh, noise_name(p), std::move(make), p, band,
                   slug_of(category + " " + surface + " " + mesh + " " + noise_name(p))});
  };
  const auto aspect = [](double a) { return [a](SurfaceOptions& o) { o.aspect = a; }; };
  // Strips: CAD exports of surfaces of revolution (along the cylinder's axis; lat-long rows
  // with thin pole fans on the sphere and the ellipsoid), and thin cells across curvature.
  add("anisotropic", cylinder, "strips 8:1 along the axis",
      surface_maker(cylinder, regular, 0, aspect(1.0 / 8)));
  add("anisotropic", sphere, "lat-long 8:1 with pole fans",
      surface_maker(sphere, regular, 0, aspect(8)));
  add("anisotropic", ellipsoid, "lat-long 1:5 with pole fans",
      surface_maker(ellipsoid, regular, 0, aspect(1.0 / 5)));
  add("anisotropic", torus, "strips 8:1", surface_maker(torus, regular, 0, aspect(8)));
  add("anisotropic", saddle, "strips 20:1", surface_maker(saddle, regular, 0, aspect(20)));
  add("anisotropic", helix_tube, "strips 1:5", surface_maker(helix_tube, regular, 0, aspect(0.2)));
  const auto graded = [](SurfaceOptions& o) { o.grading = 10; };
  for (SurfaceKind k : {ellipsoid, torus, saddle, pear})
    add("graded density", k, "irregular with density 10:1", surface_maker(k, irregular, 0, graded));
  for (SurfaceKind k : {torus, ellipsoid, pear, helix_tube, monkey_saddle})
    add("coarse", k, "irregular with 850 vertices", surface_maker(k, irregular, 850));
  add("coarse", ellipsoid, "regular with 850 vertices", surface_maker(ellipsoid, regular, 850));
  for (const auto& [k, a] : {std::pair{sphere, 0.5},
                             {torus, 0.3},
                             {torus, 0.5},
                             {ellipsoid, 0.3},
                             {pear, 0.5},
                             {saddle, 0.3}})
    add("strong vertex noise", k, "irregular", surface_maker(k, irregular), {.vertex_noise = a});
  for (SurfaceKind k : {sphere, torus, ellipsoid, monkey_saddle})
    add("strong normal noise", k, "irregular", surface_maker(k, irregular), {.normal_noise = 0.3});
  for (SurfaceKind k : {torus, ellipsoid, pear})
    add("outliers", k, "irregular", surface_maker(k, irregular), {.outlier_normals = 0.02});
  for (SurfaceKind k : {sphere, torus, saddle})
    add("outliers", k, "irregular", surface_maker(k, irregular), {.spikes = 0.005});
  add("outliers", helix_tube, "irregular", surface_maker(helix_tube, irregular),
      {.outlier_normals = 0.02, .spikes = 0.005});
  for (SurfaceKind k : {saddle, monkey_saddle, cylinder, helix_tube})
    add("near boundaries", k, "irregular scored at rings 1-2", surface_maker(k, irregular), {},
        true);
  add("near boundaries", saddle, "irregular scored at rings 1-2", surface_maker(saddle, irregular),
      {.vertex_noise = 0.1}, true);
  const auto capped = [](const EvalFlags& f) { return make_capped_cylinder(1.0, 2.0, f.vertices); };
  for (const Perturbation& p :
       {Perturbation{}, Perturbation{.vertex_noise = 0.1}, Perturbation{.normal_noise = 0.05}}) {
    out.push_back({"creases", "capped-cylinder", "regular with rims not scored", noise_name(p),
                   capped, p, false, slug_of("creases capped-cylinder " + noise_name(p))});
  }
  return out;
}

}  // namespace

std::string slug_of(const std::string& name) {
  std::string out;
  for (char ch : name) {
    if (std::isalnum(static_cast<unsigned char>(ch))) {
      out += static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    } else if (!out.empty() && out.back() != '-') {
      out += '-';
    }
  }
  while (!out.empty() && out.back() == '-') out.pop_back();
  return out;
}

std::vector<Case> cases(Suite suite) {
  std::vector<Case> out;
  if (suite != Suite::hard) out = standard_cases();
  if (suite != Suite::standard) {
    std::vector<Case> hard = hard_cases();
    out.insert(out.end(), hard.begin(), hard.end());
  }
  return out;
}

AnalyticSurface make_case(const Case& c, const EvalFlags& f) {
  AnalyticSurface s = c.make(f);
  const Perturbation& p = c.perturbation;
  if (p.vertex_noise > 0) add_position_noise(s.mesh, p.vertex_noise, f.seed + 1);
  if (p.normal_noise > 0) add_normal_noise(s.mesh, p.normal_noise, f.seed + 2);
  if (p.outlier_normals > 0) add_outlier_normals(s.mesh, p.outlier_normals, f.seed + 3);
  if (p.spikes > 0) add_spikes(s.mesh, p.spikes, kSpikeHeight, f.seed + 4);
  return s;
}

VectorXu8 scored_vertices(const Case& c, const AnalyticSurface& s) {
  const int n = static_cast<int>(s.mesh.V.rows());
  return c.boundary_band ? boundary_band_mask(n, s.mesh.F, 1, 2) : interior_mask(n, s.mesh.F);
}

Evaluation evaluate_case(const Case& c, const AnalyticSurface& s, const CurvatureResult& e) {
  Evaluation out = evaluate(s, e);
  if (c.boundary_band) out.interior = evaluate_at(s, e, scored_vertices(c, s));
  return out;
}

std::string case_label(const Case& c) { return c.surface + ", " + c.mesh + ", " + c.noise; }

void make_folder(const std::string& dir) {
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) throw IoError("cannot create folder '" + dir + "': " + error.message());
}

void export_cases(const std::string& dir,
                  const std::vector<std::pair<Case, AnalyticSurface>>& all) {
  make_folder(dir);
  std::vector<std::string> slug, surface, triangulation, noise, category;
  Eigen::VectorXd vertices(static_cast<Eigen::Index>(all.size()));
  for (std::size_t k = 0; k < all.size(); ++k) {
    const auto& [c, s] = all[k];
    export_case(std::filesystem::path(dir) / (c.slug + ".ply"),
                std::filesystem::path(dir) / (c.slug + ".truth.csv"), s, scored_vertices(c, s));
    slug.push_back(c.slug);
    surface.push_back(c.surface);
    triangulation.push_back(c.mesh);
    noise.push_back(c.noise);
    category.push_back(c.category);
    vertices[static_cast<Eigen::Index>(k)] = static_cast<double>(s.mesh.V.rows());
  }
  const std::vector<CsvColumn> columns = {
      {"slug", slug},   {"surface", surface},   {"triangulation", triangulation},
      {"noise", noise}, {"vertices", vertices}, {"category", category}};
  write_csv(std::filesystem::path(dir) / "cases.csv", columns);
}

}  // namespace focal::cli::eval
