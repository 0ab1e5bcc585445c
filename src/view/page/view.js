// inksim view: the layer's BRDF on an object, in plain WebGL2.
//
// The server gives each result's BRDF table over (θi, θo, Δφ) in linear
// sRGB, its sky and specular reflectance against θo, its measured colours
// and spectra. The shader evaluates, per pixel, in the surface's frame:
//   L = f(θi, θo, Δφ) E cos θi + sky(θo) S + spec(θo) (S + disc)
// with E the lamp's irradiance normal to it (π√2: a white diffuser lit at
// 45° reads 1 at 0 EV), S the sky's radiance and disc the lamp's mirror
// image (a 3° disc). Displayed: L 2^EV, clipped to [0, 1], sRGB-encoded.
"use strict";

const $ = (id) => document.getElementById(id);
const LIGHT_E = Math.PI * Math.SQRT2;
const DISC_DEG = 3.0;
const BACKDROP = 0.045;

const state = {
  results: [],
  data: {},
  a: 0,
  b: -1,
  mode: "split",
  split: 0.5,
  shape: "sphere",
  rot: identity(),
  theta: 45,
  phi: 135,
  sky: 0.2,
  ev: -0.5,
  clip: false,
  glints: true,
  geometry: "45/0",
};

// ---------- small linear algebra ----------
function identity() { return [1, 0, 0, 0, 1, 0, 0, 0, 1]; }
function mul3(a, b) {
  const o = new Array(9);
  for (let r = 0; r < 3; r++)
    for (let c = 0; c < 3; c++)
      o[3 * r + c] = a[3 * r] * b[c] + a[3 * r + 1] * b[3 + c] + a[3 * r + 2] * b[6 + c];
  return o;
}
function rotX(t) { const c = Math.cos(t), s = Math.sin(t); return [1, 0, 0, 0, c, -s, 0, s, c]; }
function rotY(t) { const c = Math.cos(t), s = Math.sin(t); return [c, 0, s, 0, 1, 0, -s, 0, c]; }
function lightDir() {
  const t = state.theta * Math.PI / 180, p = state.phi * Math.PI / 180;
  return [Math.sin(t) * Math.cos(p), Math.sin(t) * Math.sin(p), Math.cos(t)];
}

// ---------- meshes (positions and normals, unit size) ----------
function sphereMesh(nu, nv) {
  const pos = [], nrm = [];
  const at = (i, j) => {
    const u = i / nu * 2 * Math.PI, v = j / nv * Math.PI;
    return [Math.sin(v) * Math.cos(u), Math.cos(v), Math.sin(v) * Math.sin(u)];
  };
  for (let j = 0; j < nv; j++)
    for (let i = 0; i < nu; i++) {
      const q = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
      for (const k of [0, 1, 2, 0, 2, 3]) { pos.push(...q[k]); nrm.push(...q[k]); }
    }
  return { pos, nrm };
}
// A cylindrical section: radius 1.2, ±55° of arc, height 1.5, curved about y.
function panelMesh() {
  const pos = [], nrm = [], R = 1.2, A = 55 * Math.PI / 180, H = 0.75, nu = 60, nv = 8;
  const at = (i, j) => {
    const a = -A + 2 * A * i / nu, y = -H + 2 * H * j / nv;
    return { p: [R * Math.sin(a), y, R * Math.cos(a) - R + 0.35], n: [Math.sin(a), 0, Math.cos(a)] };
  };
  for (let j = 0; j < nv; j++)
    for (let i = 0; i < nu; i++) {
      const q = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
      for (const k of [0, 1, 2, 0, 2, 3]) { pos.push(...q[k].p); nrm.push(...q[k].n); }
    }
  return { pos, nrm };
}
// Wavefront OBJ: v, vn and f (polygons fanned into triangles, negative
// indices allowed); smooth normals where the file has none. Centred and
// scaled to unit radius.
function parseObj(text) {
  const v = [], vn = [], pos = [], nrm = [], missing = [];
  for (const raw of text.split("\n")) {
    const t = raw.trim().split(/\s+/);
    if (t[0] === "v") v.push(t.slice(1, 4).map(Number));
    else if (t[0] === "vn") vn.push(t.slice(1, 4).map(Number));
    else if (t[0] === "f") {
      const idx = t.slice(1).map((s) => {
        const [a, , c] = s.split("/");
        const vi = parseInt(a, 10), ni = c ? parseInt(c, 10) : NaN;
        return [vi < 0 ? v.length + vi : vi - 1, isNaN(ni) ? -1 : ni < 0 ? vn.length + ni : ni - 1];
      });
      for (let k = 1; k + 1 < idx.length; k++) {
        const tri = [idx[0], idx[k], idx[k + 1]];
        if (tri.some(([vi]) => !(vi >= 0 && vi < v.length))) throw new Error("a face names a vertex the file does not have");
        const p = tri.map(([vi]) => v[vi]);
        const e1 = p[1].map((x, i) => x - p[0][i]), e2 = p[2].map((x, i) => x - p[0][i]);
        const fn = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
        for (const [vi, ni] of tri) {
          pos.push(...v[vi]);
          if (ni >= 0 && ni < vn.length) nrm.push(...vn[ni]);
          else { missing.push({ at: nrm.length, vi }); nrm.push(...fn); }
        }
      }
    }
  }
  if (pos.length === 0) throw new Error("no faces");
  if (missing.length) {
    // Smooth normals: the sum of the adjacent faces' (area-weighted) normals.
    const acc = new Map();
    for (const { at, vi } of missing) {
      const s = acc.get(vi) || [0, 0, 0];
      for (let i = 0; i < 3; i++) s[i] += nrm[at + i];
      acc.set(vi, s);
    }
    for (const { at, vi } of missing) { const s = acc.get(vi); for (let i = 0; i < 3; i++) nrm[at + i] = s[i]; }
  }
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < pos.length; i += 3)
    for (let k = 0; k < 3; k++) { lo[k] = Math.min(lo[k], pos[i + k]); hi[k] = Math.max(hi[k], pos[i + k]); }
  const c = lo.map((x, k) => (x + hi[k]) / 2);
  let r = 0;
  for (let i = 0; i < pos.length; i += 3) {
    let d = 0;
    for (let k = 0; k < 3; k++) d += (pos[i + k] - c[k]) ** 2;
    r = Math.max(r, Math.sqrt(d));
  }
  for (let i = 0; i < pos.length; i += 3) for (let k = 0; k < 3; k++) pos[i + k] = (pos[i + k] - c[k]) / r;
  return { pos, nrm, triangles: pos.length / 9 };
}

