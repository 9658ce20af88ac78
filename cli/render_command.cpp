// `focal render`: placeholder while the render library is written (issue 7).
#include "commands.h"

namespace focal::cli {

void add_render_command(CLI::App& /*app*/, const Log& /*log*/) {}

}  // namespace focal::cli
