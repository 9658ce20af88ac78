#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <system_error>
#include <vector>

#include "commands.h"
#include "focal/io/mesh_io.h"
#include "focal/surfaces/cloud_samples.h"
#include "focal/surfaces/surfaces.h"
#include "paths.h"

namespace focal::cli {
namespace {

struct GenerateFlags {
  std::string surface;
  std::string output;
  std::string truth;
  bool force = false;
  SurfaceOptions options;
  double position_noise = 0.0;
  double normal_noise = 0.0;
  bool cloud = false;  ///< --cloud: point samples without faces (cloud_samples.h)
  double graded = 0.0;
  double outliers = 0.0;
  bool no_normals = false;
};

/// The mesh, or with --cloud the point samples, noise included.
AnalyticSurface make_output(const GenerateFlags& f) {
  if (f.cloud) {
    return sample_cloud({.surface = f.options,
                         .position_noise = f.position_noise,
                         .normal_noise = f.normal_noise,
                         .graded = f.graded,
                         .outliers = f.outliers,
                         .normals = !f.no_normals});
  }
  AnalyticSurface s = make_surface(f.options);
  if (f.position_noise > 0) add_position_noise(s.mesh, f.position_noise, f.options.seed + 1);
  if (f.normal_noise > 0) add_normal_noise(s.mesh, f.normal_noise, f.options.seed + 2);
  if (f.no_normals) s.mesh.N.resize(0, 3);
  return s;
}

/// The exact principal curvatures and directions, one row per vertex.
void write_truth(const std::string& path, const AnalyticSurface& s) {
  std::vector<CsvColumn> columns = {
      {"k1", s.k1}, {"k2", s.k2}, {"H", (s.k1 + s.k2) / 2}, {"K", s.k1.cwiseProduct(s.k2)}};
  const char* axis = "xyz";
  for (int c = 0; c < 3; ++c) columns.push_back({std::string("d1") + axis[c], s.d1.col(c)});
  for (int c = 0; c < 3; ++c) columns.push_back({std::string("d2") + axis[c], s.d2.col(c)});
  write_csv(path, columns);
}

void generate(GenerateFlags& f, const Log& log) {
  f.options.kind = surface_from_name(f.surface);
  AnalyticSurface s;
  {
    Stage stage(log, "generate");
    s = make_output(f);
  }
  write_mesh(f.output, s.mesh);
  if (!f.truth.empty()) {
    try {
      write_truth(f.truth, s);
    } catch (...) {
      // A failed run leaves no output behind, not a mesh without its truth.
      std::error_code ignored;
      std::filesystem::remove(f.output, ignored);
      throw;
    }
  }
  std::printf("wrote %s: %s, %lld vertices, %lld triangles%s\n", f.output.c_str(),
              f.surface.c_str(), static_cast<long long>(s.mesh.V.rows()),
              static_cast<long long>(s.mesh.F.rows()),
              f.truth.empty() ? "" : (", truth in " + f.truth).c_str());
}

}  // namespace

void add_generate_command(CLI::App& app, const Log& log) {
  auto* cmd =
      app.add_subcommand("generate", "Write an analytic test surface and its exact curvature");
  auto f = std::make_shared<GenerateFlags>();
  std::string names;
  std::vector<std::string> known;
  for (auto k : all_surfaces()) {
    names += (names.empty() ? "" : ", ") + std::string(surface_name(k));
    known.emplace_back(surface_name(k));
  }
  // Checked while parsing, so that a misspelt surface is a usage error like any other bad value.
  cmd->add_option("surface", f->surface, "one of: " + names)
      ->required()
      ->check(CLI::IsMember(known));
  cmd->add_option("-o,--output", f->output,
                  "output mesh (.ply .obj .off) or cloud (also .xyz .xyzn), with exact normals")
      ->required();
  cmd->add_option("--truth", f->truth, "also write the exact k1,k2,H,K,d1,d2 per vertex as CSV");
  const std::map<std::string, Triangulation> tri = {{"regular", Triangulation::regular},
                                                    {"irregular", Triangulation::irregular}};
  cmd->add_option("--triangulation", f->options.triangulation, "regular grid or irregular samples")
      ->transform(CLI::CheckedTransformer(tri))
      ->default_str("regular");
  cmd->add_option("--vertices", f->options.target_vertices, "approximate vertex count")
      ->check(CLI::Range(16, 100000000))
      ->default_str("2000");
  cmd->add_option("--seed", f->options.seed, "random seed (irregular sampling, noise)")
      ->default_str("1");
  cmd->add_option("--a", f->options.a, "first shape parameter (0 = the surface's default)");
  cmd->add_option("--b", f->options.b, "second shape parameter");
  cmd->add_option("--c", f->options.c, "third shape parameter");
  cmd->add_option(
         "--position-noise", f->position_noise,
         "move vertices by uniform noise of this amplitude x mean edge length (paper: 0.1)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--normal-noise", f->normal_noise,
                  "perturb normals: normalize(n + u), u uniform in [-a, a]^3 (paper: 0.05)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--cloud", f->cloud,
                "point samples without faces (the irregular samples; docs/POINTS.md)");
  cmd->add_option("--graded", f->graded,
                  "--cloud: density falls by this fraction along x, in [0, 1)")
      ->check(CLI::Range(0.0, 0.99));
  cmd->add_option("--outliers", f->outliers,
                  "--cloud: this fraction of points moved off the surface (truth NaN)")
      ->check(CLI::Range(0.0, 0.99));
  cmd->add_flag("--no-normals", f->no_normals, "write no normals");
  cmd->footer(
      "Examples:\n  focal generate torus --triangulation irregular --vertices 5000 -o torus.ply "
      "--truth torus-truth.csv\n"
      "  focal generate torus --cloud --vertices 5000 --no-normals -o torus.xyz --truth t.csv");
  cmd->add_flag("--force", f->force, "replace read-only output files");
  cmd->parse_complete_callback([f] {
    require_extension("-o", f->output, {".ply", ".obj", ".off", ".xyz", ".xyzn"});
    if (!f->cloud && (f->graded > 0 || f->outliers > 0)) {
      throw CLI::ValidationError("--graded and --outliers need --cloud");
    }
    check_output("-o", f->output, "", f->force);
    if (!f->truth.empty()) check_output("--truth", f->truth, "", f->force);
  });
  cmd->callback([f, &log] { generate(*f, log); });
}

}  // namespace focal::cli