// ---------- WebGL2 ----------
const VS = `#version 300 es
in vec3 aPos; in vec3 aNrm;
uniform mat3 uRot; uniform float uScale; uniform vec2 uOffset;
out vec3 vN;
out vec3 vP;
void main() {
  vec3 p = uRot * aPos;
  vN = uRot * aNrm;
  vP = aPos;
  gl_Position = vec4(p.xy * uScale + uOffset, -p.z * 0.5, 1.0);
}`;
const FS = `#version 300 es
precision highp float;
precision highp sampler3D;
uniform sampler3D uBrdf[2];
uniform sampler2D uSide[2];
uniform vec3 uN[2];
uniform vec3 uLight;
uniform float uLightE, uSky, uExposure, uSplitPx, uDiscCos;
uniform int uClip;
// Glints (effect paints): (flakes per cell, spread σ rad, acceptance γ rad,
// lacquer index) and (one glint's radiance rgb, on); uCell the object's
// length per canvas pixel (one resolution cell).
uniform vec4 uSpark[2], uGlint[2];
uniform float uCell;
in vec3 vN;
in vec3 vP;
out vec4 outColour;
float tc(float x, float n) { return (clamp(x, 0.0, 1.0) * (n - 1.0) + 0.5) / n; }
vec3 shade(int k, vec3 n) {
  const vec3 v = vec3(0.0, 0.0, 1.0);
  vec3 l = normalize(uLight);
  float ci = dot(n, l), co = clamp(dot(n, v), 0.0, 1.0);
  float ti = acos(clamp(ci, 0.0, 1.0)), to = acos(co);
  vec3 lp = l - ci * n, vp = v - co * n;
  float dphi = 0.0;
  if (dot(lp, lp) > 1e-10 && dot(vp, vp) > 1e-10) dphi = acos(clamp(dot(normalize(lp), normalize(vp)), -1.0, 1.0));
  vec3 N = uN[k]; // (n_theta, n_phi, _)
  const float H = 1.5707963267948966, P = 3.141592653589793;
  vec3 c3 = vec3(tc(dphi / P, N.y), tc(to / H, N.x), tc(ti / H, N.x));
  vec3 f = k == 0 ? texture(uBrdf[0], c3).rgb : texture(uBrdf[1], c3).rgb;
  float u = tc(to / H, N.x);
  vec3 sky = k == 0 ? texture(uSide[0], vec2(u, 0.25)).rgb : texture(uSide[1], vec2(u, 0.25)).rgb;
  vec3 spec = k == 0 ? texture(uSide[0], vec2(u, 0.75)).rgb : texture(uSide[1], vec2(u, 0.75)).rgb;
  vec3 r = 2.0 * co * n - v;
  float disc = (ci > 0.0 && dot(r, l) >= uDiscCos) ? uLightE / (2.0 * P * (1.0 - uDiscCos)) : 0.0;
  return f * uLightE * max(ci, 0.0) + sky * uSky + spec * (uSky + disc);
}
// PCG's output function: well-mixed 32-bit values from the cell and the
// flake's number.
uint pcg(uint v) {
  uint state = v * 747796405u + 2891336453u;
  uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}
float rnd(uvec3 c, uint j) {
  return (float(pcg(c.x ^ pcg(c.y ^ pcg(c.z ^ pcg(j))))) + 0.5) / 4294967296.0;
}
vec3 refr(vec3 d, vec3 n, float eta) {
  float c = dot(d, n);
  vec3 t = (d - c * n) / eta;
  return t + n * sqrt(max(1.0 - dot(t, t), 0.0));
}
// The sparkle model (METHOD §10): a cell glints when one of its flakes has
// its normal within γ of the half vector between the refracted lamp and
// view directions. Each cell holds M flakes drawn from the spread (tilt
// Rayleigh in σ, azimuth uniform), each standing for N/M of the cell's N
// flakes: the cone is widened to γ √(N/M), so the mean count per cell is
// the model's N P. The flakes are fixed to the object, so the glints move
// as the lamp or the object turns; under the sky alone nothing glints.
vec3 glints(int k, vec3 n, vec3 cell) {
  vec4 s = k == 0 ? uSpark[0] : uSpark[1];
  vec4 g = k == 0 ? uGlint[0] : uGlint[1];
  vec3 l = normalize(uLight);
  if (g.a <= 0.0 || dot(n, l) <= 0.0) return vec3(0.0);
  const vec3 v = vec3(0.0, 0.0, 1.0);
  vec3 h = normalize(refr(l, n, s.w) + refr(v, n, s.w));
  const int M = 64;
  // The cone as a chord, |h − m| ≤ 2 sin(γ'/2): well conditioned for small
  // cones, where 1 − cos γ' loses the digits (and GPUs' cos is not exact).
  float chord = 2.0 * sin(0.5 * min(s.z * sqrt(max(s.x, 0.0) / float(M)), 1.5));
  vec3 t1 = normalize(cross(n, abs(n.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0)));
  vec3 t2 = cross(n, t1);
  float count = 0.0;
  uvec3 c = uvec3(ivec3(cell) + ivec3(1 << 20));
  for (int j = 0; j < M; j++) {
    float u1 = rnd(c, uint(2 * j)), u2 = rnd(c, uint(2 * j + 1));
    float tilt = s.y * sqrt(-2.0 * log(u1)), az = 6.283185307 * u2;
    vec3 m = cos(tilt) * n + sin(tilt) * (cos(az) * t1 + sin(az) * t2);
    vec3 d = h - m;
    if (dot(d, d) <= chord * chord) count += 1.0;
  }
  return count * g.rgb;
}
float enc(float x) { return x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1.0 / 2.4) - 0.055; }
void main() {
  vec3 n = normalize(vN);
  if (n.z < 0.0) n = -n;  // a panel's back, seen from behind: coated too
  int k = gl_FragCoord.x < uSplitPx ? 0 : 1;
  vec3 L = (shade(k, n) + glints(k, n, floor(vP / uCell))) * uExposure;
  bool clipped = any(greaterThan(L, vec3(1.0)));
  L = clamp(L, 0.0, 1.0);
  vec3 e = vec3(enc(L.r), enc(L.g), enc(L.b));
  if (uClip == 1 && clipped && mod(floor((gl_FragCoord.x + gl_FragCoord.y) / 4.0), 2.0) == 0.0) e = vec3(1.0, 0.0, 1.0);
  outColour = vec4(e, 1.0);
}`;

