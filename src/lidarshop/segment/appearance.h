// Appearance models of the segmentation (segment.h): colour and range densities learnt from the object and
// background cells (histograms or Gaussian mixtures, each mixed with a uniform density), evaluated as log
// densities per graph node. Internal to the segment module.
#pragma once

#include <cstdint>
#include <vector>

#include "lidarshop/segment/segment.h"
#include "lidarshop/segment/segment_graph.h"

namespace lidarshop::segment_internal {

// Log densities of the nodes `subset` (nullptr = every node; the outputs are indexed like `subset`) under the
// models learnt from the nodes `object` and `background`.
LogDensities ComputeLogDensities(const Nodes& nodes, const std::vector<int32_t>& object,
                                 const std::vector<int32_t>& background, const SegmentOptions& options,
                                 const std::vector<int32_t>* subset = nullptr);

}  // namespace lidarshop::segment_internal
