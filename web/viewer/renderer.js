// WebGL2 drawing: splats (one quad per surfel, in the order the sorting worker returns, back to
// front, premultiplied alpha) into an offscreen target, then the per-pixel step of the chosen view onto the
// canvas, then the environment ball. The offscreen target is RGBA16F when the browser can render to float
// (EXT_color_buffer_float): the normals and shadow views blend signed values, as the C++ rasterizer does.
import { SPLAT_VS, SPLAT_FS, FULLSCREEN_VS, COMPOSITE_FS, BALL_FS, MODES, ORDER_WIDTH } from './shaders.js';

function compile(gl, type, source, what) {
  const s = gl.createShader(type);
  gl.shaderSource(s, source);
  gl.compileShader(s);
  if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(`${what}: ${gl.getShaderInfoLog(s)}`);
  return s;
}

function program(gl, vs, fs, what) {
  const p = gl.createProgram();
  gl.attachShader(p, compile(gl, gl.VERTEX_SHADER, vs, `${what} vertex shader`));
  gl.attachShader(p, compile(gl, gl.FRAGMENT_SHADER, fs, `${what} fragment shader`));
  gl.linkProgram(p);
  if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(`${what}: ${gl.getProgramInfoLog(p)}`);
  const uniforms = {};
  const n = gl.getProgramParameter(p, gl.ACTIVE_UNIFORMS);
  for (let i = 0; i < n; ++i) {
    const name = gl.getActiveUniform(p, i).name.replace(/\[0\]$/, '');
    uniforms[name] = gl.getUniformLocation(p, name);
  }
  return { p, u: uniforms };
}

export class SplatRenderer {
  constructor(canvas) {
    const gl = canvas.getContext('webgl2', {
      antialias: false, alpha: false, depth: false, stencil: false, premultipliedAlpha: false,
      preserveDrawingBuffer: false, powerPreference: 'high-performance',
    });
    if (!gl) throw new Error('this browser has no WebGL2');
    this.gl = gl;
    this.canvas = canvas;
    // ?target8 forces the 8-bit fallback (for tests of the path browsers without float targets take).
    const force8 = new URLSearchParams(location.search).has('target8');
    this.floatTarget = !force8 && !!gl.getExtension('EXT_color_buffer_float');
    this.maxTextureSize = gl.getParameter(gl.MAX_TEXTURE_SIZE);
    const dbg = gl.getExtension('WEBGL_debug_renderer_info');
    this.rendererName = dbg ? gl.getParameter(dbg.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER);
    this.splat = program(gl, SPLAT_VS, SPLAT_FS, 'splat');
    this.composite = program(gl, FULLSCREEN_VS, COMPOSITE_FS, 'composite');
    this.ball = program(gl, FULLSCREEN_VS, BALL_FS, 'ball');
    this.splatVao = gl.createVertexArray();
    this.emptyVao = gl.createVertexArray();
    this.orderTexture = gl.createTexture();
    this.instances = 0;
    this.target = null;
  }