let gl, prog, loc = {}, meshes = {}, tex = [null, null], side = [null, null], dims = [[2, 2], [2, 2]], sparkle = [null, null];

function compile(type, src) {
  const s = gl.createShader(type);
  gl.shaderSource(s, src);
  gl.compileShader(s);
  if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
  return s;
}

function initGl() {
  gl = $("view").getContext("webgl2", { preserveDrawingBuffer: true, antialias: true });
  if (!gl) throw new Error("this browser has no WebGL2");
  prog = gl.createProgram();
  gl.attachShader(prog, compile(gl.VERTEX_SHADER, VS));
  gl.attachShader(prog, compile(gl.FRAGMENT_SHADER, FS));
  gl.linkProgram(prog);
  if (!gl.getProgramParameter(prog, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(prog));
  for (const n of ["uRot", "uScale", "uOffset", "uLight", "uLightE", "uSky", "uExposure", "uSplitPx",
    "uDiscCos", "uClip", "uBrdf[0]", "uBrdf[1]", "uSide[0]", "uSide[1]", "uN[0]", "uN[1]",
    "uSpark[0]", "uSpark[1]", "uGlint[0]", "uGlint[1]", "uCell"])
    loc[n] = gl.getUniformLocation(prog, n);
  meshes.sphere = upload(sphereMesh(96, 48));
  meshes.panel = upload(panelMesh());
  gl.enable(gl.DEPTH_TEST);
}

function upload(m) {
  const vao = gl.createVertexArray();
  gl.bindVertexArray(vao);
  for (const [name, data] of [["aPos", m.pos], ["aNrm", m.nrm]]) {
    const b = gl.createBuffer();
    gl.bindBuffer(gl.ARRAY_BUFFER, b);
    gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(data), gl.STATIC_DRAW);
    const l = gl.getAttribLocation(prog, name);
    gl.enableVertexAttribArray(l);
    gl.vertexAttribPointer(l, 3, gl.FLOAT, false, 0, 0);
  }
  gl.bindVertexArray(null);
  return { vao, count: m.pos.length / 3 };
}

// The BRDF table as a 3-D texture (x Δφ, y θo, z θi), the sky and specular
// reflectance as two rows of a 2-D one; half floats, linear filtering.
function uploadResult(k, r) {
  const b = r.brdf, nt = b.n_theta, np = b.n_phi;
  const t3 = new Float32Array(nt * nt * np * 4);
  for (let i = 0; i < nt * nt * np; i++) {
    t3[4 * i] = b.brdf[3 * i]; t3[4 * i + 1] = b.brdf[3 * i + 1]; t3[4 * i + 2] = b.brdf[3 * i + 2]; t3[4 * i + 3] = 1;
  }
  if (tex[k]) gl.deleteTexture(tex[k]);
  tex[k] = gl.createTexture();
  gl.bindTexture(gl.TEXTURE_3D, tex[k]);
  gl.texImage3D(gl.TEXTURE_3D, 0, gl.RGBA16F, np, nt, nt, 0, gl.RGBA, gl.FLOAT, t3);
  for (const p of [gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER]) gl.texParameteri(gl.TEXTURE_3D, p, gl.LINEAR);
  for (const p of [gl.TEXTURE_WRAP_S, gl.TEXTURE_WRAP_T, gl.TEXTURE_WRAP_R]) gl.texParameteri(gl.TEXTURE_3D, p, gl.CLAMP_TO_EDGE);
  const t2 = new Float32Array(nt * 2 * 4);
  for (let i = 0; i < nt; i++)
    for (let c = 0; c < 3; c++) { t2[4 * i + c] = b.sky[3 * i + c]; t2[4 * (nt + i) + c] = b.specular[3 * i + c]; }
  if (side[k]) gl.deleteTexture(side[k]);
  side[k] = gl.createTexture();
  gl.bindTexture(gl.TEXTURE_2D, side[k]);
  gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA16F, nt, 2, 0, gl.RGBA, gl.FLOAT, t2);
  for (const p of [gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER]) gl.texParameteri(gl.TEXTURE_2D, p, gl.LINEAR);
  for (const p of [gl.TEXTURE_WRAP_S, gl.TEXTURE_WRAP_T]) gl.texParameteri(gl.TEXTURE_2D, p, gl.CLAMP_TO_EDGE);
  dims[k] = [nt, np];
  sparkle[k] = r.sparkle || null;
}

// The object's radius in clip units, alone or side by side (A/B).
const OBJECT_SCALE = 0.8, SIDE_SCALE = 0.42;

