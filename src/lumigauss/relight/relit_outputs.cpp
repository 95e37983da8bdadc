#include "lumigauss/relight/relit_outputs.h"

#include <filesystem>
#include <sstream>

#include "lumigauss/io/image.h"
#include "lumigauss/relight/relit_render.h"
#include "lumigauss/util/error.h"

namespace lumigauss {

RelitOutputs parse_relit_outputs(const std::string& list) {
    RelitOutputs o;
    if (list == "all") return o;
    o.shadowed = o.unshadowed = o.albedo = o.normal = o.shadow = o.irradiance = o.depth = o.alpha = false;
    std::stringstream s(list);
    std::string item;
    bool any = false;
    while (std::getline(s, item, ',')) {
        if (item == "shadowed")
            o.shadowed = true;
        else if (item == "unshadowed")
            o.unshadowed = true;
        else if (item == "albedo")
            o.albedo = true;
        else if (item == "normal")
            o.normal = true;
        else if (item == "shadow")
            o.shadow = true;
        else if (item == "irradiance")
            o.irradiance = true;
        else if (item == "depth")
            o.depth = true;
        else if (item == "alpha")
            o.alpha = true;
        else
            throw Error(
                "--outputs: unknown map '" + item +
                "' (all, or a list of shadowed, unshadowed, albedo, normal, shadow, irradiance, depth, "
                "alpha)");
        any = true;
    }
    if (!any) throw Error("--outputs: no map selected");
    return o;
}

std::string relit_path(const std::string& dir, const std::string& stem, const std::string& suffix) {
    return (std::filesystem::path(dir) / (stem + suffix)).string();
}

std::vector<std::string> write_relit_frame(const std::string& dir, const std::string& stem,
                                           const RasterImages<float>& raster, const RelitOutputs& o,
                                           const Image* sky) {
    std::filesystem::create_directories(std::filesystem::path(relit_path(dir, stem, "")).parent_path());
    std::vector<std::string> written;
    auto png = [&](const std::string& suffix, const Image& im) {
        written.push_back(relit_path(dir, stem, suffix + ".png"));
        write_png(written.back(), im);
    };
    auto exr = [&](const std::string& suffix, const Image& im) {
        written.push_back(relit_path(dir, stem, suffix + ".exr"));
        write_exr(written.back(), im);
    };
    const Image alpha = alpha_image(raster);
    auto colour = [&](const std::string& suffix, int first) {
        Image im = raster_channels(raster, first, 3);
        if (o.sky_background && sky != nullptr && first != kRelitAlbedo)
            im = over_background_image(im, alpha, *sky);
        else if (o.has_background)
            im = over_background(im, alpha, o.background);
        png(suffix, im);
        if (o.exr) exr(suffix, im);
    };
    if (o.shadowed) colour("_shadowed", kRelitShadowed);
    if (o.unshadowed) colour("_unshadowed", kRelitUnshadowed);
    if (o.albedo) colour("_albedo", kRelitAlbedo);
    if (o.normal) {
        png("_normal", encode_normals(raster));
        if (o.exr) exr("_normal", unit_normals(raster));
    }
    const bool need_intensity = o.shadow || o.irradiance;
    const Image is = need_intensity ? raster_channels(raster, kRelitIntensityShadowed, 3) : Image();
    const Image iu = need_intensity ? raster_channels(raster, kRelitIntensityUnshadowed, 3) : Image();
    if (o.shadow) {
        const Image sh = shadow_image(iu, is);
        png("_shadow", sh);
        if (o.exr) exr("_shadow", sh);
    }
    if (o.irradiance) {
        const float m = display_max({&is, &iu});
        png("_irradiance", divided(is, m));
        png("_irradiance_unshadowed", divided(iu, m));
        exr("_irradiance", is);
        if (o.exr) exr("_irradiance_unshadowed", iu);
    }
    if (o.depth) exr("_depth", expected_depth(raster));
    if (o.alpha) png("_alpha", alpha);
    return written;
}

}  // namespace lumigauss
