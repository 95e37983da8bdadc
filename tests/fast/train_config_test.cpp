// TrainConfig: the paper and fast presets, JSON writing and reading (round trip of every field, partial
// files, the preset key), --set overrides, and validation; every error names its source and key.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "lumigauss/train/train_config.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using Json = nlohmann::json;

// The message of the Error that `f` throws ("" and a failure when it throws none).
template <class F>
std::string error_of(F&& f) {
    try {
        std::forward<F>(f)();
    } catch (const Error& e) {
        return e.what();
    }
    ADD_FAILURE() << "expected a lumigauss::Error";
    return {};
}

std::string json_error(const std::string& text, const std::string& source = "run/config.json") {
    TrainConfig c;
    return error_of([&] { apply_train_config_json(c, text, source); });
}

std::string set_error(const std::string& text) {
    TrainConfig c;
    return error_of([&] { apply_train_config_override(c, text); });
}

// Number of members of an aggregate (independent of the library's table): the largest N for which
// T{x1, ..., xN} compiles with x convertible to anything.
struct AnyValue {
    template <class T>
    constexpr operator T() const noexcept;
};
template <class T, std::size_t... I>
constexpr bool brace_initializable_with(std::index_sequence<I...> /*unused*/) {
    return requires {
        T{(static_cast<void>(I), AnyValue{})...};
    };
}
template <class T, std::size_t N = 0>
constexpr std::size_t member_count() {
    if constexpr (brace_initializable_with<T>(std::make_index_sequence<N + 1>{})) {
        return member_count<T, N + 1>();
    } else {
        return N;
    }
}

// Every member of TrainConfig, each with a change to a non-default value (awkward doubles included, a seed
// above INT64_MAX). Written out member by member so that a field missing from the library's table shows.
struct MemberChange {
    std::string key;
    std::function<void(TrainConfig&)> change;
};

std::vector<MemberChange> every_member() {
    return {
        {"preset", [](TrainConfig& c) { c.preset = "fast"; }},
        {"seed", [](TrainConfig& c) { c.seed = 18446744073709551557ull; }},
        {"downscale", [](TrainConfig& c) { c.downscale = 4; }},
        {"iterations", [](TrainConfig& c) { c.iterations = 123457; }},
        {"warmup", [](TrainConfig& c) { c.warmup = 777; }},
        {"start_shadowed", [](TrainConfig& c) { c.start_shadowed = 8000000000; }},
        {"start_regularization", [](TrainConfig& c) { c.start_regularization = 0; }},
        {"lambda_dssim", [](TrainConfig& c) { c.lambda_dssim = 0.1 + 0.2; }},
        {"lambda_unshadowed_stage3", [](TrainConfig& c) { c.lambda_unshadowed_stage3 = 1.0 / 3.0; }},
        {"lambda_range01", [](TrainConfig& c) { c.lambda_range01 = 1e-300; }},
        {"lambda_env", [](TrainConfig& c) { c.lambda_env = 0.0; }},
        {"lambda_consistency", [](TrainConfig& c) { c.lambda_consistency = 1.0; }},
        {"consistency_final_ratio", [](TrainConfig& c) { c.consistency_final_ratio = 0.0; }},
        {"lambda_shadow", [](TrainConfig& c) { c.lambda_shadow = 123456789.125; }},
        {"lambda_normal", [](TrainConfig& c) { c.lambda_normal = 2.0 / 7.0; }},
        {"lambda_distortion", [](TrainConfig& c) { c.lambda_distortion = 1e22; }},
        {"env_noise_sigma", [](TrainConfig& c) { c.env_noise_sigma = 0.05; }},
        {"transfer_samples", [](TrainConfig& c) { c.transfer_samples = 64; }},
        {"env_samples", [](TrainConfig& c) { c.env_samples = 3; }},
        {"lr_position_init", [](TrainConfig& c) { c.lr_position_init = 1.7e-4; }},
        {"lr_position_final", [](TrainConfig& c) { c.lr_position_final = 4.9e-324; }},
        {"lr_position_max_steps", [](TrainConfig& c) { c.lr_position_max_steps = 2250; }},
        {"lr_transfer", [](TrainConfig& c) { c.lr_transfer = 0.0021; }},
        {"lr_opacity", [](TrainConfig& c) { c.lr_opacity = 0.025; }},
        {"lr_scaling", [](TrainConfig& c) { c.lr_scaling = 0.0051; }},
        {"lr_rotation", [](TrainConfig& c) { c.lr_rotation = 0.0011; }},
        {"lr_albedo", [](TrainConfig& c) { c.lr_albedo = 0.0026; }},
        {"lr_embedding", [](TrainConfig& c) { c.lr_embedding = 0.0022; }},
        {"lr_mlp", [](TrainConfig& c) { c.lr_mlp = 0.0023; }},
        {"lr_env_final_ratio", [](TrainConfig& c) { c.lr_env_final_ratio = 2.5; }},
        {"densify_from", [](TrainConfig& c) { c.densify_from = 100; }},
        {"densify_until", [](TrainConfig& c) { c.densify_until = 1200; }},
        {"densify_interval", [](TrainConfig& c) { c.densify_interval = 100; }},
        {"opacity_reset_interval", [](TrainConfig& c) { c.opacity_reset_interval = 600; }},
        {"densify_grad_threshold", [](TrainConfig& c) { c.densify_grad_threshold = 0.00021; }},
        {"lambda_ground_light", [](TrainConfig& c) { c.lambda_ground_light = 3.0; }},
        {"ground_light_albedo", [](TrainConfig& c) { c.ground_light_albedo = 0.25; }},
        {"min_opacity", [](TrainConfig& c) { c.min_opacity = 0.005; }},
        {"opacity_reset_value", [](TrainConfig& c) { c.opacity_reset_value = 0.2; }},
        {"max_screen_size", [](TrainConfig& c) { c.max_screen_size = 0.0; }},
        {"percent_dense", [](TrainConfig& c) { c.percent_dense = 0.015; }},
        {"faithful_radii_reset", [](TrainConfig& c) { c.faithful_radii_reset = false; }},
        {"init_normals_from_points", [](TrainConfig& c) { c.init_normals_from_points = true; }},
        {"sky_background", [](TrainConfig& c) { c.sky_background = true; }},
        {"ground_seeds", [](TrainConfig& c) { c.ground_seeds = true; }},
        {"sky_horizon_start", [](TrainConfig& c) { c.sky_horizon_start = 2; }},
        {"sky_horizon_fade", [](TrainConfig& c) { c.sky_horizon_fade = 5; }},
        {"sky_residual", [](TrainConfig& c) { c.sky_residual = true; }},
        {"lambda_sky_residual", [](TrainConfig& c) { c.lambda_sky_residual = 0.125; }},
        {"lr_sky_residual", [](TrainConfig& c) { c.lr_sky_residual = 0.03; }},
        {"lambda_sky_hemisphere", [](TrainConfig& c) { c.lambda_sky_hemisphere = 0.5; }},
        {"sky_pins_light", [](TrainConfig& c) { c.sky_pins_light = false; }},
        {"held_out_interval", [](TrainConfig& c) { c.held_out_interval = 250; }},
        {"lighting_init_radiance", [](TrainConfig& c) { c.lighting_init_radiance = 0.7; }},
        {"exif_exposure", [](TrainConfig& c) { c.exif_exposure = true; }},
        {"use_sky_masks", [](TrainConfig& c) { c.use_sky_masks = false; }},
        {"lambda_sky_alpha", [](TrainConfig& c) { c.lambda_sky_alpha = 0.3; }},
        {"lambda_sky_colour", [](TrainConfig& c) { c.lambda_sky_colour = 0.7; }},
        {"sky_mask_erosion", [](TrainConfig& c) { c.sky_mask_erosion = 3; }},
        {"sky_free_regularizers", [](TrainConfig& c) { c.sky_free_regularizers = true; }},
        {"lambda_background_alpha", [](TrainConfig& c) { c.lambda_background_alpha = 0.2; }},
        {"background_match_tolerance", [](TrainConfig& c) { c.background_match_tolerance = 0.05; }},
        {"background_alpha_from", [](TrainConfig& c) { c.background_alpha_from = 7; }},
        {"mask_mode", [](TrainConfig& c) { c.mask_mode = "object"; }},
        {"prune_until_end", [](TrainConfig& c) { c.prune_until_end = true; }},
        {"densify_near_fraction", [](TrainConfig& c) { c.densify_near_fraction = 0.37; }},
        {"lambda_opacity", [](TrainConfig& c) { c.lambda_opacity = 0.01; }},
        {"lambda_scale_ratio", [](TrainConfig& c) { c.lambda_scale_ratio = 0.5; }},
        {"max_scale_ratio", [](TrainConfig& c) { c.max_scale_ratio = 4.0; }},
        {"empty_space_prune_share", [](TrainConfig& c) { c.empty_space_prune_share = 0.6; }},
        {"min_contribution_pixels", [](TrainConfig& c) { c.min_contribution_pixels = 2.5; }},
        {"min_ground_views", [](TrainConfig& c) { c.min_ground_views = 3; }},
        {"geometric_transfer_every", [](TrainConfig& c) { c.geometric_transfer_every = 500; }},
        {"shadow_bounce", [](TrainConfig& c) { c.shadow_bounce = 0.25; }},
        {"ground_backdrop", [](TrainConfig& c) { c.ground_backdrop = true; }},
        {"grazing_side_degrees", [](TrainConfig& c) { c.grazing_side_degrees = 5.0; }},
        {"checkpoint_interval", [](TrainConfig& c) { c.checkpoint_interval = 0; }},
        {"log_interval", [](TrainConfig& c) { c.log_interval = 1; }},
    };
}

