#pragma once
// Exact k-nearest-neighbour distances for surfel initialisation (the role of simple-knn's distCUDA2 in
// 2DGS/LumiGauss create_from_pcd): a uniform grid searched in growing shells of cells, O(N) expected for
// SfM-like point clouds instead of O(N^2).
#include <cstdint>
#include <vector>

#include "lumigauss/math/vec.h"

namespace lumigauss {

// Per point: the mean of the squared distances to its k nearest other points (duplicates count, at distance
// 0). With fewer than k other points, the mean over those there are; 0 for a single point. Computed in
// double.
std::vector<double> mean_sq_dist_knn(const std::vector<Vec3f>& points, int k = 3);

// Per point: the indices of its k (1..16) nearest other points, nearest first, k per point; with fewer than
// k other points the list is padded with the point's own index.
std::vector<std::uint32_t> knn_indices(const std::vector<Vec3f>& points, int k);

}  // namespace lumigauss
