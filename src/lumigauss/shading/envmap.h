#pragma once
// Equirectangular panoramas <-> degree-2 SH environments.
//
// The mapping, stated once (equirect_direction): a W x H panorama, pixel (row i, column j), pixel centres at
// integer indices, direction d in the panorama's own frame:
//   theta = pi (i + 0.5) / H              polar angle from +Z: row 0 is the zenith
//   phi   = 2 pi (0.5 - (j + 0.5) / W)    azimuth atan2(y, x): decreases to the right
//   d     = (sin theta cos phi, sin theta sin phi, cos theta)
// so the centre column looks along +X, a quarter width left of it along +Y, the edges along -X. This is the
// data/plaza README convention and Blender's Environment Texture (no rotation).
//
// `frame` places the panorama in the world: world direction = frame * panorama direction, so its columns are
// the world directions of the panorama's +X (centre column), +Y (quarter left) and +Z (top row); it must be a
// rotation. The identity suits z-up worlds (plaza, Blender). A y-down world (NeRF-OSR/COLMAP style, up = -Y)
// with the centre column along +X: rotation_about_axis(+X, +pi/2) (sh_rotation.h), columns (1,0,0), (0,0,1),
// (0,-1,0); a y-up world: rotation_about_axis(+X, -pi/2). A turn of the environment about the world's up axis
// composes on the left (frame = turn * frame).
#include "lumigauss/io/image.h"
#include "lumigauss/math/vec.h"
#include "lumigauss/shading/sh.h"

namespace lumigauss {

// Continuous pixel indices: pixel (i, j)'s centre is at (row, col) = (i, j).
struct EquirectCoord {
    double row = 0, col = 0;
};

// World direction (unit) of the continuous pixel position (row, col).
Vec3d equirect_direction(double row, double col, int width, int height,
                         const Mat3d& frame = Mat3d::identity());

// Inverse of equirect_direction for any non-zero world direction: row in [-0.5, H - 0.5], col in [-0.5, W -
// 0.5).
EquirectCoord direction_to_equirect(Vec3d dir, int width, int height, const Mat3d& frame = Mat3d::identity());

// Exact solid angle of every pixel of `row`: (2 pi / W)(cos(theta - pi/2H) - cos(theta + pi/2H)); the pixels
// of all rows sum to 4 pi.
double equirect_pixel_solid_angle(int row, int width, int height);

// Radiance SH L_lm = sum_pixels L(d) Y_lm(d) dOmega (exact pixel solid angles). A 1- or 2-channel panorama is
// taken as gray; with 3 or 4 channels, R, G, B are used and alpha is ignored. Throws Error on an empty image
// or a non-finite pixel.
ShCoeffs<double> project_panorama_to_sh(const Image& pano, const Mat3d& frame = Mat3d::identity());

// The SH radiance L(d) of every pixel's direction: a 3-channel W x H panorama.
Image render_sh_panorama(const ShCoeffs<double>& sh, int width, int height,
                         const Mat3d& frame = Mat3d::identity());

// The irradiance E(n) (shading/irradiance.h: not divided by pi) for n = every pixel's direction. Divide by pi
// for the radiance of a white Lambertian surface (the official "diffuse map").
Image render_irradiance_panorama(const ShCoeffs<double>& sh, int width, int height,
                                 const Mat3d& frame = Mat3d::identity());

// Brute-force irradiance of the panorama itself: E(n) = sum_pixels L(d) max(0, n.d) dOmega (no SH
// truncation). Channels as in project_panorama_to_sh; a non-finite pixel the normal sees is an Error.
Vec3d panorama_irradiance(const Image& pano, Vec3d normal, const Mat3d& frame = Mat3d::identity());

}  // namespace lumigauss