// ---- Presets
// ------------------------------------------------------------------------------------------------

TEST(TrainConfigPreset, PaperIsTheStructDefaults) {
    EXPECT_EQ(train_config_to_json(train_preset("paper")), train_config_to_json(TrainConfig{}));
    EXPECT_EQ(train_preset("paper").preset, "paper");
}

TEST(TrainConfigPreset, PaperHasTheOfficialValues) {
    const TrainConfig c = train_preset("paper");
    EXPECT_EQ(c.seed, 0u);
    EXPECT_EQ(c.downscale, 1);
    EXPECT_EQ(c.iterations, 40000);
    EXPECT_EQ(c.warmup, 20000);
    EXPECT_EQ(c.start_shadowed, 20500);
    EXPECT_EQ(c.start_regularization, 6000);
    EXPECT_EQ(c.lambda_dssim, 0.2);
    EXPECT_EQ(c.lambda_unshadowed_stage3, 0.001);
    EXPECT_EQ(c.lambda_range01, 0.001);
    EXPECT_EQ(c.lambda_env, 0.05);
    EXPECT_EQ(c.lambda_consistency, 10.0);
    EXPECT_EQ(c.lambda_shadow, 10.0);
    EXPECT_EQ(c.lambda_normal, 0.05);
    EXPECT_EQ(c.lambda_distortion, 100.0);
    EXPECT_EQ(c.env_noise_sigma, 0.025);
    EXPECT_EQ(c.transfer_samples, 25);
    EXPECT_EQ(c.env_samples, 10);
    EXPECT_EQ(c.lr_position_init, 1.6e-4);
    EXPECT_EQ(c.lr_position_final, 1.6e-6);
    EXPECT_EQ(c.lr_position_max_steps, 30000);
    EXPECT_EQ(c.lr_transfer, 0.002);
    EXPECT_EQ(c.lr_opacity, 0.05);
    EXPECT_EQ(c.lr_scaling, 0.005);
    EXPECT_EQ(c.lr_rotation, 0.001);
    EXPECT_EQ(c.lr_albedo, 0.0025);
    EXPECT_EQ(c.lr_embedding, 0.002);
    EXPECT_EQ(c.lr_mlp, 0.002);
    EXPECT_EQ(c.lr_env_final_ratio, 10.0);
    EXPECT_EQ(c.densify_from, 500);
    EXPECT_EQ(c.densify_until, 15000);
    EXPECT_EQ(c.densify_interval, 500);
    EXPECT_EQ(c.opacity_reset_interval, 3000);
    EXPECT_EQ(c.densify_grad_threshold, 0.0002);
    EXPECT_EQ(c.min_opacity, 0.05);
    EXPECT_EQ(c.opacity_reset_value, 0.01);
    EXPECT_EQ(c.max_screen_size, 20.0);
    EXPECT_EQ(c.percent_dense, 0.01);
    EXPECT_TRUE(c.faithful_radii_reset);
    EXPECT_EQ(c.checkpoint_interval, 1000);
    EXPECT_EQ(c.log_interval, 10);
}

