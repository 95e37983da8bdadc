// Depth sorting off the main thread, so orbiting stays smooth while a large model is re-sorted.
// Messages in:  {type: 'init', positions: Float32Array (xyz per surfel)}
//               {type: 'sort', id, r2: [3], tz, near}  (row 2 of the world-to-camera rotation and t.z)
// Message out:  {type: 'sorted', id, indices: Uint32Array, count, ms}
// Depth is view-space z of the surfel's centre, z = r2 . p + tz, the C++ rasterizer's sort key
// (ProjectedSurfel::depth). Surfels with z <= near are dropped (project_surfel culls them). The rest come
// back to front: an exact sort of the float bits (LSD radix, two 16-bit passes, stable), reversed, so equal
// depths keep the C++ order (lower index in front).
'use strict';

let positions = null;
let depthF = null, depthU = null, keysB = null, idxA = null, idxB = null;
const histogram = new Uint32Array(65536);

function allocate(n) {
  depthF = new Float32Array(n);
  depthU = new Uint32Array(depthF.buffer);
  keysB = new Uint32Array(n);
  idxA = new Uint32Array(n);
  idxB = new Uint32Array(n);
}

// One stable counting pass on the 16 bits at `shift` of keys, moving (keys, idx) from src to dst.
function radixPass(count, shift, srcKeys, srcIdx, dstKeys, dstIdx) {
  histogram.fill(0);
  for (let i = 0; i < count; ++i) histogram[(srcKeys[i] >>> shift) & 0xffff]++;
  let sum = 0;
  for (let b = 0; b < 65536; ++b) {
    const c = histogram[b];
    histogram[b] = sum;
    sum += c;
  }
  for (let i = 0; i < count; ++i) {
    const k = srcKeys[i];
    const at = histogram[(k >>> shift) & 0xffff]++;
    dstKeys[at] = k;
    dstIdx[at] = srcIdx[i];
  }
}

function sortView(r2, tz, near) {
  const n = positions.length / 3;
  let count = 0;
  for (let i = 0; i < n; ++i) {
    const z = r2[0] * positions[3 * i] + r2[1] * positions[3 * i + 1] + r2[2] * positions[3 * i + 2] + tz;
    if (z > near) {
      depthF[count] = z;  // positive floats order like their bit patterns
      idxA[count++] = i;
    }
  }
  radixPass(count, 0, depthU, idxA, keysB, idxB);
  radixPass(count, 16, keysB, idxB, depthU, idxA);
  const out = new Uint32Array(count);
  for (let k = 0; k < count; ++k) out[k] = idxA[count - 1 - k];
  return out;
}

self.onmessage = (e) => {
  const m = e.data;
  if (m.type === 'init') {
    positions = m.positions;
    allocate(positions.length / 3);
  } else if (m.type === 'sort') {
    const t0 = performance.now();
    const indices = sortView(m.r2, m.tz, m.near);
    self.postMessage({ type: 'sorted', id: m.id, indices, count: indices.length, ms: performance.now() - t0 },
                     [indices.buffer]);
  }
};