// The scale and what follows from it: the object's length per canvas pixel
// (one resolution cell of the glints).
function setScale(scale, W) {
  gl.uniform1f(loc.uScale, scale);
  gl.uniform1f(loc.uCell, 2 / W / scale);
}

function draw() {
  const W = gl.drawingBufferWidth, H = gl.drawingBufferHeight;
  gl.viewport(0, 0, W, H);
  const bd = 12.92 * BACKDROP <= 0.04045 ? 12.92 * BACKDROP : 1.055 * Math.pow(BACKDROP, 1 / 2.4) - 0.055;
  gl.clearColor(bd, bd, bd, 1);
  gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
  const mesh = meshes[state.shape] || meshes.sphere;
  gl.useProgram(prog);
  gl.bindVertexArray(mesh.vao);
  const hasB = state.b >= 0 && state.data[state.b];
  for (let k = 0; k < 2; k++) {
    const t = tex[k === 1 && hasB ? 1 : 0], s = side[k === 1 && hasB ? 1 : 0];
    gl.activeTexture(gl.TEXTURE0 + 2 * k); gl.bindTexture(gl.TEXTURE_3D, t);
    gl.activeTexture(gl.TEXTURE1 + 2 * k); gl.bindTexture(gl.TEXTURE_2D, s);
    gl.uniform1i(loc[`uBrdf[${k}]`], 2 * k);
    gl.uniform1i(loc[`uSide[${k}]`], 2 * k + 1);
    const d = dims[k === 1 && hasB ? 1 : 0];
    gl.uniform3f(loc[`uN[${k}]`], d[0], d[1], 0);
    // One glint: the flake mirrors the lamp's disc over its share of the cell.
    const sp = sparkle[k === 1 && hasB ? 1 : 0], rad = Math.PI / 180;
    const lamp = LIGHT_E / (2 * Math.PI * (1 - Math.cos(DISC_DEG * rad)));
    if (sp && state.glints) {
      gl.uniform4f(loc[`uSpark[${k}]`], sp.flakes_per_cell, sp.sigma_deg * rad, sp.acceptance_deg * rad, sp.lacquer_index);
      const g = sp.glint_rgb.map((c) => c * sp.coverage * lamp);
      gl.uniform4f(loc[`uGlint[${k}]`], g[0], g[1], g[2], 1);
    } else {
      gl.uniform4f(loc[`uSpark[${k}]`], 0, 1, 0, 1.5);
      gl.uniform4f(loc[`uGlint[${k}]`], 0, 0, 0, 0);
    }
  }
  // uRot is column-major in GLSL: pass the transpose of the row-major state.
  const R = state.rot;
  gl.uniformMatrix3fv(loc.uRot, false, [R[0], R[3], R[6], R[1], R[4], R[7], R[2], R[5], R[8]]);
  const l = lightDir();
  gl.uniform3f(loc.uLight, l[0], l[1], l[2]);
  gl.uniform1f(loc.uLightE, LIGHT_E);
  gl.uniform1f(loc.uSky, state.sky);
  gl.uniform1f(loc.uExposure, Math.pow(2, state.ev));
  gl.uniform1f(loc.uDiscCos, Math.cos(DISC_DEG * Math.PI / 180));
  gl.uniform1i(loc.uClip, state.clip ? 1 : 0);
  if (hasB && state.mode === "side") {
    setScale(SIDE_SCALE, W);
    gl.uniform1f(loc.uSplitPx, W / 2);
    for (const x of [-0.5, 0.5]) { gl.uniform2f(loc.uOffset, x, 0); gl.drawArrays(gl.TRIANGLES, 0, mesh.count); }
  } else {
    setScale(OBJECT_SCALE, W);
    gl.uniform2f(loc.uOffset, 0, 0);
    gl.uniform1f(loc.uSplitPx, hasB ? state.split * W : 1e9);
    gl.drawArrays(gl.TRIANGLES, 0, mesh.count);
  }
  gl.bindVertexArray(null);
  readout();
}

// ---------- colour arithmetic for the readout ----------
function decode(v) { v /= 255; return v <= 0.04045 ? v / 12.92 : Math.pow((v + 0.055) / 1.055, 2.4); }
function labOf(rgb8, r) {
  const lin = rgb8.map(decode), M = r.rgb_to_xyz, w = r.white_xyz;
  const xyz = [0, 1, 2].map((i) => M[i][0] * lin[0] + M[i][1] * lin[1] + M[i][2] * lin[2]);
  const f = (t) => (t > 216 / 24389 ? Math.cbrt(t) : (24389 / 27 * t + 16) / 116);
  const [fx, fy, fz] = [0, 1, 2].map((i) => f(xyz[i] / w[i]));
  return [116 * fy - 16, 500 * (fx - fy), 200 * (fy - fz)];
}
// CIEDE2000 (Sharma, Wu and Dalal 2005).
function de00(l1, l2) {
  const rad = Math.PI / 180, [L1, a1, b1] = l1, [L2, a2, b2] = l2;
  const C1 = Math.hypot(a1, b1), C2 = Math.hypot(a2, b2), Cm = (C1 + C2) / 2;
  const G = 0.5 * (1 - Math.sqrt(Cm ** 7 / (Cm ** 7 + 25 ** 7)));
  const ap1 = (1 + G) * a1, ap2 = (1 + G) * a2;
  const Cp1 = Math.hypot(ap1, b1), Cp2 = Math.hypot(ap2, b2);
  const hp = (b, a) => (a === 0 && b === 0 ? 0 : ((Math.atan2(b, a) / rad) + 360) % 360);
  const h1 = hp(b1, ap1), h2 = hp(b2, ap2);
  const dL = L2 - L1, dC = Cp2 - Cp1;
  let dh = 0;
  if (Cp1 * Cp2 !== 0) { dh = h2 - h1; if (dh > 180) dh -= 360; else if (dh < -180) dh += 360; }
  const dH = 2 * Math.sqrt(Cp1 * Cp2) * Math.sin(dh * rad / 2);
  const Lm = (L1 + L2) / 2, Cpm = (Cp1 + Cp2) / 2;
  let hm = h1 + h2;
  if (Cp1 * Cp2 !== 0) { if (Math.abs(h1 - h2) > 180) hm += h1 + h2 < 360 ? 360 : -360; hm /= 2; }
  const T = 1 - 0.17 * Math.cos((hm - 30) * rad) + 0.24 * Math.cos(2 * hm * rad) + 0.32 * Math.cos((3 * hm + 6) * rad) - 0.2 * Math.cos((4 * hm - 63) * rad);
  const dTheta = 30 * Math.exp(-(((hm - 275) / 25) ** 2));
  const RC = 2 * Math.sqrt(Cpm ** 7 / (Cpm ** 7 + 25 ** 7));
  const SL = 1 + 0.015 * (Lm - 50) ** 2 / Math.sqrt(20 + (Lm - 50) ** 2), SC = 1 + 0.045 * Cpm, SH = 1 + 0.015 * Cpm * T;
  const RT = -Math.sin(2 * dTheta * rad) * RC;
  return Math.sqrt((dL / SL) ** 2 + (dC / SC) ** 2 + (dH / SH) ** 2 + RT * (dC / SC) * (dH / SH));
}

