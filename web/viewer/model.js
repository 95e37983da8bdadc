// The model payload (GET model.bin, documented in src/lumigauss/view/model_payload.h) decoded, activated
// exactly as the C++ does (scene/gaussian_model.h, shading/surfel_shading.h) and packed into the RGBA32F
// texture the splat shader reads: 8 texels per splat,
//   t0 = mean.xyz, opacity          opacity = sigmoid(logit)
//   t1 = a.xyz, albedo.r            a = s_u * R[:,0], s_u = exp(log s_u), R from the normalised quaternion
//   t2 = b.xyz, albedo.g            b = s_v * R[:,1]
//   t3 = albedo.b, P0, P1, P2       albedo = max(0, Y00 * raw + 0.5); P = positive transfer set (channel 0)
//   t4 = P3..P6,  t5 = P7, P8, N0, N1,  t6 = N2..N5,  t7 = N6, N7, N8, 0     N = negative transfer set
// The unit normal R[:,2] is cross(a, b) normalised (R is a proper rotation), computed in the shader.
import { Y00 } from './sh.js';

export const TEXELS_PER_SPLAT = 8;
const MAGIC = 'LGVIEW01';
const FLOATS_PER_SURFEL = 31;

// The blocks of the payload as Float32Array views (no copy). Throws an Error saying what is wrong.
export function decodePayload(buffer) {
  if (buffer.byteLength < 32) throw new Error(`model.bin: ${buffer.byteLength} bytes, too short for a header`);
  const bytes = new Uint8Array(buffer, 0, 8);
  const magic = String.fromCharCode(...bytes);
  if (magic !== MAGIC) throw new Error(`model.bin: bad magic "${magic}"`);
  const dv = new DataView(buffer);
  const version = dv.getUint32(8, true), count = dv.getUint32(12, true), floats = dv.getUint32(16, true);
  if (version !== 1) throw new Error(`model.bin: format version ${version}, this page reads 1`);
  if (floats !== FLOATS_PER_SURFEL) throw new Error(`model.bin: ${floats} floats per surfel, expected 31`);
  const expected = 32 + 4 * FLOATS_PER_SURFEL * count;
  if (buffer.byteLength !== expected)
    throw new Error(`model.bin: ${buffer.byteLength} bytes, expected ${expected} for ${count} surfels`);
  let offset = 32;
  const block = (width) => {
    const a = new Float32Array(buffer, offset, count * width);
    offset += 4 * count * width;
    return a;
  };
  return {
    count,
    xyz: block(3), rotation: block(4), scaling: block(2), opacity: block(1), albedo: block(3),
    transferPositive: block(9), transferNegative: block(9),
  };
}

// Writes surfel i's 32 floats at `out[o..o+31]`.
function packSplat(m, i, out, o) {
  const q = m.rotation.subarray(4 * i, 4 * i + 4);
  const inv = 1 / Math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  const w = q[0] * inv, x = q[1] * inv, y = q[2] * inv, z = q[3] * inv;
  const su = Math.exp(m.scaling[2 * i]), sv = Math.exp(m.scaling[2 * i + 1]);
  // Columns 0 and 1 of rotation_from_unit_quaternion (math/quaternion.h).
  const c0 = [1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y)];
  const c1 = [2 * (x * y - w * z), 1 - 2 * (x * x + z * z), 2 * (y * z + w * x)];
  const albedo = [0, 1, 2].map((c) => Math.max(0, Y00 * m.albedo[3 * i + c] + 0.5));
  const P = m.transferPositive.subarray(9 * i, 9 * i + 9), N = m.transferNegative.subarray(9 * i, 9 * i + 9);
  const v = [
    m.xyz[3 * i], m.xyz[3 * i + 1], m.xyz[3 * i + 2], 1 / (1 + Math.exp(-m.opacity[i])),
    su * c0[0], su * c0[1], su * c0[2], albedo[0],
    sv * c1[0], sv * c1[1], sv * c1[2], albedo[1],
    albedo[2], P[0], P[1], P[2],
    P[3], P[4], P[5], P[6],
    P[7], P[8], N[0], N[1],
    N[2], N[3], N[4], N[5],
    N[6], N[7], N[8], 0,
  ];
  out.set(v, o);
}

// The texture for `maxTextureSize`: width a multiple of 8 texels, as few rows as fit. Throws an Error when
// the model does not fit in one texture.
export function packSplats(model, maxTextureSize) {
  const width = Math.min(4096, maxTextureSize) - (Math.min(4096, maxTextureSize) % TEXELS_PER_SPLAT);
  const perRow = width / TEXELS_PER_SPLAT;
  const rows = Math.max(1, Math.ceil(model.count / perRow));
  if (rows > maxTextureSize) {
    throw new Error(`the model has ${model.count} surfels; this GPU's textures hold at most ` +
                    `${perRow * maxTextureSize}`);
  }
  const data = new Float32Array(width * rows * 4);
  for (let i = 0; i < model.count; ++i) {
    const row = Math.floor(i / perRow), col = (i % perRow) * TEXELS_PER_SPLAT;
    packSplat(model, i, data, 4 * (row * width + col));
  }
  return { data, width, height: rows, perRow, count: model.count };
}
