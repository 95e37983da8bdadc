// Equirectangular panoramas dropped on the page, projected to the degree-2 SH environment that lights the
// model, as the C++ does it (so that a panorama lights the page as `render --light PANO` lights a frame):
// shading/envmap.h's project_panorama_to_sh (row 0 the zenith, the centre column along the frame's +X, exact
// pixel solid angles) in the frame of cameras/up_axis.h's panorama_frame_for_up. Radiance .hdr files are
// decoded here (RGBE, flat or run-length scanlines, as stb_image reads them); PNG and JPEG by the browser,
// each value / 255 as the C++ image reader takes them (no sRGB curve).

import { Y00, Y1, Y2, Y20, Y22, rotationAboutAxis } from './sh.js';

function fail(message) {
  throw new Error(message);
}

// The header lines up to the blank line, then the resolution line "-Y H +X W".
function readHdrHeader(bytes) {
  let pos = 0;
  const line = () => {
    let end = pos;
    while (end < bytes.length && bytes[end] !== 10) ++end;
    if (end >= bytes.length) fail('the Radiance header has no end');
    const text = String.fromCharCode(...bytes.subarray(pos, Math.min(end, pos + 200)));
    pos = end + 1;
    return text;
  };
  const magic = line();
  if (magic !== '#?RADIANCE' && magic !== '#?RGBE') fail('not a Radiance .hdr file (no #?RADIANCE line)');
  let format = '';
  for (let l = line(); l !== ''; l = line()) if (l.startsWith('FORMAT=')) format = l.slice(7);
  if (format !== '32-bit_rle_rgbe') fail(`unsupported .hdr format "${format}" (need 32-bit_rle_rgbe)`);
  const size = /^-Y (\d+) \+X (\d+)$/.exec(line());
  if (!size) fail('unsupported .hdr orientation (need "-Y H +X W")');
  const height = Number(size[1]), width = Number(size[2]);
  if (!(width > 0 && height > 0 && width * height <= 1 << 26)) fail(`bad .hdr size ${width}x${height}`);
  return { width, height, pos };
}

// One RGBE pixel as stb_image converts it: mantissa * 2^(e - 136), 0 when e = 0.
function rgbeToFloat(r, g, b, e, out, o) {
  const f = e ? 2 ** (e - 136) : 0;
  out[o] = r * f, out[o + 1] = g * f, out[o + 2] = b * f;
}

// A Radiance .hdr file (Uint8Array) as { width, height, pixels: Float32Array of 3 per pixel, row-major }.
export function parseRadianceHdr(bytes) {
  const { width, height, pos: start } = readHdrHeader(bytes);
  const pixels = new Float32Array(width * height * 3);
  const scan = new Uint8Array(width * 4);
  let pos = start;
  const need = (n) => { if (pos + n > bytes.length) fail('the .hdr file ends inside its pixels'); };
  for (let y = 0; y < height; ++y) {
    need(4);
    const rle = width >= 8 && width < 32768 && bytes[pos] === 2 && bytes[pos + 1] === 2 &&
                !(bytes[pos + 2] & 128);
    if (!rle) {  // flat: the rest of the file is RGBE quadruples
      need(width * height * 4 - y * width * 4);
      for (let i = y * width; i < width * height; ++i, pos += 4)
        rgbeToFloat(bytes[pos], bytes[pos + 1], bytes[pos + 2], bytes[pos + 3], pixels, 3 * i);
      break;
    }
    if (((bytes[pos + 2] << 8) | bytes[pos + 3]) !== width) fail(`scanline ${y}: its length is not the width`);
    pos += 4;
    for (let c = 0; c < 4; ++c) {  // each channel run-length coded on its own
      for (let x = 0; x < width;) {
        need(1);
        let count = bytes[pos++];
        if (count > 128) {
          count -= 128;
          need(1);
          if (x + count > width) fail(`scanline ${y}: a run passes the end of the line`);
          const value = bytes[pos++];
          for (let k = 0; k < count; ++k) scan[(x + k) * 4 + c] = value;
          x += count;
        } else {
          if (count === 0 || x + count > width) fail(`scanline ${y}: a bad literal count`);
          need(count);
          for (let k = 0; k < count; ++k) scan[(x + k) * 4 + c] = bytes[pos++];
          x += count;
        }
      }
    }
    for (let x = 0; x < width; ++x)
      rgbeToFloat(scan[4 * x], scan[4 * x + 1], scan[4 * x + 2], scan[4 * x + 3], pixels, 3 * (y * width + x));
  }
  return { width, height, pixels };
}

// The coordinate axis nearest to v, signed (up_axis.cpp's nearest_axis).
function nearestAxis(v) {
  let best = 0;
  for (let a = 1; a < 3; ++a) if (Math.abs(v[a]) > Math.abs(v[best])) best = a;
  const axis = [0, 0, 0];
  axis[best] = v[best] >= 0 ? 1 : -1;
  return axis;
}