function pixel(x, y) {
  const p = new Uint8Array(4);
  gl.readPixels(Math.round(x), Math.round(y), 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, p);
  return [p[0], p[1], p[2]];
}

// The object's centre for A (and B): one pixel each where the normal faces the viewer.
function centres() {
  const W = gl.drawingBufferWidth, H = gl.drawingBufferHeight;
  const hasB = state.b >= 0 && state.data[state.b];
  if (hasB && state.mode === "side") return [[W / 4, H / 2, state.a], [3 * W / 4, H / 2, state.b]];
  if (hasB) return [[W / 2 - 3, H / 2, state.a], [W / 2 + 3, H / 2, state.b]].map((c) => (c[0] < state.split * W ? [c[0], c[1], state.a] : [c[0], c[1], state.b]));
  return [[W / 2, H / 2, state.a]];
}

function readout() {
  const lines = [];
  for (const [x, y, id] of centres()) {
    const r = state.data[id];
    if (!r) continue;
    const rgb = pixel(x, y), lab = labOf(rgb, r);
    const m = r.colours.find((c) => c.geometry === state.geometry);
    const d = m ? ` — ΔE00 ${de00(lab, m.mapped_lab).toFixed(2)} to its ${m.geometry} colour as sRGB shows it${m.moved ? " (gamut mapped)" : ""}` : "";
    lines.push(`${r.name}: sRGB ${rgb.join(", ")}; L* ${lab[0].toFixed(1)} a* ${lab[1].toFixed(1)} b* ${lab[2].toFixed(1)} (${r.conditions})${d}`);
  }
  $("readout").textContent = lines.join("\n") || "–";
  $("readout").style.whiteSpace = "pre-line";
}

// ---------- side panel: tile, colours, spectra ----------
function fmt(v, d) { return Number.isFinite(v) ? v.toFixed(d) : "–"; }

function panel() {
  const ids = [state.a].concat(state.b >= 0 ? [state.b] : []);
  const a = state.data[state.a];
  if (!a) return;
  $("tile").src = `/api/result/${state.a}/tile.png`;
  $("tile").onerror = () => { $("tile").style.display = "none"; $("tile-note").textContent = "No tile in this result."; };
  $("tile").onload = () => { $("tile").style.display = ""; $("tile-note").textContent = `Tile of ${a.name}.`; };
  const geoms = [...new Set(ids.flatMap((i) => (state.data[i] ? state.data[i].colours.map((c) => c.geometry) : [])))];
  const sel = $("geometry");
  if ([...sel.options].map((o) => o.value).join() !== geoms.join()) {
    sel.innerHTML = geoms.map((g) => `<option>${g}</option>`).join("");
    if (geoms.includes(state.geometry)) sel.value = state.geometry; else if (geoms.length) state.geometry = geoms[0];
  }
  let html = "<table><tr><th></th><th>result</th><th>L*</th><th>a*</th><th>b*</th><th>C*ab</th><th>h°</th><th>± ΔE00</th></tr>";
  const series = [];
  ids.forEach((id, k) => {
    const r = state.data[id];
    if (!r) return;
    const c = r.colours.find((x) => x.geometry === state.geometry);
    if (!c) { html += `<tr><td></td><td>${r.name}</td><td colspan="6">no ${state.geometry} colour</td></tr>`; return; }
    series.push({ r, c, k });
    html += `<tr><td><span class="sw" style="background:rgb(${c.srgb8.join(",")})"></span>${c.moved ? " mapped" : ""}</td>` +
      `<td>${k ? "B" : "A"}: ${r.name}</td><td>${fmt(c.lab[0], 1)}</td><td>${fmt(c.lab[1], 1)}</td><td>${fmt(c.lab[2], 1)}</td>` +
      `<td>${fmt(c.lch[1], 1)}</td><td>${fmt(c.lch[2], 0)}</td><td>${c.de00_se == null ? "–" : fmt(c.de00_se, 2)}</td></tr>`;
  });
  html += "</table>";
  if (series.length === 2) html += `<div>ΔE00 A → B: <span class="num">${de00(series[0].c.lab, series[1].c.lab).toFixed(2)}</span></div>`;
  $("colours").innerHTML = html;
  spectra(series);
  $("conditions").textContent = ids.filter((i) => state.data[i]).map((i) => {
    const r = state.data[i];
    return `${r.name}: ${r.model}; colours under ${r.conditions}; ${r.brdf.anchor}.`;
  }).join(" ") + " The table is linear sRGB; the display clips values above 1.";
  $("labels").textContent = ids.filter((i) => state.data[i] && state.data[i].labels.length).map((i) =>
    `${state.data[i].name}: ${state.data[i].labels.map(([a, l]) => `${a} = ${l}`).join(", ")}`).join("; ");
}

