// GLSL ES 3.00 sources. The per-splat and per-pixel maths mirror the C++ one source of truth:
//   projection, centre, reach and pixel bounds: src/lumigauss/render/surfel_projection.h (project_surfel)
//   ray-splat intersection, screen filter, alpha: src/lumigauss/render/surfel_kernel.h (evaluate_splat)
//   constants: src/lumigauss/render/raster_constants.h
//   shading: src/lumigauss/shading/surfel_shading.h and irradiance.h, the side choice of
//            shading/surfel_side.h (sees_positive_side: the side facing the camera, or with the run's grazing
//            rule the upper side of a level surfel seen within a few degrees of its plane)
//   shadow image: relight/relit_render.h (1 - clamp(luma(I_unshadowed - I_shadowed), 0, 1000))
//   normal image: render/raster_maps.h (encode_normals: (n/|n| + 1) / 2, black where |n| <= 1e-3)
import { Y00, Y1, Y2, Y20, Y22 } from './sh.js';

export const MODES = ['shadowed', 'unshadowed', 'albedo', 'normals', 'shadow'];
export const ORDER_WIDTH = 4096;  // texels per row of the order texture (a power of two)

const f = (v) => v.toPrecision(17).replace(/e\+?/, 'e');  // a GLSL float literal at full precision
const A0 = Math.PI, A1 = (2 * Math.PI) / 3, A2 = Math.PI / 4;

// Shared by the splat and the ball shaders: SH evaluation and the Ramamoorthi-Hanrahan irradiance with the
// constants derived as in irradiance.h (rh_const).
const SH_GLSL = `
uniform vec3 u_env[9];
const float kC1 = ${f(A2 * Y22)}, kC2 = ${f((A1 * Y1) / 2)}, kC3 = ${f(3 * A2 * Y20)};
const float kC4 = ${f(A0 * Y00)}, kC5 = ${f(A2 * Y20)};
vec3 irradiance(vec3 n) {
  float x = n.x, y = n.y, z = n.z;
  vec3 e = kC1 * (x * x - y * y) * u_env[8];
  e += kC3 * z * z * u_env[6];
  e += kC4 * u_env[0];
  e += -kC5 * u_env[6];
  e += 2.0 * kC1 * (x * y * u_env[4] + x * z * u_env[7] + y * z * u_env[5]);
  e += 2.0 * kC2 * (x * u_env[3] + y * u_env[1] + z * u_env[2]);
  return e;
}
vec3 radiance(vec3 d) {
  float x = d.x, y = d.y, z = d.z;
  return ${f(Y00)} * u_env[0] + ${f(Y1)} * (y * u_env[1] + z * u_env[2] + x * u_env[3]) +
         ${f(Y2)} * (x * y * u_env[4] + y * z * u_env[5] + x * z * u_env[7]) +
         ${f(Y20)} * (3.0 * z * z - 1.0) * u_env[6] + ${f(Y22)} * (x * x - y * y) * u_env[8];
}
// light_intensity: max(H, 1e-5)^(1/2.2), per channel.
vec3 intensity(vec3 h) { return pow(max(h, vec3(1e-5)), vec3(1.0 / 2.2)); }
`;

