#pragma once
/// \file focal.h
/// Everything of the focal library in one include.

// In the order of the data flow (README, Layout): the data model, files, the mesh and its
// normals, curvature, the device backends, the image-space estimator, test surfaces, evaluation.
#include "focal/curvature.h"  // the front door
#include "focal/core/error.h"
#include "focal/core/execution.h"
#include "focal/core/mesh.h"
#include "focal/core/edge_lengths.h"
#include "focal/core/fields.h"
#include "focal/io/mesh_io.h"
#include "focal/io/fields_io.h"
#include "focal/mesh/check.h"
#include "focal/mesh/neighbourhood.h"
#include "focal/mesh/prepared.h"
#include "focal/mesh/orientation.h"
#include "focal/points/neighbours.h"
#include "focal/normals/vertex_normals.h"
#include "focal/normals/jets.h"
#include "focal/normals/cloud_normals.h"
#include "focal/curvature/normal_rays.h"
#include "focal/curvature/two_slit_fit.h"
#include "focal/curvature/curvature.h"
#include "focal/curvature/triangle_curvature.h"
#include "focal/curvature/recommended.h"
#include "focal/curvature/estimate.h"
#include "focal/curvature/focal_mesh.h"
#include "focal/curvature/cloud_curvature.h"
#include "focal/curvature/baselines.h"
#include "focal/smoothing/smooth.h"
#include "focal/tiles/tiles.h"
#include "focal/cuda/device.h"
#include "focal/cuda/curvature.h"
#include "focal/image_space/image_space.h"