function spectra(series) {
  const svg = $("spectra"), W = 540, H = 260, L = 50, R = 10, T = 10, B = 36;
  const x0 = 380, x1 = 780;
  let ymax = 0.1;
  for (const { c } of series) for (const v of c.spectrum.concat(c.solved)) if (Number.isFinite(v)) ymax = Math.max(ymax, v);
  ymax = Math.ceil(ymax * 10) / 10;
  const X = (w) => L + (w - x0) / (x1 - x0) * (W - L - R), Y = (v) => H - B - v / ymax * (H - T - B);
  let s = `<rect x="${L}" y="${T}" width="${W - L - R}" height="${H - T - B}" fill="white" stroke="#888"/>`;
  for (let w = 400; w <= 780; w += 50) s += `<line x1="${X(w)}" x2="${X(w)}" y1="${H - B}" y2="${H - B + 4}" stroke="#333"/><text x="${X(w)}" y="${H - B + 16}" font-size="11" text-anchor="middle">${w}</text>`;
  for (let k = 0; k <= 5; k++) { const v = ymax * k / 5; s += `<line x1="${L - 4}" x2="${L}" y1="${Y(v)}" y2="${Y(v)}" stroke="#333"/><text x="${L - 6}" y="${Y(v) + 4}" font-size="11" text-anchor="end">${v.toFixed(2)}</text>`; }
  s += `<text x="${(L + W - R) / 2}" y="${H - 4}" font-size="12" text-anchor="middle">wavelength (nm)</text>`;
  s += `<text x="12" y="${(T + H - B) / 2}" font-size="12" text-anchor="middle" transform="rotate(-90 12 ${(T + H - B) / 2})">reflectance factor (1), ${state.geometry}</text>`;
  const colours = ["#1f4e9c", "#c0392b"];
  for (const { c, k, r } of series) {
    const pts = c.wavelengths_nm.map((w, i) => `${X(w).toFixed(1)},${Y(c.spectrum[i]).toFixed(1)}`).join(" ");
    s += `<polyline points="${pts}" fill="none" stroke="${colours[k]}" stroke-width="1.6"${k ? ' stroke-dasharray="5 3"' : ""}/>`;
    for (let i = 0; i < c.solved_nm.length; i++) s += `<circle cx="${X(c.solved_nm[i])}" cy="${Y(c.solved[i])}" r="3" fill="${colours[k]}"/>`;
    s += `<text x="${W - R - 6}" y="${T + 14 + 14 * k}" font-size="11" text-anchor="end" fill="${colours[k]}">${k ? "B" : "A"}: ${r.name}</text>`;
  }
  s += `<text x="${L + 6}" y="${T + 14}" font-size="11" fill="#555">dots: the solved wavelengths</text>`;
  svg.innerHTML = s;
}

// ---------- data ----------
async function fetchResult(id) {
  if (state.data[id]) return state.data[id];
  const r = await fetch(`/api/result/${id}`);
  if (!r.ok) throw new Error(`result ${id}: ${r.status}`);
  state.data[id] = await r.json();
  return state.data[id];
}

async function select() {
  syncAxes();
  uploadResult(0, await fetchResult(state.a));
  if (state.b >= 0) uploadResult(1, await fetchResult(state.b));
  draw();
  panel();
}

// ---------- live recompute ----------
// Each control change asks the server for the model at the new values; while
// one request is out, only the latest change waits (no queue builds up).
const live = { id: -1, params: [], busy: false, pending: null, last: null };

function liveValues() {
  return live.params.map((p) => `${encodeURIComponent(p.key)}=${Number($("live-" + p.key).value)}`).join("&");
}

async function liveCompute(t0) {
  if (live.busy) { live.pending = t0; return; }
  live.busy = true;
  try {
    const r = await fetch(`/api/live/compute?${liveValues()}`);
    if (!r.ok) throw new Error(await r.text());
    const j = await r.json();
    state.data[live.id] = j.result;
    if (state.a === live.id) uploadResult(0, j.result);
    if (state.b === live.id) uploadResult(1, j.result);
    draw();
    panel();
    const ms = performance.now() - t0;
    live.last = { server_ms: j.compute_ms, total_ms: ms };
    $("live-time").textContent = `last change: model ${j.compute_ms.toFixed(1)} ms on the server, ` +
      `${ms.toFixed(0)} ms from the control to the new picture`;
  } catch (e) {
    $("live-time").textContent = `recompute failed: ${e.message}`;
  } finally {
    live.busy = false;
    if (live.pending !== null) { const t = live.pending; live.pending = null; liveCompute(t); }
  }
}

async function initLive() {
  const r = await fetch("/api/live");
  if (!r.ok) return;
  const j = await r.json();
  live.id = j.id;
  live.params = j.params;
  $("live").style.display = "";
  $("live-params").innerHTML = j.params.map((p) =>
    `<label>${p.label} <input type="range" id="live-${p.key}" min="${p.min}" max="${p.max}" step="${p.step}" value="${p.value}"> ` +
    `<span id="live-${p.key}-v" class="num">${p.value}</span>${p.unit === "1" ? "" : " " + p.unit}</label><br>`).join("");
  for (const p of j.params) {
    const el = $("live-" + p.key);
    el.addEventListener("input", () => { $("live-" + p.key + "-v").textContent = el.value; liveCompute(performance.now()); });
  }
}

