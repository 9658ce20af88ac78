#pragma once
// Meshes for the kernel benchmarks: regular tori generated with make_surface, cached as binary
// PLY under build/bench-data (FOCAL_BENCH_DATA) so that a run does not regenerate them.

#include <string>

#include "focal/core/mesh.h"

namespace focal::bench {

/// The regular torus of about `vertices` vertices with exact normals, loaded from the cache or
/// generated and cached. Meshes stay in memory for the rest of the run (one per size).
const Mesh& torus(int vertices);

/// The Stanford bunny (37,706 vertices, no normals) from build/bench-data/bunny.off, extracted
/// there from Debian's libcgal-demo data when missing; nullptr when neither exists.
const Mesh* bunny();

}  // namespace focal::bench
