#include "lumigauss/synth/sky.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "lumigauss/shading/envmap.h"
#include "lumigauss/shading/irradiance.h"
#include "lumigauss/synth/rng.h"

namespace lumigauss::synth {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;

// Parameters of the analytic sky before it is projected to SH.
struct SkyParams {
    Vec3d zenith, horizon, ground;
    Vec3d glow;               // circumsolar brightening (added colour at the sun)
    double glow_width = 0.1;  // in 1 - cos(angle to the sun)
    double gradient = 0.5;    // exponent of the horizon-to-zenith blend
};

Vec3d lerp(Vec3d a, Vec3d b, double t) {
    return a + t * (b - a);
}

double luminance(Vec3d c) {
    return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
}

Vec3d analytic_sky(const SkyParams& p, Vec3d sun, Vec3d d) {
    if (d.z < 0) return p.ground;
    const Vec3d base = lerp(p.horizon, p.zenith, std::pow(d.z, p.gradient));
    return base + std::exp((dot(d, sun) - 1.0) / p.glow_width) * p.glow;
}

// L_lm = sum over a 64 x 128 grid of L(d) Y_lm(d) dOmega (exact pixel solid angles).
ShCoeffs<double> project_analytic_sky(const SkyParams& p, Vec3d sun) {
    constexpr int kW = 128, kH = 64;
    ShCoeffs<double> sh;
    for (int i = 0; i < kH; ++i) {
        const double d_omega = equirect_pixel_solid_angle(i, kW, kH);
        for (int j = 0; j < kW; ++j) {
            const Vec3d d = equirect_direction(i, j, kW, kH);
            double y[kShCount];
            sh_basis(d, y);
            const Vec3d l = analytic_sky(p, sun, d);
            for (int k = 0; k < kShCount; ++k) sh.c[k] += (y[k] * d_omega) * l;
        }
    }
    return sh;
}

// A degree-2 fit of a bright sky can dip below zero somewhere (ringing); raise the constant band until the
// radiance is at least 3% of its mean everywhere, so that the SH *is* a physical sky.
void make_non_negative(ShCoeffs<double>& sh) {
    constexpr double kFloor = 0.03;
    Vec3d lowest{1e300, 1e300, 1e300};
    for (int i = 0; i < 48; ++i)
        for (int j = 0; j < 96; ++j) {
            const Vec3d l = eval_sh(sh, equirect_direction(i, j, 96, 48));
            for (int c = 0; c < 3; ++c) lowest[c] = std::min(lowest[c], l[c]);
        }
    const double y00 = sh_const::kY00;
    for (int c = 0; c < 3; ++c) {
        const double mean = sh.c[0][c] * y00;
        if (lowest[c] < kFloor * mean) sh.c[0][c] += (kFloor * mean - lowest[c]) / (y00 * (1 - kFloor));
    }
}

// Sun colour: white when high, reddened through the long air path near the horizon.
Vec3d sun_colour(double elevation_deg) {
    const double w = std::exp(-(elevation_deg - 2.0) / 12.0);
    const Vec3d c{1.0, 1.0 - 0.28 * w, 1.0 - 0.62 * w};
    return c / luminance(c);
}

SkyParams clear_sky(Rng& rng, double elevation_deg) {
    const double warm = std::exp(-(elevation_deg - 2.0) / 15.0);  // 1 at sunrise/sunset, small at noon
    SkyParams p;
    p.zenith = hadamard(Vec3d{0.13, 0.26, 0.62}, Vec3d{rng.uniform(0.8, 1.2), rng.uniform(0.85, 1.15), 1.0});
    p.horizon = lerp(Vec3d{0.55, 0.62, 0.75}, Vec3d{0.80, 0.62, 0.45}, warm) * rng.uniform(0.8, 1.2);
    p.ground = Vec3d{0.13, 0.12, 0.10} * rng.uniform(0.7, 1.3);
    p.glow = rng.uniform(0.4, 1.2) * sun_colour(elevation_deg);
    p.glow_width = rng.uniform(0.04, 0.15);
    p.gradient = rng.uniform(0.35, 0.8);
    return p;
}

SkyParams overcast_sky(Rng& rng) {
    SkyParams p;
    const Vec3d grey{rng.uniform(0.85, 1.0), rng.uniform(0.88, 1.0), 1.0};
    p.zenith = 0.9 * grey;  // the CIE overcast sky: zenith about twice as bright as the horizon
    p.horizon = 0.42 * grey;
    p.ground = Vec3d{0.12, 0.12, 0.11} * rng.uniform(0.7, 1.3);
    p.glow = 0.25 * grey;  // a faint bright patch where the sun hides
    p.glow_width = 0.3;
    p.gradient = 1.0;
    return p;
}

// Sun direction snapped to the centre of an env-map pixel, so that the published map holds the sun exactly.
void place_sun(LightCondition& c, double elevation_deg, double azimuth_deg) {
    const double el = elevation_deg * kDeg, az = azimuth_deg * kDeg;
    const Vec3d d{std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)};
    const EquirectCoord pc = direction_to_equirect(d, kEnvWidth, kEnvHeight);
    c.sun_row = std::clamp(int(std::lround(pc.row)), 0, kEnvHeight - 1);
    c.sun_col = int(std::lround(pc.col)) % kEnvWidth;
    c.sun_dir = equirect_direction(c.sun_row, c.sun_col, kEnvWidth, kEnvHeight);
}

