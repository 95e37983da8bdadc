// The orbit camera: a target, a distance, and azimuth/elevation in the scene's orbit frame (e1, e2, up) of
// src/lumigauss/relight/orbit.h (azimuth a is the direction cos a e1 + sin a e2, counter-clockwise seen from
// above). Cameras follow io/camera.h: world-to-camera R|t, camera x right, y down, z forward, pinhole with
// pixel centres at (i + 0.5, j + 0.5).

const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const scale = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
const norm = (a) => scale(a, 1 / Math.hypot(a[0], a[1], a[2]));

const MAX_ELEVATION = (89 * Math.PI) / 180;

export class OrbitCamera {
  // scene: scene.json (up, e1, e2, centre, radius, camera).
  constructor(scene) {
    this.up = scene.up;
    this.e1 = scene.e1;
    this.e2 = scene.e2;
    this.radius = scene.radius;
    this.home = this.initialState(scene);
    this.reset();
  }

  reset() {
    Object.assign(this, structuredClone(this.home));
  }

  // From the scene's first camera when there is one (its position, and a target on its optical axis at the
  // distance of the model's centre), else looking at the model's centre from 2.5 radii, 25 degrees up.
  initialState(scene) {
    const c = scene.camera;
    if (!c) {
      const fovY = (50 * Math.PI) / 180;
      const distance = (1.1 * scene.radius) / Math.sin(fovY / 2);
      return { target: scene.centre.slice(), distance, azimuth: -Math.PI / 2, elevation: (25 * Math.PI) / 180, fovY };
    }
    const R = c.R, t = c.t;
    const eye = [0, 1, 2].map((i) => -(R[0][i] * t[0] + R[1][i] * t[1] + R[2][i] * t[2]));
    const forward = R[2];
    const along = Math.max(dot(sub(scene.centre, eye), forward), 0.1 * scene.radius);
    const target = add(eye, scale(forward, along));
    const back = sub(eye, target);
    const elevation = Math.asin(Math.max(-1, Math.min(1, dot(back, this.up) / along)));
    const azimuth = Math.atan2(dot(back, this.e2), dot(back, this.e1));
    return { target, distance: along, azimuth, elevation: clampElevation(elevation),
             fovY: 2 * Math.atan(c.height / 2 / c.fy) };
  }

  eye() {
    const ce = Math.cos(this.elevation);
    const dir = add(add(scale(this.e1, ce * Math.cos(this.azimuth)), scale(this.e2, ce * Math.sin(this.azimuth))),
                    scale(this.up, Math.sin(this.elevation)));
    return add(this.target, scale(dir, this.distance));
  }

  // The pinhole view for a width x height image: {R (rows), t, fx, fy, cx, cy, width, height}.
  view(width, height) {
    const eye = this.eye();
    const forward = norm(sub(this.target, eye));
    const right = norm(cross(forward, this.up));
    const down = cross(forward, right);
    const R = [right, down, forward];
    const t = scale([dot(right, eye), dot(down, eye), dot(forward, eye)], -1);
    const fy = height / 2 / Math.tan(this.fovY / 2);
    return { R, t, fx: fy, fy, cx: width / 2, cy: height / 2, width, height };
  }

  // Mouse drag by (dx, dy) pixels of a viewport `height` pixels tall.
  orbit(dx, dy, height) {
    const k = (2 * Math.PI) / Math.max(height, 1) * 0.5;
    this.azimuth -= dx * k;
    this.elevation = clampElevation(this.elevation + dy * k);
  }

  pan(dx, dy, height) {
    const v = this.view(1, height);
    const perPixel = (2 * this.distance * Math.tan(this.fovY / 2)) / Math.max(height, 1);
    this.target = add(this.target, add(scale(v.R[0], -dx * perPixel), scale(v.R[1], -dy * perPixel)));
  }

  zoom(factor) {
    this.distance = Math.min(Math.max(this.distance * factor, 1e-3 * this.radius), 1e3 * this.radius);
  }
}

function clampElevation(e) {
  return Math.max(-MAX_ELEVATION, Math.min(MAX_ELEVATION, e));
}

// A fixed camera "W,H,fx,fy,cx,cy,r00,...,r22,tx,ty,tz" (18 numbers, io/camera.h conventions), as the
// tests pass it in the URL; null when malformed.
export function parseCameraParam(text) {
  const v = text.split(',').map(Number);
  if (v.length !== 18 || !v.every(Number.isFinite)) return null;
  return {
    width: Math.round(v[0]), height: Math.round(v[1]), fx: v[2], fy: v[3], cx: v[4], cy: v[5],
    R: [v.slice(6, 9), v.slice(9, 12), v.slice(12, 15)], t: v.slice(15, 18),
  };
}
