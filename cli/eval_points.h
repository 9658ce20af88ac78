#pragma once
// `focal eval --points` (eval_points.cpp), called by eval_command.cpp.

#include <cstdint>
#include <string>

#include "log.h"

namespace focal::cli {

/// The cloud estimator on every analytic cloud case; prints a Markdown table, writes `csv` and
/// `markdown` when not empty.
void run_eval_points(int points, std::uint64_t seed, const std::string& csv,
                     const std::string& markdown, const Log& log);

}  // namespace focal::cli