export const SPLAT_VS = `#version 300 es
precision highp float;
precision highp int;
precision highp sampler2D;
uniform sampler2D u_splats;
uniform int u_perRow;
uniform vec3 u_r0, u_r1, u_r2;  // world-to-camera rotation, rows
uniform vec3 u_t;
uniform vec4 u_intr;            // fx, fy, cx, cy (pixels, COLMAP conventions)
uniform vec2 u_size;            // width, height (pixels)
uniform int u_mode;             // index into MODES
uniform bool u_unitRange;       // no float target: signed values are encoded into [0, 1]
${SH_GLSL}
uniform highp usampler2D u_order;  // back-to-front surfel indices, ORDER_WIDTH per row
uniform vec3 u_sideUp;             // the run's side rule: the photos' up ...
uniform float u_grazingSine;       // ... and sin(grazing_degrees); 0: the side facing the camera
flat out vec3 v_pa, v_pb, v_pd, v_tw;
flat out vec4 v_centerOpacity;  // filter centre (pixels), opacity, rho cutoff
flat out vec3 v_colour;

const float kNear = 0.2, kAlphaMin = 1.0 / 255.0, kFilterInvSquare = 2.0, kSigma2 = 9.0;

void cull() { gl_Position = vec4(0.0, 0.0, 2.0, 1.0); }  // outside the clip volume: nothing is drawn

float conicDenominator(vec3 tw, float c2) { return c2 * (tw.x * tw.x + tw.y * tw.y) - tw.z * tw.z; }

// conic_box: centre (xy) and half extents (zw) of the image of the disk u^2 + v^2 <= c2.
vec4 conicBox(vec3 tu, vec3 tv, vec3 tw, float c2, float d) {
  vec3 f = vec3(c2 / d, c2 / d, -1.0 / d);
  vec2 c = vec2(dot(f, tu * tw), dot(f, tv * tw));
  float ex = c.x * c.x - dot(f, tu * tu), ey = c.y * c.y - dot(f, tv * tv);
  return vec4(c, sqrt(max(ex, 0.0)), sqrt(max(ey, 0.0)));
}

vec3 shade(vec4 t[8], vec3 normal, bool positive) {
  vec3 albedo = vec3(t[1].w, t[2].w, t[3].x);
  if (u_mode == 2) return albedo;
  if (u_mode == 3) return u_unitRange ? 0.5 * (normal + 1.0) : normal;
  if (u_mode == 1) return max(albedo * intensity(irradiance(normal)), 0.0);
  float T[9];
  if (positive) {
    T[0] = t[3].y; T[1] = t[3].z; T[2] = t[3].w; T[3] = t[4].x; T[4] = t[4].y; T[5] = t[4].z;
    T[6] = t[4].w; T[7] = t[5].x; T[8] = t[5].y;
  } else {
    T[0] = t[5].z; T[1] = t[5].w; T[2] = t[6].x; T[3] = t[6].y; T[4] = t[6].z; T[5] = t[6].w;
    T[6] = t[7].x; T[7] = t[7].y; T[8] = t[7].z;
  }
  vec3 s = vec3(0.0);
  for (int k = 0; k < 9; ++k) s += T[k] * u_env[k];
  if (u_mode == 0) return max(albedo * intensity(s), 0.0);
  float luma = dot(vec3(0.2126, 0.7152, 0.0722), intensity(irradiance(normal)) - intensity(s));
  return vec3(u_unitRange ? 1.0 - clamp(luma, 0.0, 1.0) : luma);
}

void main() {
  // No instancing (software renderers run instances one by one): vertex v is corner v & 3 of the quad of
  // sorted slot v >> 2, drawn with a static index buffer of two triangles per quad.
  int slot = gl_VertexID >> 2;
  int i = int(texelFetch(u_order, ivec2(slot & ${ORDER_WIDTH - 1}, slot >> ${Math.log2(ORDER_WIDTH)}), 0).r);
  ivec2 base = ivec2((i % u_perRow) * 8, i / u_perRow);
  vec4 t[8];
  for (int k = 0; k < 8; ++k) t[k] = texelFetch(u_splats, base + ivec2(k, 0), 0);
  float opacity = t[0].w;
  float reach = opacity > kAlphaMin ? 2.0 * log(opacity / kAlphaMin) * 1.0001 + 1e-6 : -1.0;
  vec3 mc = vec3(dot(u_r0, t[0].xyz), dot(u_r1, t[0].xyz), dot(u_r2, t[0].xyz)) + u_t;
  if (!(reach > 0.0) || !(mc.z > kNear)) { cull(); return; }
  vec3 nw = normalize(cross(t[1].xyz, t[2].xyz));
  vec3 a = vec3(dot(u_r0, t[1].xyz), dot(u_r1, t[1].xyz), dot(u_r2, t[1].xyz));
  vec3 b = vec3(dot(u_r0, t[2].xyz), dot(u_r1, t[2].xyz), dot(u_r2, t[2].xyz));
  vec3 nc = vec3(dot(u_r0, nw), dot(u_r1, nw), dot(u_r2, nw));
  float facing = -dot(mc, nc);
  if (facing == 0.0) { cull(); return; }
  float flip = facing > 0.0 ? 1.0 : -1.0;
  float axisUp = dot(nw, u_sideUp);  // sees_positive_side (shading/surfel_side.h)
  if (u_grazingSine > 0.0 && abs(axisUp) > ${f(0.9)} && abs(facing) < u_grazingSine * length(mc))
    flip = axisUp > 0.0 ? 1.0 : -1.0;
  float fx = u_intr.x, fy = u_intr.y, cx = u_intr.z, cy = u_intr.w;
  vec3 tu = vec3(fx * a.x + cx * a.z, fx * b.x + cx * b.z, fx * mc.x + cx * mc.z);
  vec3 tv = vec3(fy * a.y + cy * a.z, fy * b.y + cy * b.z, fy * mc.y + cy * mc.z);
  vec3 tw = vec3(a.z, b.z, mc.z);

  // Filter centre: the 3-sigma conic box centre, or the projected mean when that disk crosses the camera
  // plane or its centre runs far outside the image.
  float d3 = conicDenominator(tw, kSigma2);
  vec2 center = vec2(tu.z / tw.z, tv.z / tw.z);
  if (d3 < 0.0) {
    vec2 c = conicBox(tu, tv, tw, kSigma2, d3).xy;
    float margin = 2.0 * (u_size.x + u_size.y);
    if (c.x > -margin && u_size.x + margin > c.x && c.y > -margin && u_size.y + margin > c.y) center = c;
  }
  if (isnan(center.x) || isnan(center.y) || isinf(center.x) || isinf(center.y)) { cull(); return; }

  // The pixels it can reach: the reach ellipse and the filter disk, or everything when that ellipse crosses
  // the camera plane (the per-pixel near test then removes what lies behind).
  vec2 lo = vec2(0.0), hi = u_size;
  float dr = conicDenominator(tw, reach);
  if (dr < 0.0) {
    vec4 box = conicBox(tu, tv, tw, reach, dr);
    float filterRadius = sqrt(reach / kFilterInvSquare);
    lo = min(box.xy - box.zw, center - filterRadius);
    hi = max(box.xy + box.zw, center + filterRadius);
  }
  lo = clamp(lo, vec2(0.0), u_size);
  hi = clamp(hi, vec2(0.0), u_size);
  if (!(hi.x > lo.x && hi.y > lo.y)) { cull(); return; }

  v_pa = cross(tv, tw);
  v_pb = cross(tw, tu);
  v_pd = cross(center.x * tw - tu, center.y * tw - tv);
  v_tw = tw;
  v_centerOpacity = vec4(center, opacity, reach);
  v_colour = shade(t, flip * nw, flip > 0.0);
  vec2 corner = vec2(float(gl_VertexID & 1), float((gl_VertexID >> 1) & 1));
  vec2 p = mix(lo, hi, corner);
  gl_Position = vec4(p.x / u_size.x * 2.0 - 1.0, 1.0 - p.y / u_size.y * 2.0, 0.0, 1.0);
}
`;

