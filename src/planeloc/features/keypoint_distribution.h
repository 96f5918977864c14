// Quadtree distribution of FAST corners (the idea of ORB-SLAM2's DistributeOctTree): the detection
// area is split into nodes, nodes holding more than one corner are split in four until there are
// at least `target` nodes (or nothing can be split), and each node keeps its strongest corner.
// The result is spread over the image instead of clustered on the most textured spot.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace planeloc {

// Returns the indices (into `corners`) of the kept corners, in ascending order. `area` is the
// region the corners lie in (same pixel frame as the corners). Deterministic: ties in node size
// and corner response are broken by creation order / index. Returns all indices if there are at
// most `target` corners.
std::vector<int> DistributeQuadtree(const std::vector<cv::KeyPoint>& corners,
                                    const cv::Rect2f& area, int target);

}  // namespace planeloc
