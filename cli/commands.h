#pragma once
// The subcommands of `focal`. Each registers itself on the app and runs from its callback.

#include <CLI/CLI.hpp>

#include "log.h"

namespace focal::cli {

void add_info_command(CLI::App& app, const Log& log);
void add_generate_command(CLI::App& app, const Log& log);
void add_curvature_command(CLI::App& app, const Log& log);
void add_focal_mesh_command(CLI::App& app, const Log& log);
void add_normals_command(CLI::App& app, const Log& log);
void add_smooth_command(CLI::App& app, const Log& log);
void add_eval_command(CLI::App& app, const Log& log);
void add_render_command(CLI::App& app, const Log& log);
void add_devices_command(CLI::App& app, const Log& log);

}  // namespace focal::cli