TEST(TrainConfigPreset, PaperFastShrinksTheScheduleOnly) {
    const TrainConfig fast = train_preset("paper-fast");
    EXPECT_EQ(fast.preset, "paper-fast");
    EXPECT_EQ(fast.iterations, 3000);
    EXPECT_EQ(fast.warmup, 1500);
    EXPECT_EQ(fast.start_shadowed, 1600);
    EXPECT_EQ(fast.start_regularization, 500);
    EXPECT_EQ(fast.lr_position_max_steps, 2250);
    EXPECT_EQ(fast.densify_from, 100);
    EXPECT_EQ(fast.densify_until, 1200);
    EXPECT_EQ(fast.densify_interval, 100);
    EXPECT_EQ(fast.opacity_reset_interval, 600);
    EXPECT_EQ(fast.checkpoint_interval, 500);
    EXPECT_EQ(fast.held_out_interval, 1000);

    // Everything else as paper: the JSONs differ in exactly the keys above.
    const Json f = Json::parse(train_config_to_json(fast));
    const Json p = Json::parse(train_config_to_json(train_preset("paper")));
    const std::set<std::string> expected = {"preset",
                                            "iterations",
                                            "warmup",
                                            "start_shadowed",
                                            "start_regularization",
                                            "lr_position_max_steps",
                                            "densify_from",
                                            "densify_until",
                                            "densify_interval",
                                            "held_out_interval",
                                            "opacity_reset_interval",
                                            "checkpoint_interval",
                                            "background_alpha_from"};
    std::set<std::string> differing;
    for (const auto& item : p.items()) {
        if (f.at(item.key()) != item.value()) differing.insert(item.key());
    }
    EXPECT_EQ(differing, expected);
}

// The default presets are the paper's (and paper-fast's) plus the improvements of issue #25, each a key.
TEST(TrainConfigPreset, DefaultAndFastAddTheImprovementsToThePaper) {
    const std::set<std::string> improvements = {"init_normals_from_points",
                                                "sky_background",
                                                "lambda_sky_alpha",
                                                "sky_free_regularizers",
                                                "lambda_background_alpha",
                                                "prune_until_end",
                                                "densify_near_fraction",
                                                "downscale",
                                                "sky_horizon_start",
                                                "sky_horizon_fade",
                                                "ground_seeds",
                                                "empty_space_prune_share",
                                                "ground_backdrop",
                                                "grazing_side_degrees",
                                                "min_contribution_pixels",
                                                "sky_residual",
                                                "lambda_sky_residual",
                                                "sky_pins_light",
                                                "lambda_ground_light",
                                                "ground_light_albedo",
                                                "lambda_sky_hemisphere"};
    for (const auto& [improved, base] : {std::pair{"default", "paper"}, std::pair{"fast", "paper-fast"}}) {
        SCOPED_TRACE(improved);
        const Json a = Json::parse(train_config_to_json(train_preset(improved)));
        const Json b = Json::parse(train_config_to_json(train_preset(base)));
        std::set<std::string> differing;
        for (const auto& item : b.items())
            if (a.at(item.key()) != item.value()) differing.insert(item.key());
        std::set<std::string> expected = improvements;
        expected.insert("preset");
        // Traced shadows: measured on the fast schedule only (train_preset).
        if (std::string(improved) == "fast") expected.insert("geometric_transfer_every");
        EXPECT_EQ(differing, expected);
        EXPECT_EQ(a.at("preset"), improved);
    }
    // The paper preset keeps every improvement off.
    const TrainConfig paper = train_preset("paper");
    EXPECT_FALSE(paper.init_normals_from_points || paper.sky_background || paper.prune_until_end);
    EXPECT_EQ(paper.lambda_sky_alpha, 0.0);
    EXPECT_EQ(paper.lambda_background_alpha, 0.0);
    EXPECT_EQ(paper.sky_horizon_fade, 0.0);
    EXPECT_EQ(paper.empty_space_prune_share, 0.0);
    EXPECT_EQ(paper.min_contribution_pixels, 0.0);
    EXPECT_EQ(paper.min_ground_views, 0);
    EXPECT_EQ(paper.geometric_transfer_every, 0);
    EXPECT_EQ(train_preset("default").geometric_transfer_every, 0);
    EXPECT_EQ(train_preset("fast").geometric_transfer_every, 500);
    EXPECT_EQ(paper.lambda_sky_hemisphere, 0.0);
    EXPECT_EQ(train_preset("default").lambda_sky_hemisphere, 1.0);
    EXPECT_EQ(train_preset("fast").lambda_sky_hemisphere, 1.0);
    EXPECT_FALSE(paper.ground_backdrop);
    EXPECT_FALSE(paper.ground_seeds);
    EXPECT_EQ(paper.grazing_side_degrees, 0.0);
    EXPECT_EQ(paper.lambda_ground_light, 0.0);
    EXPECT_TRUE(paper.sky_pins_light);
    EXPECT_FALSE(train_preset("default").sky_pins_light);
    EXPECT_FALSE(train_preset("fast").sky_pins_light);
}

