#pragma once
/// \file focal.h
/// Everything of the focal library in one include.

#include "focal/baselines.h"
#include "focal/cuda_curvature.h"
#include "focal/curvature.h"
#include "focal/device.h"
#include "focal/error.h"
#include "focal/fields_io.h"
#include "focal/image_space.h"
#include "focal/focal_mesh.h"
#include "focal/mesh.h"
#include "focal/mesh_check.h"
#include "focal/mesh_io.h"
#include "focal/neighbourhood.h"
#include "focal/normal_rays.h"
#include "focal/normals.h"
#include "focal/recommended.h"
#include "focal/surfaces.h"
#include "focal/triangle_curvature.h"
#include "focal/two_slit_fit.h"
