#pragma once
/// \file
/// Umbrella header: everything touchdown offers. Include the module headers
/// (touchdown/core/..., touchdown/terrain/...) instead to compile faster.
#include "touchdown/core/atomic_file.hpp"
#include "touchdown/core/cloud_io.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/mesh.hpp"
#include "touchdown/core/mesh_io.hpp"
#include "touchdown/core/point_cloud.hpp"
#include "touchdown/core/random.hpp"
#include "touchdown/core/version.hpp"
#include "touchdown/pose/gauss_newton.hpp"
#include "touchdown/pose/se3.hpp"
#include "touchdown/terrain/extrinsics.hpp"
#include "touchdown/terrain/filters.hpp"
#include "touchdown/terrain/height_map.hpp"
#include "touchdown/terrain/synthetic.hpp"
#include "touchdown/terrain/terrain_mesher.hpp"
#include "touchdown/twin/airframe.hpp"
#include "touchdown/twin/landing.hpp"
#include "touchdown/twin/sweep.hpp"
#include "touchdown/twin/terrain_model.hpp"
#include "touchdown/twin/threshold.hpp"