TEST(TrainConfigPreset, EveryPresetValidates) {
    for (const std::string& name : train_preset_names())
        EXPECT_NO_THROW(validate_train_config(train_preset(name)));
}

TEST(TrainConfigPreset, UnknownNameListsTheValidOnes) {
    const std::string message = error_of([] { (void)train_preset("quick"); });
    EXPECT_THAT(message,
                AllOf(HasSubstr("'quick'"), HasSubstr("default"), HasSubstr("paper"), HasSubstr("fast")));
    EXPECT_THROW((void)train_preset(""), Error);
    EXPECT_THROW((void)train_preset("Paper"), Error);
}

// ---- The field list
// -----------------------------------------------------------------------------------------

TEST(TrainConfigFields, JsonHasOneKeyPerMember) {
    const Json j = Json::parse(train_config_to_json(TrainConfig{}));
    ASSERT_TRUE(j.is_object());
    const std::vector<MemberChange> members = every_member();
    // The list above covers every member of the struct (update it when a field is added) ...
    static_assert(member_count<TrainConfig>() == 78, "a TrainConfig member was added or removed");
    ASSERT_EQ(members.size(), member_count<TrainConfig>());
    // ... and the JSON has exactly those keys.
    std::set<std::string> names;
    for (const MemberChange& m : members) names.insert(m.key);
    EXPECT_EQ(names.size(), members.size());
    std::set<std::string> keys;
    for (const auto& item : j.items()) keys.insert(item.key());
    EXPECT_EQ(j.size(), members.size());
    EXPECT_EQ(keys, names);
}

TEST(TrainConfigFields, EveryMemberRoundTripsThroughJsonAndSet) {
    const Json defaults = Json::parse(train_config_to_json(TrainConfig{}));
    for (const MemberChange& m : every_member()) {
        SCOPED_TRACE(m.key);
        TrainConfig changed;
        m.change(changed);
        const std::string text = train_config_to_json(changed);
        const Json j = Json::parse(text);

        // Exactly this key differs from the defaults.
        for (const auto& item : defaults.items()) {
            if (item.key() == m.key) {
                EXPECT_NE(j.at(item.key()), item.value());
            } else {
                EXPECT_EQ(j.at(item.key()), item.value()) << item.key();
            }
        }

        // The whole file read back onto a default config reproduces it.
        TrainConfig from_file;
        apply_train_config_json(from_file, text, "config.json");
        EXPECT_EQ(train_config_to_json(from_file), text);

        if (m.key == "preset") continue;  // alone, the preset key loads the preset (tested below)

        // The single key, as JSON and as --set key=value.
        TrainConfig from_key;
        apply_train_config_json(from_key, Json{{m.key, j.at(m.key)}}.dump(), "--config");
        EXPECT_EQ(train_config_to_json(from_key), text);
        TrainConfig from_set;
        const Json& value = j.at(m.key);
        apply_train_config_override(
            from_set, m.key + "=" + (value.is_string() ? value.get<std::string>() : value.dump()));
        EXPECT_EQ(train_config_to_json(from_set), text);
    }
}

TEST(TrainConfigFields, JsonTypesAndLayout) {
    TrainConfig c;
    c.seed = 18446744073709551615ull;
    const std::string text = train_config_to_json(c);
    EXPECT_EQ(text.substr(0, 2), "{\n");
    EXPECT_THAT(text, HasSubstr("\n  \"preset\": \"paper\",\n"));
    EXPECT_THAT(text, HasSubstr("\n  \"iterations\": 40000,\n"));
    EXPECT_THAT(text, HasSubstr("\n  \"seed\": 18446744073709551615,\n"));
    EXPECT_EQ(text.substr(text.size() - 2), "}\n");

    const Json j = Json::parse(text);
    EXPECT_TRUE(j.at("preset").is_string());
    EXPECT_TRUE(j.at("seed").is_number_unsigned());
    EXPECT_EQ(j.at("seed").get<std::uint64_t>(), c.seed);
    for (const char* key :
         {"downscale", "iterations", "warmup", "start_shadowed", "start_regularization", "transfer_samples",
          "env_samples", "lr_position_max_steps", "densify_from", "densify_until", "densify_interval",
          "opacity_reset_interval", "checkpoint_interval", "log_interval"}) {
        EXPECT_TRUE(j.at(key).is_number_integer()) << key;
    }
    // Doubles stay doubles even when integral (10.0 is written as a float, not as 10).
    for (const char* key : {"lambda_consistency", "lambda_distortion", "lambda_shadow", "max_screen_size",
                            "lr_env_final_ratio", "env_noise_sigma", "lr_position_init"}) {
        EXPECT_TRUE(j.at(key).is_number_float()) << key;
    }
    EXPECT_TRUE(j.at("faithful_radii_reset").is_boolean());
}

// ---- JSON
// ---------------------------------------------------------------------------------------------------

TEST(TrainConfigJson, RoundTripOfPresetsAndChangedValues) {
    for (const char* name : {"paper", "fast"}) {
        TrainConfig c = train_preset(name);
        c.seed = 42;
        c.lambda_dssim = 0.1 + 0.2;
        c.lr_position_init = 1.0 / 3.0 * 1e-4;
        c.faithful_radii_reset = false;
        const std::string text = train_config_to_json(c);
        TrainConfig back;  // paper defaults
        apply_train_config_json(back, text, "config.json");
        EXPECT_EQ(back.preset, name);
        EXPECT_EQ(back.seed, 42u);
        EXPECT_EQ(back.lambda_dssim, 0.1 + 0.2);
        EXPECT_EQ(back.lr_position_init, 1.0 / 3.0 * 1e-4);
        EXPECT_FALSE(back.faithful_radii_reset);
        EXPECT_EQ(back.iterations, c.iterations);
        EXPECT_EQ(train_config_to_json(back), text);
    }
}

