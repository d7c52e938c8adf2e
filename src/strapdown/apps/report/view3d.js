// The report's 3D view (strapdown.apps.report.view3d): an orthographic camera over the reference frame, drawn on a
// 2D canvas (no WebGL: it works in any browser, headless ones included).  view3d.py computes the same projection
// for the first frame; the browser tests compare the two.  Vectors are [x, y, z] in the display frame (east, north,
// up); `cam` holds the camera's azimuth and elevation (radians).
const SD = {
  // q = [w, x, y, z] rotates v: v' = q v q* (Hamilton; body to reference)
  rotate(q, v) {
    const [w, x, y, z] = q;
    const tx = 2 * (y * v[2] - z * v[1]), ty = 2 * (z * v[0] - x * v[2]), tz = 2 * (x * v[1] - y * v[0]);
    return [v[0] + w * tx + (y * tz - z * ty), v[1] + w * ty + (z * tx - x * tz), v[2] + w * tz + (x * ty - y * tx)];
  },
  mul(m, v) {  // 3x3 row-major matrix times vector
    return [m[0] * v[0] + m[1] * v[1] + m[2] * v[2], m[3] * v[0] + m[4] * v[1] + m[5] * v[2],
            m[6] * v[0] + m[7] * v[1] + m[8] * v[2]];
  },
  basis(cam) {  // camera position c (unit), screen right r and screen up u
    const ca = Math.cos(cam.az), sa = Math.sin(cam.az), ce = Math.cos(cam.el), se = Math.sin(cam.el);
    const c = [sa * ce, ca * ce, se];
    const r = [-ca, sa, 0];
    const u = [r[1] * -c[2] - r[2] * -c[1], r[2] * -c[0] - r[0] * -c[2], r[0] * -c[1] - r[1] * -c[0]];
    return {c, r, u};
  },
  project(p, b) {
    return [p[0] * b.r[0] + p[1] * b.r[1] + p[2] * b.r[2], p[0] * b.u[0] + p[1] * b.u[1] + p[2] * b.u[2],
            p[0] * b.c[0] + p[1] * b.c[1] + p[2] * b.c[2]];
  },
  frameAt(frames, t) {  // the last frame at or before t (binary search)
    const ts = frames.data.t;
    let lo = 0, hi = ts.length - 1;
    if (t <= ts[0]) return 0;
    if (t >= ts[hi]) return hi;
    while (hi - lo > 1) {
      const mid = (lo + hi) >> 1;
      if (ts[mid] <= t) lo = mid; else hi = mid;
    }
    return lo;
  },
  shade(hex, k) {  // a colour darkened (k < 1) or lightened toward white (k > 1)
    const n = parseInt(hex.slice(1), 16);
    const f = (c) => Math.round(k <= 1 ? c * k : c + (255 - c) * (k - 1));
    const rgb = [(n >> 16) & 255, (n >> 8) & 255, n & 255].map(f).map((c) => Math.max(0, Math.min(255, c)));
    return "#" + rgb.map((c) => c.toString(16).padStart(2, "0")).join("");
  },
  // the body model, its axes and the reference axes for attitude q: the data of the three sources
  scene(spec, q, cam) {
    const b = SD.basis(cam);
    const toDisplay = (v) => SD.mul(spec.display, v);
    const world = spec.vertices.map((v) => toDisplay(SD.rotate(q, v)));
    const screen = world.map((p) => SD.project(p, b));
    const faces = spec.faces.map((f, i) => {
      const pts = f.map((k) => world[k]);
      const e1 = [pts[1][0] - pts[0][0], pts[1][1] - pts[0][1], pts[1][2] - pts[0][2]];
      const e2 = [pts[2][0] - pts[0][0], pts[2][1] - pts[0][1], pts[2][2] - pts[0][2]];
      const n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
      const len = Math.hypot(n[0], n[1], n[2]) || 1;
      const facing = (n[0] * b.c[0] + n[1] * b.c[1] + n[2] * b.c[2]) / len;
      const depth = f.reduce((s, k) => s + screen[k][2], 0) / f.length;
      const color = facing >= 0 ? spec.front[i] : spec.back[i];
      return {i, depth, color: SD.shade(color, 0.6 + 0.4 * Math.abs(facing))};
    });
    faces.sort((a, c) => a.depth - c.depth || a.i - c.i);  // far faces first (painter's order)
    const model = {xs: [], ys: [], color: []};
    for (const f of faces) {
      model.xs.push(spec.faces[f.i].map((k) => screen[k][0]));
      model.ys.push(spec.faces[f.i].map((k) => screen[k][1]));
      model.color.push(f.color);
    }
    const axes = {x0: [], y0: [], x1: [], y1: [], color: [], tx: [], ty: [], text: []};
    const add = (v, color, label) => {
      const p = SD.project(v, b);
      axes.x0.push(0); axes.y0.push(0); axes.x1.push(p[0]); axes.y1.push(p[1]); axes.color.push(color);
      axes.tx.push(p[0] * 1.08); axes.ty.push(p[1] * 1.08); axes.text.push(label);
    };
    spec.reference_axes.forEach((a) => add(toDisplay(a.v), a.color, a.label));
    spec.body_axes.forEach((a) => add(toDisplay(SD.rotate(q, a.v)), a.color, a.label));
    const ring = {x: [], y: []};
    for (const p of spec.ring) {
      const s = SD.project(p, b);
      ring.x.push(s[0]); ring.y.push(s[1]);
    }
    return {model, axes, ring};
  },
  draw(spec, sources, frames, t, cam) {
    const k = SD.frameAt(frames, t);
    const d = frames.data;
    const s = SD.scene(spec, [d.qw[k], d.qx[k], d.qy[k], d.qz[k]], cam);
    sources.model.data = s.model;
    sources.axes.data = s.axes;
    sources.ring.data = s.ring;
    return k;
  },
  points(spec, cam) {  // a cloud of display-frame points (the magnetometer sphere), projected
    const b = SD.basis(cam);
    const out = {};
    for (const [name, pts] of Object.entries(spec.clouds)) {
      const xs = [], ys = [];
      for (let i = 0; i < pts.x.length; i++) {
        const p = SD.project([pts.x[i], pts.y[i], pts.z[i]], b);
        xs.push(p[0]); ys.push(p[1]);
      }
      out[name] = {x: xs, y: ys};
    }
    return out;
  },
  orbit(cam, dx, dy) {  // a drag turns the camera: sideways about the vertical, up and down in elevation
    cam.az -= dx * 0.01;
    cam.el = Math.max(-1.55, Math.min(1.55, cam.el + dy * 0.01));
  },
};