export const SPLAT_FS = `#version 300 es
precision highp float;
uniform vec2 u_size;
flat in vec3 v_pa, v_pb, v_pd, v_tw;
flat in vec4 v_centerOpacity;
flat in vec3 v_colour;
out vec4 o_colour;
const float kNear = 0.2, kAlphaMin = 1.0 / 255.0, kAlphaMax = 0.99, kFilterInvSquare = 2.0;
void main() {
  // Pixel centres at (i + 0.5, j + 0.5) with rows counted from the top, as the C++ rasterizer.
  vec2 d = vec2(gl_FragCoord.x, u_size.y - gl_FragCoord.y) - v_centerOpacity.xy;
  vec3 p = d.x * v_pa + d.y * v_pb + v_pd;
  if (p.z == 0.0) discard;  // a ray parallel to the disk
  float u = p.x / p.z, v = p.y / p.z;
  float rhoObject = u * u + v * v, rhoScreen = kFilterInvSquare * dot(d, d);
  bool screen = rhoScreen < rhoObject;
  float rho = screen ? rhoScreen : rhoObject;
  float z = screen ? v_tw.z : v_tw.x * u + v_tw.y * v + v_tw.z;
  if (!(rho <= v_centerOpacity.w) || !(z >= kNear)) discard;
  float alpha = min(kAlphaMax, v_centerOpacity.z * exp(-0.5 * rho));
  if (alpha < kAlphaMin) discard;
  o_colour = vec4(v_colour * alpha, alpha);  // premultiplied, blended back to front
}
`;

