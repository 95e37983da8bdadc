#include "lumigauss/synth/colmap_with_tracks.h"

#include "lumigauss/math/quaternion.h"

namespace lumigauss::synth {

namespace {

ColmapImage image_of(const ColmapView& v) {
    ColmapImage image;
    image.id = v.image_id;
    image.name = v.name;
    image.qvec = quaternion_from_rotation(v.camera.rotation);
    image.tvec = v.camera.translation;
    image.camera_id = v.image_id;
    return image;
}

}  // namespace

ColmapModel colmap_model_with_tracks(const std::vector<ColmapView>& views,
                                     const std::vector<SfmPoint>& points) {
    ColmapModel model;
    std::vector<int> image_of_training_view;  // training index -> position in model.images
    for (const ColmapView& v : views) {
        const Camera& c = v.camera;
        model.cameras[v.image_id] =
            ColmapCamera{v.image_id, "PINHOLE", c.width, c.height, {c.fx, c.fy, c.cx, c.cy}};
        if (v.training_index >= 0) {
            if (std::size_t(v.training_index) >= image_of_training_view.size())
                image_of_training_view.resize(std::size_t(v.training_index) + 1, -1);
            image_of_training_view[std::size_t(v.training_index)] = int(model.images.size());
        }
        model.images.push_back(image_of(v));
    }
    for (std::size_t p = 0; p < points.size(); ++p) {
        const SfmPoint& point = points[p];
        model.point_xyz.push_back(point.position.cast<float>());
        model.point_rgb.push_back(
            {float(point.rgb[0]) / 255.0f, float(point.rgb[1]) / 255.0f, float(point.rgb[2]) / 255.0f});
        model.point_error.push_back(point.error);
        std::vector<ColmapTrackElement>& track = model.point_tracks.emplace_back();
        for (const Observation& o : point.track) {
            ColmapImage& image = model.images[std::size_t(image_of_training_view.at(std::size_t(o.view)))];
            track.push_back({image.id, int(image.observations.size())});
            image.observations.push_back({{o.x, o.y}, std::int64_t(p)});
        }
    }
    return model;
}

}  // namespace lumigauss::synth