TEST(TrainConfigJson, PartialObjectKeepsOtherValues) {
    TrainConfig c = train_preset("fast");
    c.lambda_shadow = 3.0;
    apply_train_config_json(c, R"({"iterations": 5000, "lambda_normal": 0.1, "env_samples": 4})",
                            "partial.json");
    EXPECT_EQ(c.preset, "fast");
    EXPECT_EQ(c.iterations, 5000);
    EXPECT_EQ(c.lambda_normal, 0.1);
    EXPECT_EQ(c.env_samples, 4);
    EXPECT_EQ(c.lambda_shadow, 3.0);  // kept
    EXPECT_EQ(c.warmup, 1500);        // kept from fast

    TrainConfig unchanged = train_preset("fast");
    apply_train_config_json(unchanged, "{}", "empty.json");
    EXPECT_EQ(train_config_to_json(unchanged), train_config_to_json(train_preset("fast")));
}

TEST(TrainConfigJson, PresetKeyResetsBeforeTheOtherKeys) {
    for (const char* text :
         {R"({"preset": "fast", "iterations": 4000})", R"({"iterations": 4000, "preset": "fast"})"}) {
        SCOPED_TRACE(text);
        TrainConfig c;
        c.lambda_shadow = 3.0;  // reset by the preset
        apply_train_config_json(c, text, "config.json");
        EXPECT_EQ(c.preset, "fast");
        EXPECT_EQ(c.iterations, 4000);  // applied after the reset, wherever it is in the object
        EXPECT_EQ(c.warmup, 1500);
        EXPECT_EQ(c.lambda_shadow, 10.0);
    }
    TrainConfig c = train_preset("fast");
    apply_train_config_json(c, R"({"preset": "paper"})", "config.json");
    EXPECT_EQ(train_config_to_json(c), train_config_to_json(TrainConfig{}));
}

TEST(TrainConfigJson, IntegralNumbersAcceptedForIntegerAndDoubleFields) {
    // Choice: an integer field accepts a float with an exact integer value (3.0, 3e4); a double field
    // accepts an integer.
    TrainConfig c;
    apply_train_config_json(c, R"({"iterations": 3e4, "downscale": 2.0, "seed": 7.0, "lambda_shadow": 5})",
                            "c.json");
    EXPECT_EQ(c.iterations, 30000);
    EXPECT_EQ(c.downscale, 2);
    EXPECT_EQ(c.seed, 7u);
    EXPECT_EQ(c.lambda_shadow, 5.0);
}

TEST(TrainConfigJson, NotJsonOrNotAnObject) {
    EXPECT_THAT(json_error("{\"iterations\": 10,}"),
                AllOf(HasSubstr("run/config.json"), HasSubstr("not valid JSON")));
    EXPECT_THAT(json_error(""), AllOf(HasSubstr("run/config.json"), HasSubstr("not valid JSON")));
    EXPECT_THAT(json_error("{\"iterations\": 10} trailing"), HasSubstr("not valid JSON"));
    // A number out of double's range was an internal error (nlohmann's out_of_range), found by
    // fuzz_train_config.
    EXPECT_THAT(json_error("{\"lambda_shadow\": 1e400}"),
                AllOf(HasSubstr("run/config.json"), HasSubstr("not valid JSON")));
    for (const char* text : {"[1, 2]", "42", "\"paper\"", "null"}) {
        EXPECT_THAT(json_error(text, "--config"), AllOf(HasSubstr("--config"), HasSubstr("object"))) << text;
    }
}

TEST(TrainConfigJson, UnknownKeyIsNamedWithAHint) {
    EXPECT_THAT(json_error(R"({"iteration": 10})"),
                AllOf(HasSubstr("run/config.json"), HasSubstr("unknown key 'iteration'"),
                      HasSubstr("did you mean 'iterations'")));
    EXPECT_THAT(json_error(R"({"lambda_dsim": 0.2})"), HasSubstr("did you mean 'lambda_dssim'"));
    const std::string far = json_error(R"({"xyz": 1})");
    EXPECT_THAT(far, AllOf(HasSubstr("run/config.json"), HasSubstr("unknown key 'xyz'")));
    EXPECT_THAT(far, ::testing::Not(HasSubstr("did you mean")));
}

TEST(TrainConfigJson, WrongTypesNameSourceKeyAndExpectedType) {
    struct Case {
        std::string text, key, expected;
    };
    const std::vector<Case> cases = {
        {R"({"iterations": "3000"})", "'iterations'", "integer"},
        {R"({"iterations": 3.5})", "'iterations'", "integer"},
        {R"({"iterations": true})", "'iterations'", "integer"},
        {R"({"iterations": null})", "'iterations'", "integer"},
        {R"({"iterations": 1e30})", "'iterations'", "integer"},
        {R"({"downscale": 3000000000})", "'downscale'", "integer"},
        {R"({"transfer_samples": [25]})", "'transfer_samples'", "integer"},
        {R"({"lambda_shadow": "10"})", "'lambda_shadow'", "number"},
        {R"({"lr_mlp": {"value": 1}})", "'lr_mlp'", "number"},
        {R"({"seed": -1})", "'seed'", "non-negative integer"},
        {R"({"seed": 1.5})", "'seed'", "non-negative integer"},
        {R"({"seed": "7"})", "'seed'", "non-negative integer"},
        {R"({"faithful_radii_reset": 1})", "'faithful_radii_reset'", "boolean"},
        {R"({"faithful_radii_reset": "true"})", "'faithful_radii_reset'", "boolean"},
        {R"({"preset": 1})", "'preset'", "string"},
    };
    for (const Case& c : cases) {
        EXPECT_THAT(json_error(c.text),
                    AllOf(HasSubstr("run/config.json"), HasSubstr(c.key), HasSubstr(c.expected)))
            << c.text;
    }
    EXPECT_THAT(
        json_error(R"({"preset": "quick"})"),
        AllOf(HasSubstr("run/config.json"), HasSubstr("'preset'"), HasSubstr("'quick'"), HasSubstr("fast")));
}

