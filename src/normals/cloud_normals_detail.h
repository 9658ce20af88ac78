#pragma once
// Internal: cloud_normals with the jets' residuals, for the cloud estimator's plan (the noise of
// the positions, as the recommended estimator measures it on meshes).

#include "focal/core/mesh.h"
#include "focal/mesh/neighbourhood.h"
#include "focal/normals/cloud_normals.h"
#include "focal/normals/jets.h"

namespace focal::detail {

/// cloud_normals, with the jets' residuals and degrees (empty for CloudNormalMethod::pca).
/// \throw as cloud_normals.
JetNormals cloud_jets(PositionsRef V, const Neighbourhoods& neighbours,
                      const CloudNormalOptions& options);

}  // namespace focal::detail