// ---------- controls ----------
function bindRange(id, key, digits) {
  const el = $(id);
  const show = () => { $(id + "-v").textContent = Number(state[key]).toFixed(digits); };
  el.value = state[key];
  show();
  el.addEventListener("input", () => { state[key] = Number(el.value); show(); draw(); });
  return show;
}

function syncLightSliders() {
  $("theta").value = state.theta; $("phi").value = state.phi;
  $("theta-v").textContent = state.theta.toFixed(0); $("phi-v").textContent = state.phi.toFixed(0);
}

function bindPointer() {
  const c = $("view");
  let drag = null;
  c.addEventListener("contextmenu", (e) => e.preventDefault());
  c.addEventListener("pointerdown", (e) => { drag = { x: e.clientX, y: e.clientY, light: e.shiftKey || e.button === 2 }; c.setPointerCapture(e.pointerId); });
  c.addEventListener("pointerup", () => { drag = null; });
  c.addEventListener("pointermove", (e) => {
    if (!drag) return;
    const rect = c.getBoundingClientRect();
    if (drag.light) {
      // The light sits on the hemisphere facing the viewer, under the pointer.
      let x = (e.clientX - rect.left) / rect.width * 2 - 1, y = 1 - (e.clientY - rect.top) / rect.height * 2;
      const r = Math.hypot(x, y), max = Math.sin(85 * Math.PI / 180);
      if (r > max) { x *= max / r; y *= max / r; }
      state.theta = Math.round(Math.asin(Math.min(Math.hypot(x, y), 1)) * 180 / Math.PI);
      state.phi = Math.round(Math.atan2(y, x) * 180 / Math.PI);
      syncLightSliders();
    } else {
      const dx = (e.clientX - drag.x) / rect.width * Math.PI, dy = (e.clientY - drag.y) / rect.height * Math.PI;
      state.rot = mul3(rotX(dy), mul3(rotY(dx), state.rot));
      drag.x = e.clientX; drag.y = e.clientY;
    }
    draw();
  });
}

function bindControls() {
  bindRange("theta", "theta", 0);
  bindRange("phi", "phi", 0);
  bindRange("sky", "sky", 2);
  bindRange("ev", "ev", 1);
  $("clip").addEventListener("change", () => { state.clip = $("clip").checked; draw(); });
  $("glints").addEventListener("change", () => { state.glints = $("glints").checked; draw(); });
  $("split").addEventListener("input", () => { state.split = Number($("split").value); draw(); });
  for (const el of document.querySelectorAll("input[name=shape]"))
    el.addEventListener("change", () => { state.shape = el.value; draw(); });
  for (const el of document.querySelectorAll("input[name=mode]"))
    el.addEventListener("change", () => { state.mode = el.value; draw(); });
  $("sel-a").addEventListener("change", () => { state.a = Number($("sel-a").value); select(); });
  $("sel-b").addEventListener("change", () => { state.b = Number($("sel-b").value); select(); });
  $("geometry").addEventListener("change", () => { state.geometry = $("geometry").value; panel(); draw(); });
  $("objfile").addEventListener("change", async () => {
    const f = $("objfile").files[0];
    if (!f) return;
    try {
      const m = parseObj(await f.text());
      meshes.obj = upload(m);
      $("shape-obj").disabled = false; $("shape-obj").checked = true; state.shape = "obj";
      $("objinfo").textContent = `${f.name}: ${m.triangles} triangles`;
      draw();
    } catch (e) { $("objinfo").textContent = `${f.name}: not a usable OBJ (${e.message})`; }
  });
  bindPointer();
}

// Settings from the address (?a=0&b=1&theta=45&phi=0&sky=0&ev=0&mode=side&shape=panel&geometry=45/0),
// and ?probe=… for tests: the page writes what it drew into #probe.
function fromQuery(q) {
  for (const k of ["theta", "phi", "sky", "ev", "split", "a", "b"]) if (q.has(k)) state[k] = Number(q.get(k));
  for (const k of ["mode", "shape", "geometry"]) if (q.has(k)) state[k] = q.get(k);
  if (q.has("glints")) state.glints = q.get("glints") !== "0";
  $("glints").checked = state.glints;
  for (const el of document.querySelectorAll("input[name=mode]")) el.checked = el.value === state.mode;
  for (const el of document.querySelectorAll("input[name=shape]")) el.checked = el.value === state.shape;
  $("split").value = state.split;
}

function stats() {
  const W = gl.drawingBufferWidth, H = gl.drawingBufferHeight, p = new Uint8Array(W * H * 4);
  gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE, p);
  const bd = Math.round(255 * (1.055 * Math.pow(BACKDROP, 1 / 2.4) - 0.055));
  let object = 0;
  for (let i = 0; i < W * H; i++) if (Math.abs(p[4 * i] - bd) > 2 || Math.abs(p[4 * i + 1] - bd) > 2 || Math.abs(p[4 * i + 2] - bd) > 2) object++;
  return { width: W, height: H, object_pixels: object };
}

// A study's variants chosen by their axis values: per side one select per
// axis (the labels from the study's summary.h5); a change picks the variant
// with every chosen label.
function labelOf(r, axis) {
  const p = r && r.labels && r.labels.find(([x]) => x === axis);
  return p ? p[1] : "";
}

// The pickers showing A's and B's own labels (after any way of choosing them).
function syncAxes() {
  for (const el of $("axes").querySelectorAll("select")) {
    const r = state.results.find((x) => x.id === state[el.dataset.side]);
    const v = labelOf(r, el.dataset.axis);
    if (v) el.value = v;
  }
}

