// PCL point clouds for the registration's .cpp files that call PCL (downsampling.cpp,
// features_pcl.cpp). Include this before any other PCL header: PCL's templates are instantiated
// in our own flags (PCL_NO_PRECOMPILE) instead of using the instances precompiled into Debian's
// libpcl_*.so. With -march=native Eigen's heap alignment (and so its aligned_malloc/free) differs
// from the library's SSE2 build, and memory allocated on one side and freed on the other (e.g.
// point-cloud storage resized inside a filter) would corrupt the heap.
#pragma once

#ifndef PCL_NO_PRECOMPILE
#define PCL_NO_PRECOMPILE
#endif
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include "bayesgrasp/vision/oriented_cloud.hpp"

namespace bayesgrasp::vision {

using CloudN = pcl::PointCloud<pcl::PointNormal>;

/// The cloud as PCL points with normals (curvature 0).
CloudN::Ptr to_pcl(const OrientedCloud& cloud);

}  // namespace bayesgrasp::vision
