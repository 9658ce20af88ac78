// `focal render`: a PNG picture of a curvature field on the mesh (focal::render, OpenGL on a
// headless EGL context), optionally with principal-direction glyphs and the two focal meshes.
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "commands.h"
#include "estimator_flags.h"
#include "focal/core/execution.h"
#include "focal/curvature/focal_mesh.h"
#include "focal/io/mesh_io.h"
#include "focal/render/render.h"
#include "input_check.h"
#include "paths.h"

namespace focal::cli {
namespace {

struct RenderFlags {
  std::string input;
  std::string output;
  bool force = false;
  std::string field = "H";
  std::string camera_text;  // "AZIMUTH,ELEVATION" in degrees
  std::string size_text = "1200x900";
  std::string range_text;  // "LO,HI"
  std::string directions;  // "", "d1" or "d2"
  bool focal_meshes = false;
  bool orthographic = false;
  std::string title;
  EstimatorFlags estimator;
  // Parsed from the texts above.
  FieldPictureOptions picture;
};

/// Parses "A<separator>B" into two finite numbers. \throw CLI::ValidationError naming `option`.
std::pair<double, double> parse_pair(const std::string& option, const std::string& text,
                                     char separator, const char* form) {
  const auto split = text.find(separator);
  const auto number = [&](std::string_view token) {
    double value = 0.0;
    if (!token.empty() && token.front() == '+') token.remove_prefix(1);
    const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (error != std::errc{} || end != token.data() + token.size() || !std::isfinite(value)) {
      throw CLI::ValidationError(option, "expected " + std::string(form) + ", got '" + text + "'");
    }
    return value;
  };
  if (split == std::string::npos) {
    throw CLI::ValidationError(option, "expected " + std::string(form) + ", got '" + text + "'");
  }
  const std::string_view all(text);
  return {number(all.substr(0, split)), number(all.substr(split + 1))};
}

/// Checks and converts the flags before any work, so that a wrong flag is a usage error.
void parse_picture_flags(RenderFlags& f) {
  require_extension("-o", f.output, {".png"});
  FieldPictureOptions& p = f.picture;
  const auto [w, h] = parse_pair("--size", f.size_text, 'x', "WIDTHxHEIGHT, e.g. 1200x900");
  if (w != std::floor(w) || h != std::floor(h) || w < 64 || h < 64 || w > 16384 || h > 16384) {
    throw CLI::ValidationError("--size",
                               "width and height must be whole numbers in [64, 16384], "
                               "got '" +
                                   f.size_text + "'");
  }
  p.width = static_cast<int>(w);
  p.height = static_cast<int>(h);
  if (!f.camera_text.empty()) {
    const auto [azimuth, elevation] =
        parse_pair("--camera", f.camera_text, ',', "AZIMUTH,ELEVATION in degrees, e.g. 30,20");
    if (elevation < -90.0 || elevation > 90.0) {
      throw CLI::ValidationError("--camera", "elevation must be in [-90, 90] degrees");
    }
    p.view.azimuth = azimuth;
    p.view.elevation = elevation;
  }
  if (!f.range_text.empty()) {
    const auto [lo, hi] = parse_pair("--range", f.range_text, ',', "LO,HI, e.g. -2,2");
    if (!(lo < hi))
      throw CLI::ValidationError("--range", "needs LO < HI, got '" + f.range_text + "'");
    if (f.field == "class")
      throw CLI::ValidationError("--range", "does not apply to --field class");
    p.range = ColourRange{lo, hi};
  }
  p.view.projection = f.orthographic ? Projection::orthographic : Projection::perspective;
  p.colour_map = f.field == "class" ? ColourMap::classes : ColourMap::diverging;
}

std::string field_description(const std::string& field) {
  if (field == "H") return "H, mean curvature";
  if (field == "K") return "K, Gaussian curvature";
  if (field == "k1") return "k1, larger principal curvature";
  if (field == "k2") return "k2, smaller principal curvature";
  return "point class";
}

Eigen::VectorXd field_values(const CurvatureResult& c, const std::string& field) {
  if (field == "H") return c.H;
  if (field == "K") return c.K;
  if (field == "k1") return c.k1;
  if (field == "k2") return c.k2;
  return c.point_class.cast<double>();
}

/// The picture of a mesh, with the focal meshes and glyphs the flags ask for.
Image render_mesh(RenderFlags& f, const Input& input, const Log& log) {
  const Estimate e = run_estimate(input, f.estimator, log);
  const PreparedMesh mesh = estimated_mesh(input, e);
  const CurvatureResult& fields = e.curvature;
  FieldPictureOptions& p = f.picture;
  if (f.focal_meshes) {
    Stage stage(log, "focal meshes");
    // Faces reaching a focal point at infinity would only draw long slivers across the view.
    p.focal_meshes =
        focal_meshes(mesh, fields, {.max_distance = 0.0, .drop_faces_at_infinity = true});
  }
  if (f.directions == "d1") p.directions = fields.d1;
  if (f.directions == "d2") p.directions = fields.d2;
  Stage stage(log, "render");
  return render_field_picture(mesh.V(), mesh.F(), mesh.N(), field_values(fields, f.field), p);
}

/// The picture of a point cloud: splats of its points (with the normals used) and, with
/// --focal-meshes, of its focal points.
Image render_cloud(RenderFlags& f, const Input& input, const Log& log) {
  const Estimate e = run_estimate(input, f.estimator, log);
  const CurvatureResult& fields = e.curvature;
  const RowMatrixX3d& N = *e.N;
  FieldPictureOptions& p = f.picture;
  const RowMatrixX3i no_faces(0, 3);
  if (f.focal_meshes) {
    Stage stage(log, "focal points");
    p.focal_meshes = focal_meshes(input.mesh.V, no_faces, N, fields, {.max_distance = 0.0});
  }
  if (f.directions == "d1") p.directions = fields.d1;
  if (f.directions == "d2") p.directions = fields.d2;
  Stage stage(log, "render");
  return render_field_picture(input.mesh.V, no_faces, N, field_values(fields, f.field), p);
}

void run_render(RenderFlags& f, const Log& log) {
  const ExecutionScope scope({.threads = f.estimator.threads});
  const Input input(f.input, f.estimator, log);
  FieldPictureOptions& p = f.picture;
  p.title = f.title.empty() ? std::filesystem::path(f.input).filename().string() + ": " +
                                  field_description(f.field)
                            : f.title;
  Image image;
  if (input.cloud) {
    image = render_cloud(f, input, log);
  } else {
    image = render_mesh(f, input, log);
  }
  Stage stage(log, "write");
  write_png(f.output, image);
  std::printf("wrote %s (%d x %d)\n", f.output.c_str(), image.width, image.height);
}

}  // namespace

void add_render_command(CLI::App& app, const Log& log) {
  auto* cmd = app.add_subcommand("render", "A PNG picture of a curvature field on the mesh");
  auto f = std::make_shared<RenderFlags>();
  cmd->add_option("input", f->input,
                  "mesh file (.obj .ply .off .stl) or point cloud (no faces; drawn as splats)")
      ->required();
  cmd->add_option("-o,--output", f->output, "OUT.png")->required();
  cmd->add_option("--field", f->field, "the field to colour by: H, K, k1, k2 or class")
      ->check(CLI::IsMember({"H", "K", "k1", "k2", "class"}))
      ->capture_default_str();
  cmd->add_option("--camera", f->camera_text,
                  "AZIMUTH,ELEVATION in degrees: about +y from +z, above the xz plane (default "
                  "0,0: looking along -z)");
  cmd->add_option("--size", f->size_text, "WIDTHxHEIGHT of the picture in pixels, 64 to 16384")
      ->capture_default_str();
  cmd->add_option("--range", f->range_text,
                  "LO,HI of the colour map (default: -P,P with P the 95th percentile of |field|)");
  cmd->add_option("--directions", f->directions,
                  "draw principal-direction glyphs along d1 or d2 at a subsample of vertices")
      ->check(CLI::IsMember({"d1", "d2"}));
  cmd->add_flag("--focal-meshes", f->focal_meshes,
                "two more panels: the focal meshes Gamma_1 and Gamma_2, same camera and colours");
  cmd->add_flag("--orthographic", f->orthographic, "orthographic instead of perspective view");
  cmd->add_option("--splat-radius", f->picture.splat_radius,
                  "point clouds: radius of each point's disc (0 = 0.7 x the mean distance to its "
                  "8 nearest)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--title", f->title, "title above the picture (default: file name and field)");
  f->estimator.add_to(*cmd);
  cmd->footer(
      "Colours: H, K, k1, k2 on a blue-white-red map with white at 0 (red: curving away from the\n"
      "normal, e.g. convex parts with outward normals); class on one colour per point class.\n"
      "Vertices without an estimate are grey. Runs without a display (EGL; Mesa or a GPU driver);\n"
      "see docs/RENDER.md. Examples:\n"
      "  focal render bunny.off -o bunny-H.png\n"
      "  focal render bunny.off -o bunny-K.png --field K --camera 30,20 --size 1600x1200\n"
      "  focal render scan.ply -o scan-class.png --field class --rings 2\n"
      "  focal render torus.ply -o torus.png --field k1 --directions d1 --range -1,3\n"
      "  focal render bunny.off -o bunny-focal.png --focal-meshes --size 2400x900");
  cmd->add_flag("--force", f->force, "replace a read-only output file");
  cmd->parse_complete_callback([f] {
    parse_picture_flags(*f);
    check_output("-o", f->output, f->input, f->force);
  });
  cmd->callback([f, &log] { run_render(*f, log); });
}

}  // namespace focal::cli