// Largest irradiance over upward and sideways normals (the upper hemisphere), over the channels.
double max_irradiance(const LightCondition& c) {
    double best = 0;
    for (int i = 0; i <= 16; ++i)
        for (int j = 0; j < 64; ++j) {
            const double theta = 0.5 * kPi * i / 16, phi = 2 * kPi * j / 64;
            const Vec3d n{std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
            const Vec3d e = sky_irradiance(c, n) + sun_irradiance(c, n);
            best = std::max({best, e.x, e.y, e.z});
        }
    // The sun direction itself is where the sun's term peaks.
    const Vec3d e = sky_irradiance(c, c.sun_dir) + sun_irradiance(c, c.sun_dir);
    return std::max({best, e.x, e.y, e.z});
}

LightCondition make_condition(int index, const std::string& split, std::uint64_t seed) {
    Rng rng(seed, Stream::kCondition, std::uint64_t(index));
    LightCondition c;
    char id[16];
    std::snprintf(id, sizeof id, "sky%02d", index);
    c.id = id, c.split = split;
    c.overcast = rng.bernoulli(0.2);
    const double elevation = rng.uniform(8.0, 70.0), azimuth = rng.uniform(-180.0, 180.0);
    place_sun(c, elevation, azimuth);
    const double snapped_elevation = sun_elevation_deg(c);
    const SkyParams sky = c.overcast ? overcast_sky(rng) : clear_sky(rng, snapped_elevation);
    c.sky_sh = project_analytic_sky(sky, c.sun_dir);
    make_non_negative(c.sky_sh);
    // Direct-to-diffuse ratio: a clear sun gives several times the sky's horizontal irradiance.
    const double ratio = c.overcast ? rng.uniform(0.03, 0.25) : rng.uniform(2.5, 6.0);
    const double sky_up = luminance(irradiance(c.sky_sh, Vec3d{0, 0, 1}));
    c.sun_power = ratio * sky_up * sun_colour(snapped_elevation);
    c.strength = kMaxIrradiance / max_irradiance(c);
    for (auto& k : c.sky_sh.c) k = c.strength * k;
    c.sun_power = c.strength * c.sun_power;
    return c;
}

// Mean of the Legendre polynomial P_l over a cap of half-angle alpha: the factor by which a uniform disc's
// SH band l differs from a point light of the same power.
double disc_band_factor(int l) {
    const double ca = std::cos(0.5 * kSunDiameterDeg * kDeg);
    return l == 0 ? 1.0 : (l == 1 ? 0.5 * (1 + ca) : 0.5 * ca * (1 + ca));
}

}  // namespace

std::vector<LightCondition> make_conditions(int n_train, int n_test, std::uint64_t seed) {
    std::vector<LightCondition> out;
    for (int i = 0; i < n_train + n_test; ++i)
        out.push_back(make_condition(i, i < n_train ? "train" : "test", seed));
    return out;
}

ShCoeffs<double> environment_sh(const LightCondition& c) {
    ShCoeffs<double> sh = c.sky_sh;
    double y[kShCount];
    sh_basis(c.sun_dir, y);
    for (int k = 0; k < kShCount; ++k) {
        const int band = k == 0 ? 0 : (k < 4 ? 1 : 2);
        sh.c[k] += (y[k] * disc_band_factor(band)) * c.sun_power;
    }
    return sh;
}

Vec3d sky_radiance(const LightCondition& c, Vec3d dir) {
    Vec3d l = eval_sh(c.sky_sh, dir);
    l = {std::max(l.x, 0.0), std::max(l.y, 0.0), std::max(l.z, 0.0)};
    const double cos_radius = std::cos(0.5 * kSunDiameterDeg * kDeg);
    if (dot(dir, c.sun_dir) >= cos_radius) l += c.sun_power / (2 * kPi * (1 - cos_radius));
    return l;
}

Vec3d sky_irradiance(const LightCondition& c, Vec3d n) {
    return irradiance(c.sky_sh, n);
}

Vec3d sun_irradiance(const LightCondition& c, Vec3d n) {
    return std::max(0.0, dot(n, c.sun_dir)) * c.sun_power;
}

Image environment_panorama(const LightCondition& c) {
    Image pano = render_sh_panorama(c.sky_sh, kEnvWidth, kEnvHeight);
    for (float& v : pano.pixels) v = std::max(v, 0.0f);
    const double d_omega = equirect_pixel_solid_angle(c.sun_row, kEnvWidth, kEnvHeight);
    for (int ch = 0; ch < 3; ++ch) pano.at(c.sun_col, c.sun_row, ch) += float(c.sun_power[ch] / d_omega);
    return pano;
}

double sun_elevation_deg(const LightCondition& c) {
    return std::asin(std::clamp(c.sun_dir.z, -1.0, 1.0)) / kDeg;
}

double sun_azimuth_deg(const LightCondition& c) {
    return std::atan2(c.sun_dir.y, c.sun_dir.x) / kDeg;
}

}  // namespace lumigauss::synth
