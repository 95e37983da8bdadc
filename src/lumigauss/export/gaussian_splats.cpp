#include "lumigauss/export/gaussian_splats.h"

#include "lumigauss/export/two_sided_sh.h"
#include "lumigauss/model/view_sh.h"

namespace lumigauss {

std::vector<GaussianSplat> gaussian_splats(const SurfelModel& model, const std::vector<float>& view_sh,
                                           int sh_degree) {
    const std::size_t n = model.size();
    check_view_sh_size(view_sh.size(), n, sh_degree);
    const std::size_t count = std::size_t(view_sh_coefficients(sh_degree));
    const auto& xyz = model.param(ModelParam::Xyz);
    const auto& opacity = model.param(ModelParam::Opacity);
    const auto& scaling = model.param(ModelParam::Scaling);
    std::vector<GaussianSplat> splats(n);
    for (std::size_t i = 0; i < n; ++i) {
        GaussianSplat& s = splats[i];
        s.position = {xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]};
        s.log_scale = {scaling[2 * i], scaling[2 * i + 1], kThinLogScale};
        s.rotation = model.unit_quaternion(i);
        s.opacity = opacity[i];
        const float* sh = &view_sh[i * count * 3];
        s.dc = {sh[0], sh[1], sh[2]};
        s.rest.resize(3 * (count - 1));
        for (std::size_t c = 0; c < 3; ++c)
            for (std::size_t k = 1; k < count; ++k) s.rest[c * (count - 1) + k - 1] = sh[k * 3 + c];
    }
    return splats;
}

}  // namespace lumigauss
