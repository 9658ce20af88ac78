#include "focal/recommended.h"

#include "focal/normals.h"

namespace focal {

CurvatureResult estimate_curvature_recommended(PositionsRef V, FacesRef F, NormalsRef N,
                                               int threads) {
  CurvatureOptions options;
  options.threads = threads;
  return estimate_curvature(V, F, N, options);
}

CurvatureResult estimate_curvature_recommended(PositionsRef V, FacesRef F, int threads) {
  CurvatureOptions options;
  options.threads = threads;
  return estimate_curvature(V, F, vertex_normals(V, F, NormalWeighting::max), options);
}

}  // namespace focal
