// estimate_curvature_cuda and CurvatureCudaContext in a build without the CUDA backend: a
// DeviceError that says why, never a silent fallback to the CPU (STYLE.md, convention 8).
#include <string>

#include "focal/core/error.h"
#include "focal/cuda/curvature.h"

namespace focal {

namespace {

[[noreturn]] void no_backend(const char* what) {
  throw DeviceError(std::string(what) +
                    ": this build of focal has no CUDA backend; configure with "
                    "-DFOCAL_WITH_CUDA=ON on a machine with the CUDA toolkit (nvcc) to use a GPU, "
                    "or call estimate_curvature");
}

}  // namespace

CurvatureResult estimate_curvature_cuda(PositionsRef /*V*/, FacesRef /*F*/, NormalsRef /*N*/,
                                        const CurvatureOptions& /*options*/, int /*device*/) {
  no_backend("estimate_curvature_cuda");
}

// No context is ever made here: the constructor throws, the other members cannot be reached.
struct CurvatureCudaContext::Resident {};

CurvatureCudaContext::CurvatureCudaContext(PositionsRef /*V*/, FacesRef /*F*/, NormalsRef /*N*/,
                                           const CurvatureOptions& /*options*/, int /*device*/) {
  no_backend("CurvatureCudaContext");
}
CurvatureCudaContext::~CurvatureCudaContext() = default;
CurvatureCudaContext::CurvatureCudaContext(CurvatureCudaContext&&) noexcept = default;
CurvatureCudaContext& CurvatureCudaContext::operator=(CurvatureCudaContext&&) noexcept = default;
void CurvatureCudaContext::set_normals(NormalsRef /*N*/) { no_backend("CurvatureCudaContext"); }
CurvatureResult CurvatureCudaContext::estimate() { no_backend("CurvatureCudaContext"); }
int CurvatureCudaContext::vertex_count() const { return 0; }

}  // namespace focal