export const FULLSCREEN_VS = `#version 300 es
void main() {
  vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
  gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
`;

// The sky's per-photo residual (shading/sh_degree4.h: bands 3 and 4 in its order and constants; bands 0-2
// are sh.h's), added to the light's radiance in the sky only. It is evaluated at u_turn * d: the light's
// turn about the up axis (rotateAboutUp) applied to the residual as f'(w) = f(R^T w), rows of R^T.
const SKY_RESIDUAL_GLSL = `
uniform bool u_hasResidual;
uniform vec3 u_residual[25];
uniform vec3 u_turn0, u_turn1, u_turn2;
vec3 skyResidual(vec3 w) {
  vec3 d = vec3(dot(u_turn0, w), dot(u_turn1, w), dot(u_turn2, w));
  float x = d.x, y = d.y, z = d.z, x2 = x * x, y2 = y * y, z2 = z * z;
  float b[25];
  b[0] = ${f(Y00)};
  b[1] = ${f(Y1)} * y; b[2] = ${f(Y1)} * z; b[3] = ${f(Y1)} * x;
  b[4] = ${f(Y2)} * x * y; b[5] = ${f(Y2)} * y * z; b[6] = ${f(Y20)} * (3.0 * z2 - 1.0);
  b[7] = ${f(Y2)} * x * z; b[8] = ${f(Y22)} * (x2 - y2);
  b[9] = ${f(0.5900435899266435)} * y * (3.0 * x2 - y2);
  b[10] = ${f(2.890611442640554)} * x * y * z;
  b[11] = ${f(0.4570457994644658)} * y * (5.0 * z2 - 1.0);
  b[12] = ${f(0.3731763325901154)} * z * (5.0 * z2 - 3.0);
  b[13] = ${f(0.4570457994644658)} * x * (5.0 * z2 - 1.0);
  b[14] = ${f(1.445305721320277)} * z * (x2 - y2);
  b[15] = ${f(0.5900435899266435)} * x * (x2 - 3.0 * y2);
  b[16] = ${f(2.503342941796705)} * x * y * (x2 - y2);
  b[17] = ${f(1.770130769779931)} * y * z * (3.0 * x2 - y2);
  b[18] = ${f(0.9461746957575601)} * x * y * (7.0 * z2 - 1.0);
  b[19] = ${f(0.6690465435572892)} * y * z * (7.0 * z2 - 3.0);
  b[20] = ${f(0.1057855469152043)} * (35.0 * z2 * z2 - 30.0 * z2 + 3.0);
  b[21] = ${f(0.6690465435572892)} * x * z * (7.0 * z2 - 3.0);
  b[22] = ${f(0.4730873478787800)} * (x2 - y2) * (7.0 * z2 - 1.0);
  b[23] = ${f(1.770130769779931)} * x * z * (x2 - 3.0 * y2);
  b[24] = ${f(0.6258357354491761)} * (x2 * (x2 - 3.0 * y2) - y2 * (3.0 * x2 - y2));
  vec3 r = vec3(0.0);
  for (int k = 0; k < 25; ++k) r += b[k] * u_residual[k];
  return r;
}
`;

