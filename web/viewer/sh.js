// Degree-2 real spherical harmonics on the page, written to match the C++ exactly:
// basis, order and constants of src/lumigauss/shading/sh.h (no Condon-Shortley phase), the rotation of
// shading/sh_rotation.h (band 1 rotates as a vector in (y, z, x) order, band 2 as a traceless quadratic form
// Q' = R Q R^T) and rotate_about_up of relight/up_axis.h (right-handed about up: a sun at azimuth b moves to
// b + degrees). An environment is an array of 9 [R, G, B] radiance coefficients.

export const Y00 = 0.28209479177387814;
export const Y1 = 0.4886025119029199;
export const Y2 = 1.0925484305920792;
export const Y20 = 0.31539156525252005;
export const Y22 = 0.5462742152960396;

// Rotation by `radians` about the unit `axis` (Rodrigues), row-major 3x3, as rotation_about_axis.
export function rotationAboutAxis(axis, radians) {
  const n = Math.hypot(axis[0], axis[1], axis[2]);
  const [x, y, z] = [axis[0] / n, axis[1] / n, axis[2] / n];
  const c = Math.cos(radians), s = Math.sin(radians), t = 1 - c;
  return [
    [c + t * x * x, t * x * y - s * z, t * x * z + s * y],
    [t * y * x + s * z, c + t * y * y, t * y * z - s * x],
    [t * z * x - s * y, t * z * y + s * x, c + t * z * z],
  ];
}

function mul(a, b) {
  const r = [[0, 0, 0], [0, 0, 0], [0, 0, 0]];
  for (let i = 0; i < 3; ++i)
    for (let j = 0; j < 3; ++j) r[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
  return r;
}

function transpose(a) {
  return [0, 1, 2].map((i) => [a[0][i], a[1][i], a[2][i]]);
}

// One channel's band-2 coefficients (L2-2, L2-1, L20, L21, L22) as the form Q (sh_rotation.cpp).
function band2ToForm(b) {
  const xy = (Y2 * b[0]) / 2, yz = (Y2 * b[1]) / 2, xz = (Y2 * b[3]) / 2;
  const zonal = Y20 * b[2], sectoral = Y22 * b[4];
  return [
    [-zonal + sectoral, xy, xz],
    [xy, -zonal - sectoral, yz],
    [xz, yz, 2 * zonal],
  ];
}

function formToBand2(q) {
  return [(2 * q[0][1]) / Y2, (2 * q[1][2]) / Y2, q[2][2] / (2 * Y20), (2 * q[0][2]) / Y2,
          (q[0][0] - q[1][1]) / (2 * Y22)];
}

// The environment turned by the rotation R (f'(w) = f(R^T w)).
export function rotateSh(sh, R) {
  const out = sh.map((row) => row.slice());
  const Rt = transpose(R);
  for (let c = 0; c < 3; ++c) {
    const a = [sh[3][c], sh[1][c], sh[2][c]];  // band 1 as a vector in xyz order
    const ra = [0, 1, 2].map((i) => R[i][0] * a[0] + R[i][1] * a[1] + R[i][2] * a[2]);
    out[1][c] = ra[1], out[2][c] = ra[2], out[3][c] = ra[0];
    const q = mul(mul(R, band2ToForm([4, 5, 6, 7, 8].map((k) => sh[k][c]))), Rt);
    formToBand2(q).forEach((v, i) => (out[4 + i][c] = v));
  }
  return out;
}

export function rotateAboutUp(sh, up, degrees) {
  if (degrees === 0) return sh.map((row) => row.slice());
  return rotateSh(sh, rotationAboutAxis(up, (degrees * Math.PI) / 180));
}

export function scaleSh(sh, factor) {
  return sh.map((row) => row.map((v) => v * factor));
}

// 9 lines "R G B" (spaces, tabs or commas), '#' comments and blank lines skipped: the format of
// shading/sh_text.h. Throws an Error naming the line on anything else.
export function parseShText(text) {
  const rows = [];
  const lines = text.split(/\r?\n/);
  for (let i = 0; i < lines.length; ++i) {
    const line = lines[i].replace(/#.*/, '').trim();
    if (!line) continue;
    const parts = line.split(/[\s,]+/).filter((p) => p.length);
    const values = parts.map(Number);
    if (values.length !== 3 || !values.every(Number.isFinite))
      throw new Error(`line ${i + 1}: expected three numbers "R G B", got "${lines[i].trim()}"`);
    rows.push(values);
  }
  if (rows.length !== 9) throw new Error(`expected 9 coefficient rows, found ${rows.length}`);
  return rows;
}

// The sky residual of an SH text file (shading/sh_text.h): 25 lines "#sky R G B" (the word "#sky" first;
// "#sky01" is an ordinary comment), null when the file has none. Throws an Error naming the line on a
// damaged row, and on a block that is not 25 rows.
export function parseShSkyRows(text) {
  const rows = [];
  const lines = text.split(/\r?\n/);
  for (let i = 0; i < lines.length; ++i) {
    const m = /^[ \t]*#sky(?:[ \t]+(.*))?$/.exec(lines[i]);
    if (!m) continue;
    const parts = (m[1] || '').replace(/#.*/, '').split(/[\s,]+/).filter((p) => p.length);
    const values = parts.map(Number);
    if (values.length !== 3 || !values.every(Number.isFinite))
      throw new Error(`line ${i + 1}: expected "#sky R G B", got "${lines[i].trim()}"`);
    if (rows.length === 25) throw new Error(`line ${i + 1}: more than 25 "#sky" lines`);
    rows.push(values);
  }
  if (rows.length !== 0 && rows.length !== 25)
    throw new Error(`expected 25 "#sky" lines of the sky residual, found ${rows.length}`);
  return rows.length ? rows : null;
}