function axisPickers() {
  const rs = state.results.filter((r) => r.labels && r.labels.length);
  const box = $("axes");
  if (!rs.length) { box.innerHTML = ""; return; }
  const axes = [...new Set(rs.flatMap((r) => r.labels.map(([a]) => a)))];
  let html = "";
  for (const side of ["a", "b"]) {
    html += `<div>${side.toUpperCase()} by axis: ` + axes.map((a) => {
      const vals = [...new Set(rs.map((r) => labelOf(r, a)).filter((v) => v))];
      return `<label>${a} <select data-side="${side}" data-axis="${a}">${vals.map((v) => `<option>${v}</option>`).join("")}</select></label>`;
    }).join(" ") + "</div>";
  }
  box.innerHTML = html + `<div id="axes-note" class="note"></div>`;
  syncAxes();
  for (const el of box.querySelectorAll("select")) el.addEventListener("change", () => {
    const side = el.dataset.side, want = {};
    for (const s of box.querySelectorAll(`select[data-side=${side}]`)) want[s.dataset.axis] = s.value;
    const hit = rs.find((r) => axes.every((a) => !labelOf(r, a) || labelOf(r, a) === want[a]));
    if (!hit) { $("axes-note").textContent = `no variant has ${axes.map((a) => `${a} = ${want[a]}`).join(", ")}`; return; }
    $("axes-note").textContent = "";
    state[side] = hit.id;
    $("sel-" + side).value = String(hit.id);
    select();
  });
}

function probe(kind) {
  const out = { kind, renderer: gl.getParameter(gl.RENDERER), settings: { theta: state.theta, phi: state.phi, sky: state.sky, ev: state.ev, mode: state.mode, a: state.a, b: state.b } };
  out.centres = centres().map(([x, y, id]) => ({ x, y, id, rgb: pixel(x, y) }));
  out.readout = $("readout").textContent;
  out.colours = $("colours").textContent;
  Object.assign(out, stats());
  if (kind === "move") {
    // Move the light's slider as a user would, then read again.
    const el = $("theta");
    el.value = String(Math.max(0, state.theta - 30));
    el.dispatchEvent(new Event("input"));
    out.after = { theta: state.theta, centres: centres().map(([x, y, id]) => ({ x, y, id, rgb: pixel(x, y) })), readout: $("readout").textContent };
  }
  if (kind === "sparkle") {
    // The glints alone: the picture with and without them, at the lamp's
    // angle and 10° further; and their share of the cells near the centre
    // (a normal within ~5° of the view) against the model's mean.
    const W = gl.drawingBufferWidth, H = gl.drawingBufferHeight;
    const grab = (on) => { state.glints = on; draw(); const p = new Uint8Array(W * H * 4); gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE, p); return p; };
    const lit = () => {
      const a = grab(true), b = grab(false), set = new Set();
      for (let i = 0; i < W * H; i++) if (Math.abs(a[4 * i] - b[4 * i]) + Math.abs(a[4 * i + 1] - b[4 * i + 1]) + Math.abs(a[4 * i + 2] - b[4 * i + 2]) > 12) set.add(i);
      return set;
    };
    const g1 = lit();
    const R = OBJECT_SCALE * Math.min(W, H) / 2, r2 = (0.08 * R) ** 2;
    let centre = 0, centreLit = 0;
    for (let y = 0; y < H; y++) for (let x = 0; x < W; x++) {
      if ((x + 0.5 - W / 2) ** 2 + (y + 0.5 - H / 2) ** 2 > r2) continue;
      centre++;
      if (g1.has(y * W + x)) centreLit++;
    }
    state.theta += 10;
    const g2 = lit();
    let both = 0;
    for (const i of g1) if (g2.has(i)) both++;
    const sp = sparkle[0];
    out.sparkle = { glints: g1.size, moved: g2.size, both, centre_pixels: centre, centre_glints: centreLit, model_mean_45: sp ? sp.mean_glints_45 : null };
    state.theta -= 10;
    state.glints = true;
    draw();
  }
  if (kind === "axes") {
    // Choose A by its axis values as a user would: the last label of every axis.
    const picks = [...document.querySelectorAll("#axes select[data-side=a]")];
    for (const el of picks) el.value = el.options[el.options.length - 1].value;
    if (picks.length) picks[picks.length - 1].dispatchEvent(new Event("change"));
    out.axes = { pickers: picks.length, chosen: picks.map((el) => [el.dataset.axis, el.value]), a: state.results.find((r) => r.id === state.a).name, note: $("axes-note").textContent };
  }
  if (kind === "live" && live.params.length) {
    // Move the first live control as a user would; report once the picture changed.
    const p = live.params[0], el = $("live-" + p.key);
    el.value = String(Math.min(p.max, Number(el.value) / 2 + p.min / 2));
    const before = live.last;
    el.dispatchEvent(new Event("input"));
    const wait = () => new Promise((res) => setTimeout(res, 20));
    return (async () => {
      for (let k = 0; k < 500 && (live.busy || live.last === before); k++) await wait();
      out.after = { centres: centres().map(([x, y, id]) => ({ x, y, id, rgb: pixel(x, y) })), readout: $("readout").textContent, latency: live.last, colours: $("colours").textContent };
      $("probe").textContent = JSON.stringify(out);
    })();
  }
  $("probe").textContent = JSON.stringify(out);
}

async function main() {
  try {
    initGl();
    const q = new URLSearchParams(location.search);
    state.results = await (await fetch("/api/results")).json();
    if (!state.results.length) throw new Error("the server has no results");
    const opts = state.results.map((r) => `<option value="${r.id}">${r.name}</option>`).join("");
    $("sel-a").innerHTML = opts;
    $("sel-b").innerHTML = `<option value="-1">none</option>` + opts;
    fromQuery(q);
    $("sel-a").value = state.a; $("sel-b").value = state.b;
    $("title").textContent = state.results.length === 1 ? state.results[0].name : `${state.results.length} results`;
    bindControls();
    axisPickers();
    syncLightSliders();
    await initLive();
    await select();
    if (q.has("probe")) await probe(q.get("probe"));
  } catch (e) {
    $("error").textContent = `error: ${e.message}`;
    $("probe").textContent = JSON.stringify({ error: e.message });
  }
}

main();
