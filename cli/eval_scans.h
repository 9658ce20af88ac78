#pragma once
// `focal eval --scan` (eval_scans.cpp): the smoothness of H on scanned meshes without truth
// (paper Fig. 7).

#include "eval_cases.h"
#include "log.h"

namespace focal::cli::eval {

/// `focal eval --scan`: every scan method on each of f.scans, the table printed and written to
/// f.csv and f.markdown where given, coloured H fields into f.export_dir where given.
void run_scans(const EvalFlags& f, const Log& log);

}  // namespace focal::cli::eval