TEST(TrainConfigJson, FailureLeavesTheConfigUnchanged) {
    TrainConfig c = train_preset("fast");
    const std::string before = train_config_to_json(c);
    EXPECT_THROW(apply_train_config_json(c, R"({"preset": "paper", "iterations": 10, "bogus": 1})", "c.json"),
                 Error);
    EXPECT_THROW(apply_train_config_json(c, R"({"iterations": 10, "warmup": "x"})", "c.json"), Error);
    EXPECT_EQ(train_config_to_json(c), before);
}

// ---- --set key=value
// ----------------------------------------------------------------------------------------

TEST(TrainConfigOverride, ParsesEachFieldType) {
    TrainConfig c;
    apply_train_config_override(c, "iterations=3000");
    apply_train_config_override(c, "downscale=2");
    apply_train_config_override(c, "seed=18446744073709551615");
    apply_train_config_override(c, "lambda_shadow=2.5e-1");
    apply_train_config_override(c, "lr_mlp=+0.004");
    apply_train_config_override(c, "lambda_normal=1");
    apply_train_config_override(c, " warmup = 100 ");  // whitespace around key and value is ignored
    EXPECT_EQ(c.iterations, 3000);
    EXPECT_EQ(c.downscale, 2);
    EXPECT_EQ(c.seed, 18446744073709551615ull);
    EXPECT_EQ(c.lambda_shadow, 0.25);
    EXPECT_EQ(c.lr_mlp, 0.004);
    EXPECT_EQ(c.lambda_normal, 1.0);
    EXPECT_EQ(c.warmup, 100);
    EXPECT_EQ(c.preset, "paper");
}

TEST(TrainConfigOverride, BoolSpellings) {
    TrainConfig c;
    for (const auto& [text, value] : std::vector<std::pair<std::string, bool>>{
             {"false", false}, {"true", true}, {"0", false}, {"1", true}}) {
        apply_train_config_override(c, "faithful_radii_reset=" + text);
        EXPECT_EQ(c.faithful_radii_reset, value) << text;
    }
    for (const char* bad : {"yes", "no", "2", "", "TRUEX", "-1"}) {
        EXPECT_THAT(set_error(std::string("faithful_radii_reset=") + bad),
                    AllOf(HasSubstr("'faithful_radii_reset'"), HasSubstr("true, false, 1 or 0")))
            << bad;
    }
}

TEST(TrainConfigOverride, PresetResetsEverything) {
    TrainConfig c;
    c.lambda_shadow = 3.0;
    apply_train_config_override(c, "preset=fast");
    EXPECT_EQ(train_config_to_json(c), train_config_to_json(train_preset("fast")));
    apply_train_config_override(c, "preset=paper");
    EXPECT_EQ(train_config_to_json(c), train_config_to_json(TrainConfig{}));
    EXPECT_THAT(set_error("preset=quick"),
                AllOf(HasSubstr("'preset'"), HasSubstr("'quick'"), HasSubstr("paper")));
}

TEST(TrainConfigOverride, MissingEqualsExplainsTheFormat) {
    EXPECT_THAT(set_error("iterations"), AllOf(HasSubstr("iterations"), HasSubstr("key=value")));
    EXPECT_THAT(set_error(""), HasSubstr("key=value"));
    EXPECT_THAT(set_error("=5"), HasSubstr("key=value"));
}

TEST(TrainConfigOverride, UnknownKey) {
    EXPECT_THAT(set_error("iteratoins=10"),
                AllOf(HasSubstr("--set"), HasSubstr("unknown key 'iteratoins'"), HasSubstr("'iterations'")));
    EXPECT_THAT(set_error("nothing_like_it=1"), HasSubstr("unknown key 'nothing_like_it'"));
}

TEST(TrainConfigOverride, BadValuesAreRejectedWholly) {
    struct Case {
        std::string text, key, expected;
    };
    const std::vector<Case> cases = {
        {"iterations=12abc", "'iterations'", "integer"},
        {"iterations=", "'iterations'", "integer"},
        {"iterations=3.5", "'iterations'", "integer"},
        {"iterations=1e3", "'iterations'", "integer"},
        {"iterations=0x10", "'iterations'", "integer"},
        {"iterations=99999999999999999999", "'iterations'", "integer"},
        {"iterations=++1", "'iterations'", "integer"},
        {"downscale=3000000000", "'downscale'", "integer"},
        {"seed=-1", "'seed'", "non-negative integer"},
        {"seed=18446744073709551616", "'seed'", "non-negative integer"},
        {"lambda_shadow=abc", "'lambda_shadow'", "number"},
        {"lambda_shadow=1.5x", "'lambda_shadow'", "number"},
        {"lambda_shadow=nan", "'lambda_shadow'", "finite number"},
        {"lambda_shadow=inf", "'lambda_shadow'", "finite number"},
        {"lambda_shadow=1e999", "'lambda_shadow'", "finite number"},
        {"lambda_shadow=1,5", "'lambda_shadow'", "number"},
    };
    for (const Case& c : cases) {
        EXPECT_THAT(set_error(c.text), AllOf(HasSubstr("--set"), HasSubstr(c.key), HasSubstr(c.expected)))
            << c.text;
    }
    TrainConfig c;
    EXPECT_THROW(apply_train_config_override(c, "iterations=12abc"), Error);
    EXPECT_EQ(c.iterations, 40000);
    // A negative value parses (validation rejects it later).
    apply_train_config_override(c, "iterations=-5");
    EXPECT_EQ(c.iterations, -5);
}

