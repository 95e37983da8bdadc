#pragma once
// Which side of a two-sided surfel a camera sees: that side's normal shades it (unshadowed) and its
// transfer set (shadowed), shading/surfel_shading.h.
//
// Officially (research/lumigauss_official.md 2.1) the side facing the camera: positive when
// facing = -(W n) . p_view >= 0, with n the surfel's axis R[:,2] and p_view its centre in the camera frame.
//
// The grazing rule (a key of the trained run; off in the paper preset): a nearly level surfel (its axis
// within acos(kLevelSurfelCos) = 25.8 deg of the up) seen within `grazing_degrees` of its own plane shows its
// upper side. Why: training fits the ground with surfels tilted a few degrees at random, and a camera far
// away sees the ground at a grazing angle (34 m away at 1.55 m height: 2 deg), so a tilt of a few degrees
// away from that camera shows it the underside, whose camera-facing normal points down and shades it with the
// light from below: a dark blob in the near ground of new views (bench/RESULTS.md, session 36). Such a tilt
// is noise of the fit, not geometry: the photos saw the ground from above. Within that angle the side is
// set by the up instead, so the noise cannot flip it. Off the level (walls) and away from grazing angles
// the official rule holds.
#include <cmath>

#include "lumigauss/math/hd.h"
#include "lumigauss/math/vec.h"

namespace lumigauss {

// A surfel counts as level when |axis . up| exceeds this (within 25.8 deg of level).
inline constexpr float kLevelSurfelCos = 0.9f;

struct SurfelSideRule {
    Vec3f up{0, 0, 1};          // unit world up (the training photos' up)
    float grazing_degrees = 0;  // 0: the official rule for every surfel
    bool active() const { return grazing_degrees > 0; }
    // sin(grazing_degrees), the bound on facing / |p_view| below which a level surfel shows its upper side;
    // 0 when off.
    float grazing_sine() const {
        return active() ? float(std::sin(double(grazing_degrees) * 3.14159265358979323846 / 180.0)) : 0.0f;
    }
};

// True when the camera sees the positive side. `facing` = -(W n) . p_view, `distance` = |p_view|,
// `axis_up` = n . up (world), `grazing_sine` = SurfelSideRule::grazing_sine() (0: the official rule).
LG_HD_INLINE bool sees_positive_side(float facing, float distance, float axis_up, float grazing_sine) {
    if (grazing_sine > 0.0f && std::abs(axis_up) > kLevelSurfelCos &&
        std::abs(facing) < grazing_sine * distance)
        return axis_up > 0.0f;
    return facing >= 0.0f;
}

}  // namespace lumigauss
