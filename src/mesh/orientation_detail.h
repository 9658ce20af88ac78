#pragma once
// Internal: orientation_report on a topology already computed, for check_mesh (check.cpp), which
// computes the topology once for its statistics and its orientation.

#include "focal/core/mesh.h"
#include "focal/mesh/orientation.h"
#include "mesh/statistics_detail.h"

namespace focal::detail {

/// orientation_report from a topology already computed for (V, F).
OrientationReport orientation_report_from(PositionsRef V, FacesRef F, const MeshTopology& t,
                                          int threads);

}  // namespace focal::detail