// ---- Validation
// ---------------------------------------------------------------------------------------------

TEST(TrainConfigValidate, RejectsEachBadValueNamingTheKey) {
    struct Case {
        std::string key;
        std::function<void(TrainConfig&)> change;
    };
    const std::vector<Case> cases = {
        {"iterations", [](TrainConfig& c) { c.iterations = 0; }},
        {"iterations", [](TrainConfig& c) { c.iterations = -1; }},
        {"warmup", [](TrainConfig& c) { c.warmup = 0; }},
        {"warmup", [](TrainConfig& c) { c.warmup = c.start_shadowed + 1; }},
        {"start_regularization", [](TrainConfig& c) { c.start_regularization = -1; }},
        {"downscale", [](TrainConfig& c) { c.downscale = 3; }},
        {"downscale", [](TrainConfig& c) { c.downscale = -1; }},
        {"downscale", [](TrainConfig& c) { c.downscale = 16; }},
        {"transfer_samples", [](TrainConfig& c) { c.transfer_samples = 0; }},
        {"env_samples", [](TrainConfig& c) { c.env_samples = -2; }},
        {"transfer_samples", [](TrainConfig& c) { c.transfer_samples = 100000; }},  // ran for hours
        {"env_samples", [](TrainConfig& c) { c.env_samples = 5000; }},
        {"lambda_dssim", [](TrainConfig& c) { c.lambda_dssim = -0.1; }},
        {"lambda_unshadowed_stage3", [](TrainConfig& c) { c.lambda_unshadowed_stage3 = -1e-9; }},
        {"lambda_range01", [](TrainConfig& c) { c.lambda_range01 = -1; }},
        {"lambda_env", [](TrainConfig& c) { c.lambda_env = -1; }},
        {"lambda_consistency", [](TrainConfig& c) { c.lambda_consistency = -1; }},
        {"lambda_shadow", [](TrainConfig& c) { c.lambda_shadow = -1; }},
        {"lambda_normal", [](TrainConfig& c) { c.lambda_normal = -1; }},
        {"lambda_distortion", [](TrainConfig& c) { c.lambda_distortion = -1; }},
        {"env_noise_sigma", [](TrainConfig& c) { c.env_noise_sigma = -0.01; }},
        {"lr_position_init", [](TrainConfig& c) { c.lr_position_init = -1e-4; }},
        {"lr_position_final", [](TrainConfig& c) { c.lr_position_final = -1e-6; }},
        {"lr_position_final",
         [](TrainConfig& c) { c.lr_position_final = 0.0; }},  // log-linear needs both > 0
        {"lr_position_max_steps", [](TrainConfig& c) { c.lr_position_max_steps = 0; }},
        {"lr_transfer", [](TrainConfig& c) { c.lr_transfer = -1; }},
        {"lr_opacity", [](TrainConfig& c) { c.lr_opacity = -1; }},
        {"lr_scaling", [](TrainConfig& c) { c.lr_scaling = -1; }},
        {"lr_rotation", [](TrainConfig& c) { c.lr_rotation = -1; }},
        {"lr_albedo", [](TrainConfig& c) { c.lr_albedo = -1; }},
        {"lr_embedding", [](TrainConfig& c) { c.lr_embedding = -1; }},
        {"lr_mlp", [](TrainConfig& c) { c.lr_mlp = -1; }},
        {"lr_env_final_ratio", [](TrainConfig& c) { c.lr_env_final_ratio = 0.0; }},
        {"lr_env_final_ratio", [](TrainConfig& c) { c.lr_env_final_ratio = -10.0; }},
        {"densify_from", [](TrainConfig& c) { c.densify_from = -1; }},
        {"densify_until", [](TrainConfig& c) { c.densify_until = -1; }},
        {"densify_interval", [](TrainConfig& c) { c.densify_interval = 0; }},
        {"opacity_reset_interval", [](TrainConfig& c) { c.opacity_reset_interval = 0; }},
        {"densify_grad_threshold", [](TrainConfig& c) { c.densify_grad_threshold = -1e-4; }},
        {"lambda_ground_light", [](TrainConfig& c) { c.lambda_ground_light = -1.0; }},
        {"ground_light_albedo", [](TrainConfig& c) { c.ground_light_albedo = -0.1; }},
        {"ground_light_albedo", [](TrainConfig& c) { c.ground_light_albedo = 1.5; }},
        {"grazing_side_degrees", [](TrainConfig& c) { c.grazing_side_degrees = -1.0; }},
        {"grazing_side_degrees", [](TrainConfig& c) { c.grazing_side_degrees = 60.0; }},
        {"min_opacity", [](TrainConfig& c) { c.min_opacity = -0.01; }},
        {"min_opacity", [](TrainConfig& c) { c.min_opacity = 1.0; }},
        {"opacity_reset_value", [](TrainConfig& c) { c.opacity_reset_value = 0.0; }},
        {"opacity_reset_value", [](TrainConfig& c) { c.opacity_reset_value = 1.0; }},
        {"max_screen_size", [](TrainConfig& c) { c.max_screen_size = -1; }},
        {"percent_dense", [](TrainConfig& c) { c.percent_dense = 0.0; }},
        {"checkpoint_interval", [](TrainConfig& c) { c.checkpoint_interval = -1; }},
        {"log_interval", [](TrainConfig& c) { c.log_interval = 0; }},
        {"held_out_interval", [](TrainConfig& c) { c.held_out_interval = -1; }},
        {"lambda_shadow", [](TrainConfig& c) { c.lambda_shadow = std::numeric_limits<double>::quiet_NaN(); }},
        {"lr_mlp", [](TrainConfig& c) { c.lr_mlp = std::numeric_limits<double>::infinity(); }},
        {"sky_horizon_start", [](TrainConfig& c) { c.sky_horizon_start = -1; }},
        {"sky_horizon_fade", [](TrainConfig& c) { c.sky_horizon_fade = -1; }},
        {"sky_horizon_fade", [](TrainConfig& c) { c.sky_horizon_start = 60, c.sky_horizon_fade = 40; }},
        {"empty_space_prune_share", [](TrainConfig& c) { c.empty_space_prune_share = -0.1; }},
        {"empty_space_prune_share", [](TrainConfig& c) { c.empty_space_prune_share = 1.5; }},
        {"min_contribution_pixels", [](TrainConfig& c) { c.min_contribution_pixels = -1; }},
        {"min_contribution_pixels", [](TrainConfig& c) { c.min_contribution_pixels = 1e9; }},
        {"min_ground_views", [](TrainConfig& c) { c.min_ground_views = -1; }},
        {"min_ground_views", [](TrainConfig& c) { c.min_ground_views = 1001; }},
        {"geometric_transfer_every", [](TrainConfig& c) { c.geometric_transfer_every = -1; }},
        {"lambda_sky_hemisphere", [](TrainConfig& c) { c.lambda_sky_hemisphere = -0.5; }},
        {"shadow_bounce", [](TrainConfig& c) { c.shadow_bounce = -0.1; }},
        {"shadow_bounce", [](TrainConfig& c) { c.shadow_bounce = 1.5; }},
        {"lambda_scale_ratio", [](TrainConfig& c) { c.lambda_scale_ratio = -0.1; }},
        {"max_scale_ratio", [](TrainConfig& c) { c.max_scale_ratio = 0.5; }},
        {"max_scale_ratio", [](TrainConfig& c) { c.max_scale_ratio = 1e7; }},
    };
    for (const char* preset : {"paper", "fast"}) {
        for (const Case& c : cases) {
            TrainConfig config = train_preset(preset);
            c.change(config);
            EXPECT_THAT(error_of([&] { validate_train_config(config); }), HasSubstr(c.key + " = "))
                << preset << " " << c.key;
        }
    }
}