  // packed: model.js packSplats(). Called again for a newer model (a running training's snapshot): the
  // previous model's textures and index buffer are freed first.
  setModel(packed) {
    const gl = this.gl;
    if (this.texture) {
      gl.deleteTexture(this.texture);
      gl.deleteBuffer(this.indexBuffer);
      gl.deleteTexture(this.orderTexture);  // immutable storage (texStorage2D): a new size needs a new one
      this.orderTexture = gl.createTexture();
      this.instances = 0;
    }
    this.texture = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D, this.texture);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, packed.width, packed.height, 0, gl.RGBA, gl.FLOAT, packed.data);
    this.perRow = packed.perRow;
    // Two triangles per quad, corners 4q + (0, 1, 2) and 4q + (1, 3, 2): indexed, so that each corner's
    // vertex shader runs once.
    const quads = Math.max(packed.count, 1);
    const indices = new Uint32Array(6 * quads);
    for (let q = 0; q < quads; ++q) indices.set([4 * q, 4 * q + 1, 4 * q + 2, 4 * q + 1, 4 * q + 3, 4 * q + 2], 6 * q);
    gl.bindVertexArray(this.splatVao);
    this.indexBuffer = gl.createBuffer();
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, this.indexBuffer);
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, indices, gl.STATIC_DRAW);
    gl.bindVertexArray(null);
    this.orderRows = Math.max(1, Math.ceil(packed.count / ORDER_WIDTH));
    gl.bindTexture(gl.TEXTURE_2D, this.orderTexture);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
    gl.texStorage2D(gl.TEXTURE_2D, 1, gl.R32UI, ORDER_WIDTH, this.orderRows);
  }

  // Back-to-front surfel indices from the sorting worker; the first `count` are drawn.
  setOrder(indices, count) {
    const gl = this.gl;
    gl.bindTexture(gl.TEXTURE_2D, this.orderTexture);
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 4);
    const full = Math.floor(count / ORDER_WIDTH), rest = count - full * ORDER_WIDTH;
    if (full > 0)
      gl.texSubImage2D(gl.TEXTURE_2D, 0, 0, 0, ORDER_WIDTH, full, gl.RED_INTEGER, gl.UNSIGNED_INT, indices, 0);
    if (rest > 0) {
      gl.texSubImage2D(gl.TEXTURE_2D, 0, 0, full, rest, 1, gl.RED_INTEGER, gl.UNSIGNED_INT, indices,
                       full * ORDER_WIDTH);
    }
    this.instances = count;
  }

  ensureTarget(width, height) {
    const gl = this.gl;
    if (this.target && this.target.width === width && this.target.height === height) return;
    if (this.target) {
      gl.deleteFramebuffer(this.target.fbo);
      gl.deleteTexture(this.target.tex);
    }
    const tex = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D, tex);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
    const format = this.floatTarget ? gl.RGBA16F : gl.RGBA8;
    gl.texStorage2D(gl.TEXTURE_2D, 1, format, width, height);
    const fbo = gl.createFramebuffer();
    gl.bindFramebuffer(gl.FRAMEBUFFER, fbo);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0);
    if (gl.checkFramebufferStatus(gl.FRAMEBUFFER) !== gl.FRAMEBUFFER_COMPLETE) {
      if (!this.floatTarget) throw new Error('cannot create the offscreen render target');
      this.floatTarget = false;  // try again with 8 bits
      gl.deleteFramebuffer(fbo);
      gl.deleteTexture(tex);
      return this.ensureTarget(width, height);
    }
    this.target = { fbo, tex, width, height };
  }

  setCamera(u, view) {
    const gl = this.gl;
    gl.uniform3fv(u.u_r0, view.R[0]);
    gl.uniform3fv(u.u_r1, view.R[1]);
    gl.uniform3fv(u.u_r2, view.R[2]);
  }

  // view: {R (rows), t, fx, fy, cx, cy, width, height}; env: Float32Array(27); mode: a MODES name;
  // ball: null or {mode: 0|1, size (pixels)}; sky: draw the light's sky behind the colour views;
  // horizon: null or the scene's sky_horizon {up, start_degrees, fade_degrees, ground_albedo} (where that
  // sky ends, and the ground drawn below); sides: null or the scene's side_rule {up, grazing_degrees}
  // (which side of a surfel the camera sees, shading/surfel_side.h); residual: null or the light's sky
  // residual {coeffs: Float32Array(75), turn: the rows of R^T for the light's turn about up (3 x 3)}.
  render(view, env, mode, ball, sky = false, horizon = null, sides = null, residual = null) {
    const gl = this.gl;
    const { width, height } = view;
    if (this.canvas.width !== width || this.canvas.height !== height) {
      this.canvas.width = width;
      this.canvas.height = height;
    }
    this.ensureTarget(width, height);
    const m = MODES.indexOf(mode);
    // 1. Splats into the offscreen target.
    gl.bindFramebuffer(gl.FRAMEBUFFER, this.target.fbo);
    gl.viewport(0, 0, width, height);
    gl.clearColor(0, 0, 0, 0);
    gl.clear(gl.COLOR_BUFFER_BIT);
    if (this.instances > 0 && this.texture) {
      const { p, u } = this.splat;
      gl.useProgram(p);
      gl.activeTexture(gl.TEXTURE0);
      gl.bindTexture(gl.TEXTURE_2D, this.texture);
      gl.uniform1i(u.u_splats, 0);
      gl.activeTexture(gl.TEXTURE1);
      gl.bindTexture(gl.TEXTURE_2D, this.orderTexture);
      gl.uniform1i(u.u_order, 1);
      gl.uniform1i(u.u_perRow, this.perRow);
      this.setCamera(u, view);
      gl.uniform3fv(u.u_t, view.t);
      gl.uniform4f(u.u_intr, view.fx, view.fy, view.cx, view.cy);
      gl.uniform2f(u.u_size, width, height);
      gl.uniform1i(u.u_mode, m);
      gl.uniform1i(u.u_unitRange, this.floatTarget ? 0 : 1);
      gl.uniform3fv(u.u_env, env);
      const sideUp = sides ? sides.up : [0, 0, 1];
      gl.uniform3f(u.u_sideUp, sideUp[0], sideUp[1], sideUp[2]);
      gl.uniform1f(u.u_grazingSine, sides ? Math.sin(Math.min(Math.max(sides.grazing_degrees, 0), 45) * Math.PI / 180) : 0);
      gl.enable(gl.BLEND);
      gl.blendFunc(gl.ONE, gl.ONE_MINUS_SRC_ALPHA);
      gl.bindVertexArray(this.splatVao);
      gl.drawElements(gl.TRIANGLES, 6 * this.instances, gl.UNSIGNED_INT, 0);
      gl.bindVertexArray(null);
      gl.disable(gl.BLEND);
    }
    // 2. The view's per-pixel step onto the canvas.
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    gl.viewport(0, 0, width, height);
    const c = this.composite;
    gl.useProgram(c.p);
    gl.activeTexture(gl.TEXTURE0);
    gl.bindTexture(gl.TEXTURE_2D, this.target.tex);
    gl.uniform1i(c.u.u_accum, 0);
    gl.uniform1i(c.u.u_mode, m);
    gl.uniform1i(c.u.u_unitRange, this.floatTarget ? 0 : 1);
    gl.uniform1i(c.u.u_sky, sky ? 1 : 0);
    const sine = (deg) => Math.sin(Math.min(Math.max(deg, 0), 90) * Math.PI / 180);
    const up = horizon ? horizon.up : [0, 0, 1];
    gl.uniform3f(c.u.u_horizonUp, up[0], up[1], up[2]);
    gl.uniform2f(c.u.u_horizonSines, horizon ? sine(horizon.start_degrees) : 0,
                 horizon ? sine(horizon.start_degrees + horizon.fade_degrees) : 0);
    const ground = horizon && horizon.ground_albedo ? horizon.ground_albedo : [0, 0, 0];
    gl.uniform3f(c.u.u_groundAlbedo, ground[0], ground[1], ground[2]);
    this.setCamera(c.u, view);
    gl.uniform4f(c.u.u_intr, view.fx, view.fy, view.cx, view.cy);
    gl.uniform2f(c.u.u_size, width, height);
    gl.uniform3fv(c.u.u_env, env);
    gl.uniform1i(c.u.u_hasResidual, residual ? 1 : 0);
    if (residual) {
      gl.uniform3fv(c.u.u_residual, residual.coeffs);
      gl.uniform3fv(c.u.u_turn0, residual.turn[0]);
      gl.uniform3fv(c.u.u_turn1, residual.turn[1]);
      gl.uniform3fv(c.u.u_turn2, residual.turn[2]);
    }
    gl.bindVertexArray(this.emptyVao);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
    // 3. The environment ball in the top right corner.
    if (ball) this.drawBall(view, env, ball);
    gl.bindVertexArray(null);
  }

  drawBall(view, env, ball) {
    const gl = this.gl;
    const s = Math.min(ball.size, view.width / 3, view.height / 3);
    const x = view.width - s - 0.05 * s, y = view.height - s - 0.05 * s;
    const b = this.ball;
    gl.useProgram(b.p);
    gl.uniform4f(b.u.u_rect, x, y, s, s);
    this.setCamera(b.u, view);
    gl.uniform1i(b.u.u_ballMode, ball.mode);
    gl.uniform3fv(b.u.u_env, env);
    gl.enable(gl.BLEND);
    gl.blendFunc(gl.ONE, gl.ONE_MINUS_SRC_ALPHA);
    gl.enable(gl.SCISSOR_TEST);
    gl.scissor(Math.floor(x), Math.floor(y), Math.ceil(s) + 1, Math.ceil(s) + 1);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
    gl.disable(gl.SCISSOR_TEST);
    gl.disable(gl.BLEND);
  }

  // Waits until the GPU has finished the frame (a one-pixel read-back): what a frame really costs.
  finish() {
    const px = new Uint8Array(4);
    this.gl.readPixels(0, 0, 1, 1, this.gl.RGBA, this.gl.UNSIGNED_BYTE, px);
  }

  // The canvas as RGB bytes, rows from the top (call right after render()).
  readRgb() {
    const gl = this.gl;
    const w = this.canvas.width, h = this.canvas.height;
    const rgba = new Uint8Array(w * h * 4);
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, rgba);
    const rgb = new Uint8Array(w * h * 3);
    for (let y = 0; y < h; ++y)
      for (let x = 0; x < w; ++x)
        for (let c = 0; c < 3; ++c) rgb[3 * (y * w + x) + c] = rgba[4 * ((h - 1 - y) * w + x) + c];
    return { width: w, height: h, rgb };
  }
}
