#pragma once
/// \file focal.h
/// Everything of the focal library in one include.

#include "focal/curvature/baselines.h"
#include "focal/cuda/curvature.h"
#include "focal/curvature/curvature.h"
#include "focal/cuda/device.h"
#include "focal/core/error.h"
#include "focal/io/fields_io.h"
#include "focal/image_space/image_space.h"
#include "focal/curvature/focal_mesh.h"
#include "focal/core/mesh.h"
#include "focal/mesh/check.h"
#include "focal/io/mesh_io.h"
#include "focal/mesh/neighbourhood.h"
#include "focal/curvature/normal_rays.h"
#include "focal/mesh/normals.h"
#include "focal/curvature/recommended.h"
#include "focal/surfaces/surfaces.h"
#include "focal/curvature/triangle_curvature.h"
#include "focal/curvature/two_slit_fit.h"
