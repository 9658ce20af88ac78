#pragma once
// The estimators that `focal eval` compares (eval_estimators.cpp): focal's and the baselines, on
// the analytic suite and on scanned meshes.

#include <functional>
#include <string>
#include <vector>

#include "focal/core/mesh.h"
#include "focal/curvature/curvature.h"

namespace focal::cli::eval {

/// One estimator: a name and how it runs on a mesh whose N holds the file's normals.
/// `reads_normals`: whether it uses the file's normals (else it sees positions only).
struct Estimator {
  std::string name;
  std::function<CurvatureResult(const Mesh&)> run;
  bool reads_normals = false;
};

/// The estimators of the analytic suite; rows 0 and 1 of each case are focal default with the
/// file's normals and without normals (the tables count its wins from them).
std::vector<Estimator> methods();

/// The estimators of the scan table: focal default (with the file's normals when it has them) and
/// the paper's 1-ring fit with Max normals, and the positions-only baselines.
std::vector<Estimator> scan_methods(bool file_normals);

}  // namespace focal::cli::eval
