#pragma once
/// \file curvature.h
/// The front door: the curvature of a triangle mesh or of a point cloud in one call, what the
/// `focal curvature` command runs. The options name the estimator (the recommended default, the
/// paper's method, or a baseline of the literature), the device, tiling and the execution
/// (focal/core/execution.h); the result carries the fields and everything a
/// caller may want to report about how they were made.
///
///     focal::Mesh mesh = focal::read_mesh("bunny.ply");  // or a cloud: a file without faces
///     focal::Estimate e = focal::curvature(mesh);           // e.curvature.k1, .H, .d1, ...
///
/// A mesh (#F > 0) runs prepare_normals then the estimator (focal/curvature/estimate.h); a
/// cloud (#F = 0) runs estimate_cloud_curvature with EstimateOptions::cloud
/// (focal/curvature/cloud_curvature.h). With tile_vertices > 0 either runs tile by tile
/// (focal/tiles/tiles.h: the same bits). The steps stay public for callers that need one of
/// them alone; docs/METHOD.md describes what each estimator does.
///
/// Stages reported through Execution::progress: "normals" and "curvature" (a mesh),
/// "cloud curvature" (a cloud), "curvature in tiles of N vertices" or "cloud curvature in tiles
/// of N points" (tiled). Warnings (inward components reversed, file normals fixed or ignored,
/// vertices over the neighbourhood cap, nothing defined) go to Execution::warning, the
/// recommended estimator's plan and a cloud's normals and spacing to Execution::info.
///
/// Row i of every field is input vertex i, for any thread count and tiling, bit for bit.

#include "focal/core/mesh.h"
#include "focal/curvature/estimate.h"
#include "focal/mesh/prepared.h"

namespace focal {

/// The curvature of `input`: a mesh, or a point cloud when it has no faces. Its normals are the
/// given ones (judged, and fixed or ignored, by the estimator) when it has them.
/// \throw InvalidInput when an option is out of range or does not apply to the input (a
/// baseline, the device or NormalsSource other than automatic on a cloud; NormalsSource::file
/// without normals); DeviceError for Device::cuda without a usable GPU; Cancelled when
/// Execution::cancel is set.
[[nodiscard]] Estimate curvature(const PreparedMesh& input, const EstimateOptions& options = {});

/// curvature() of a mesh or cloud as read (Mesh::is_cloud: no faces).
[[nodiscard]] Estimate curvature(const Mesh& input, const EstimateOptions& options = {});

}  // namespace focal