// The per-pixel step after blending: what the C++ does to the rasterised maps before writing PNGs.
// With u_sky, the colour views are composited over the light's sky (shading/sky_colour.h: the radiance
// along the pixel's ray, floored at 1e-4, to the power 1/2.2, clipped at 1), as `render --background sky`,
// fading out below the horizon as the run was trained (sky_visibility in shading/sky_colour.h) into the
// ground drawn there (ground_colour). The sky's radiance is the light's plus the light's sky residual, when
// it has one (sky_radiance in sky_colour.h).
export const COMPOSITE_FS = `#version 300 es
precision highp float;
uniform highp sampler2D u_accum;
uniform int u_mode;
uniform bool u_unitRange;
uniform bool u_sky;
uniform vec3 u_horizonUp;       // the training cameras' mean up
uniform vec2 u_horizonSines;    // sines of the depressions where the sky starts to fade and is gone; y <= 0: none
uniform vec3 u_groundAlbedo;    // the ground drawn where the sky has faded (ground_colour in sky_colour.h)
uniform vec3 u_r0, u_r1, u_r2;  // world-to-camera rotation, rows
uniform vec4 u_intr;            // fx, fy, cx, cy
uniform vec2 u_size;
${SH_GLSL}
${SKY_RESIDUAL_GLSL}
out vec4 o_colour;
vec3 sky() {
  vec2 px = vec2(gl_FragCoord.x, u_size.y - gl_FragCoord.y);  // pixel centre, image rows from the top
  vec3 dc = vec3((px.x - u_intr.z) / u_intr.x, (px.y - u_intr.w) / u_intr.y, 1.0);
  vec3 d = normalize(dc.x * u_r0 + dc.y * u_r1 + dc.z * u_r2);  // R^T dc: world frame
  float visible = 1.0;
  if (u_horizonSines.y > 0.0) {
    float depression = -dot(u_horizonUp, d);
    visible = clamp((u_horizonSines.y - depression) / max(u_horizonSines.y - u_horizonSines.x, 1e-6), 0.0, 1.0);
  }
  vec3 ground = u_groundAlbedo * intensity(irradiance(u_horizonUp));
  vec3 l = radiance(d);
  if (u_hasResidual) l += skyResidual(d);
  return visible * min(pow(max(l, vec3(1e-4)), vec3(1.0 / 2.2)), vec3(1.0)) + (1.0 - visible) * ground;
}
void main() {
  vec4 c = texelFetch(u_accum, ivec2(gl_FragCoord.xy), 0);
  vec3 rgb = c.rgb;
  if (u_sky && u_mode <= 1) rgb += (1.0 - c.a) * sky();
  if (u_unitRange) {
    if (u_mode == 3) rgb = c.a > 0.0 ? c.rgb / c.a : vec3(0.0);
    if (u_mode == 4) rgb = c.rgb + (1.0 - c.a);
  } else if (u_mode == 3) {
    float len = length(c.rgb);
    rgb = len > 1e-3 ? 0.5 * (c.rgb / len + 1.0) : vec3(0.0);
  } else if (u_mode == 4) {
    rgb = vec3(1.0 - clamp(c.r, 0.0, 1000.0));
  }
  o_colour = vec4(clamp(rgb, 0.0, 1.0), 1.0);
}
`;

// The environment ball: a sphere seen by the current camera, shaded as a matte 0.8-albedo ball
// (albedo * intensity(E(n)), the unshadowed shading) or showing the radiance in the normal's direction.
export const BALL_FS = `#version 300 es
precision highp float;
uniform vec4 u_rect;        // x, y, width, height in framebuffer pixels (GL origin: bottom left)
uniform vec3 u_r0, u_r1, u_r2;
uniform int u_ballMode;     // 0 matte ball, 1 radiance
${SH_GLSL}
out vec4 o_colour;
void main() {
  vec2 q = (gl_FragCoord.xy - u_rect.xy) / u_rect.zw * 2.0 - 1.0;
  float r2 = dot(q, q);
  if (r2 > 1.0) discard;
  vec3 nc = vec3(q.x, -q.y, -sqrt(1.0 - r2));  // camera frame (y down), facing the camera
  vec3 n = nc.x * u_r0 + nc.y * u_r1 + nc.z * u_r2;  // R^T nc: world frame
  vec3 rgb = u_ballMode == 0 ? 0.8 * intensity(irradiance(n)) : intensity(radiance(n));
  float edge = clamp((1.0 - sqrt(r2)) * u_rect.z * 0.5, 0.0, 1.0);  // one pixel of anti-aliasing
  o_colour = vec4(clamp(rgb, 0.0, 1.0) * edge, edge);
}
`;
