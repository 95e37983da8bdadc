#pragma once
// The synthetic scene's sparse model as structure from motion would leave it: one PINHOLE camera per photo,
// the poses, and the sampled points with their 2D observations and tracks (a synthetic dataset stands in for
// real user data, so its tracks must be valid). Written by io/colmap.h's writers.
#include <string>
#include <vector>

#include "lumigauss/io/camera.h"
#include "lumigauss/io/colmap.h"
#include "lumigauss/synth/sfm_points.h"

namespace lumigauss::synth {

struct ColmapView {
    int image_id = 0;  // also its camera id (one PINHOLE camera per image)
    std::string name;
    Camera camera;
    int training_index = -1;  // index into the views of SfmPoint::track, -1 for test photos (no 2D points)
};

// The model of `views` (in that order) and `points` (in that order, numbered from 1 when written). Each
// training view observes the points whose tracks name it, in point order.
ColmapModel colmap_model_with_tracks(const std::vector<ColmapView>& views,
                                     const std::vector<SfmPoint>& points);

}  // namespace lumigauss::synth