TEST(TrainConfigValidate, AcceptsTheAllowedEdgeCases) {
    const std::vector<std::function<void(TrainConfig&)>> allowed = {
        [](TrainConfig& c) { c.start_shadowed = c.iterations + 1000; },  // stage 3 never runs
        [](TrainConfig& c) {
            c.warmup = c.iterations + 10;  // stage 1 only
            c.start_shadowed = c.iterations + 20;
        },
        [](TrainConfig& c) { c.warmup = c.start_shadowed; },
        [](TrainConfig& c) { c.warmup = 1; },
        [](TrainConfig& c) { c.checkpoint_interval = 0; },
        [](TrainConfig& c) {
            c.lambda_consistency = 0.0;
            c.lambda_distortion = 0.0;
            c.env_noise_sigma = 0.0;
            c.lr_transfer = 0.0;
        },
        [](TrainConfig& c) {
            c.lr_position_init = 0.0;  // frozen positions
            c.lr_position_final = 0.0;
        },
        [](TrainConfig& c) { c.min_opacity = 0.0; },
        [](TrainConfig& c) { c.densify_until = c.densify_from - 1; },  // no densification
        [](TrainConfig& c) { c.downscale = 8; },
        [](TrainConfig& c) { c.iterations = 1; },
        [](TrainConfig& c) { c.empty_space_prune_share = 1.0; },  // removes none
    };
    for (std::size_t i = 0; i < allowed.size(); ++i) {
        TrainConfig c = train_preset("fast");
        allowed[i](c);
        EXPECT_NO_THROW(validate_train_config(c)) << "case " << i;
    }
}

}  // namespace
}  // namespace lumigauss

namespace lumigauss {
namespace {

// `train --preset fast --iterations 300` kept the stage boundaries at 1500/1600: the whole run was the
// unshadowed stage, its shadowed renders nearly black (eval: 10.0 dB shadowed on plaza_mini, 12.8 now).
TEST(TrainConfigSchedule, IterationsScaleTheStagesAndWindowsNotTheRhythms) {
    TrainConfig c = train_preset("fast");
    scale_schedule(c, 300);
    EXPECT_EQ(c.iterations, 300);
    EXPECT_EQ(c.warmup, 150);
    EXPECT_EQ(c.start_shadowed, 160);
    EXPECT_EQ(c.start_regularization, 50);
    EXPECT_EQ(c.lr_position_max_steps, 225);
    EXPECT_EQ(c.densify_from, 10);
    EXPECT_EQ(c.densify_until, 120);
    EXPECT_EQ(c.background_alpha_from, 10);
    EXPECT_EQ(c.densify_interval, 100);  // rhythms of photo visits: unchanged
    EXPECT_EQ(c.opacity_reset_interval, 600);
    EXPECT_EQ(c.checkpoint_interval, train_preset("fast").checkpoint_interval);
    EXPECT_NO_THROW(validate_train_config(c));
    EXPECT_EQ(
        schedule_summary(c),
        "stages: unshadowed 1-149, transfer fitting 150-160, shadowed 161-300; densification 10-120 every "
        "100, opacity reset every 600; shadows traced from the geometry every 500");

    // Tiny runs keep one transfer-fitting iteration and the stage order; longer ones stretch.
    TrainConfig tiny = train_preset("default");
    scale_schedule(tiny, 10);
    EXPECT_EQ(tiny.warmup, 5);
    EXPECT_EQ(tiny.start_shadowed, 6);
    TrainConfig longer = train_preset("fast");
    scale_schedule(longer, 30000);
    EXPECT_EQ(longer.warmup, 15000);
    EXPECT_EQ(longer.start_shadowed, 16000);
    EXPECT_EQ(longer.densify_until, 12000);
    EXPECT_THROW(scale_schedule(longer, 0), Error);
}

}  // namespace
}  // namespace lumigauss