// The panorama frame of an axis up (up_axis.cpp's axis_panorama_frame).
function axisPanoramaFrame(axis) {
  const h = Math.PI / 2;
  if (axis[2] > 0.5) return [[1, 0, 0], [0, 1, 0], [0, 0, 1]];
  if (axis[2] < -0.5) return rotationAboutAxis([1, 0, 0], Math.PI);
  if (axis[1] < -0.5) return rotationAboutAxis([1, 0, 0], h);
  if (axis[1] > 0.5) return rotationAboutAxis([1, 0, 0], -h);
  if (axis[0] > 0.5) return rotationAboutAxis([0, 1, 0], h);
  return rotationAboutAxis([0, 1, 0], -h);
}

// World direction = frame * panorama direction, with the panorama's top row towards `up`
// (panorama_frame_for_up): the frame of the nearest axis, turned by the smallest rotation onto `up`.
export function panoramaFrameForUp(up) {
  const n = Math.hypot(up[0], up[1], up[2]);
  if (!(n > 0.5)) fail('the up vector has no length');
  const u = up.map((v) => v / n);
  const axis = nearestAxis(u);
  const turn = [axis[1] * u[2] - axis[2] * u[1], axis[2] * u[0] - axis[0] * u[2], axis[0] * u[1] - axis[1] * u[0]];
  const frame = axisPanoramaFrame(axis);
  const s = Math.hypot(turn[0], turn[1], turn[2]);
  if (!(s > 1e-12)) return frame;
  const R = rotationAboutAxis(turn.map((v) => v / s), Math.atan2(s, axis[0] * u[0] + axis[1] * u[1] + axis[2] * u[2]));
  return [0, 1, 2].map((i) => [0, 1, 2].map((j) => R[i][0] * frame[0][j] + R[i][1] * frame[1][j] + R[i][2] * frame[2][j]));
}

// Radiance SH L_k = sum over pixels of L(d) Y_k(d) dOmega (project_panorama_to_sh), 9 [R, G, B] rows.
export function projectPanoramaToSh(pano, frame) {
  const { width: W, height: H, pixels } = pano;
  const sh = Array.from({ length: 9 }, () => [0, 0, 0]);
  const y = new Float64Array(9);
  for (let row = 0; row < H; ++row) {
    const theta = (Math.PI * (row + 0.5)) / H, half = Math.PI / (2 * H);
    const dOmega = ((2 * Math.PI) / W) * (Math.cos(theta - half) - Math.cos(theta + half));
    const st = Math.sin(theta), ct = Math.cos(theta);
    for (let col = 0; col < W; ++col) {
      const phi = 2 * Math.PI * (0.5 - (col + 0.5) / W);
      const p = [st * Math.cos(phi), st * Math.sin(phi), ct];
      const x = frame[0][0] * p[0] + frame[0][1] * p[1] + frame[0][2] * p[2];
      const yy = frame[1][0] * p[0] + frame[1][1] * p[1] + frame[1][2] * p[2];
      const z = frame[2][0] * p[0] + frame[2][1] * p[1] + frame[2][2] * p[2];
      y[0] = Y00, y[1] = Y1 * yy, y[2] = Y1 * z, y[3] = Y1 * x, y[4] = Y2 * x * yy, y[5] = Y2 * yy * z;
      y[6] = Y20 * (3 * z * z - 1), y[7] = Y2 * x * z, y[8] = Y22 * (x * x - yy * yy);
      const o = 3 * (row * W + col);
      for (let c = 0; c < 3; ++c) {
        const v = dOmega * pixels[o + c];
        if (!Number.isFinite(v)) fail(`pixel (${col}, ${row}) is not finite`);
        for (let k = 0; k < 9; ++k) sh[k][c] += y[k] * v;
      }
    }
  }
  return sh;
}

// A dropped or chosen panorama file as { width, height, pixels }: .hdr decoded here, PNG/JPEG by the browser.
export async function decodePanoramaFile(file) {
  const name = file.name.toLowerCase();
  if (name.endsWith('.hdr')) return parseRadianceHdr(new Uint8Array(await file.arrayBuffer()));
  if (name.endsWith('.exr'))
    fail('OpenEXR panoramas are not read in the browser: convert with `lumigauss env PANO.exr -o SH.txt` and load that');
  const bitmap = await createImageBitmap(file, { colorSpaceConversion: 'none', premultiplyAlpha: 'none' });
  const canvas = new OffscreenCanvas(bitmap.width, bitmap.height);
  const ctx = canvas.getContext('2d');
  ctx.drawImage(bitmap, 0, 0);
  const rgba = ctx.getImageData(0, 0, bitmap.width, bitmap.height).data;
  const pixels = new Float32Array(bitmap.width * bitmap.height * 3);
  for (let i = 0; i < bitmap.width * bitmap.height; ++i)
    for (let c = 0; c < 3; ++c) pixels[3 * i + c] = rgba[4 * i + c] / 255;
  return { width: bitmap.width, height: bitmap.height, pixels };
}
