#pragma once
// COLMAP text model with 2D observations and point tracks, as structure-from-motion would leave it.
// io/colmap.h's writer keeps cameras, poses and point colours only (what training needs); a synthetic
// dataset that stands in for real user data must also have valid tracks, so it is written here.
#include <string>
#include <vector>

#include "lumigauss/io/camera.h"
#include "lumigauss/synth/sfm_points.h"

namespace lumigauss::synth {

struct ColmapView {
    int image_id = 0;  // also its camera id (one PINHOLE camera per image)
    std::string name;
    Camera camera;
    int training_index = -1;  // index into the views of SfmPoint::track, -1 for test photos (no 2D points)
};

// Writes dir/{cameras,images,points3D}.txt (dir must exist). Point ids are 1-based in the order given.
void write_colmap_with_tracks(const std::string& dir, const std::vector<ColmapView>& views,
                              const std::vector<SfmPoint>& points);

}  // namespace lumigauss::synth
