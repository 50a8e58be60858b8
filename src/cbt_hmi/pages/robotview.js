/* CBT HMI: the robot view of the main page and of every motion page. Two projections, the same on every page
   (top view X-Y and a side view, Y-Z or X-Z as the operator chose, see sideAxis; both in the robot base frame), at a fixed scale the operator changes with the
   zoom buttons (not with the content, so the view holds still while a target is typed), with a labelled grid and
   scale bar; the TM5-700 arm drawn from the joint angles CBT_ReadActualPosition reads (forward kinematics of the
   arm data in tm5_700.json); the TCP with its tool axes; the trail the server keeps (/api/trail); and, on a
   motion page, the target of the parameters as entered, previewed before Execute and drawn red with the reason
   when the TM5-700 cannot reach it (reachRefusal: the page refuses to send it). */
"use strict";

/* trailSeq counts the changes of the trail: a drawing of it is redone only when it changed */
const VIEW = { trail: [], trailSeq: 0, next: 0, preview: null, zoom: Number(sessionStorage.getItem("hmi.zoom")) || 1 };

/* The side view's horizontal axis, the same on every page (the PnP page included): Y by default — the robot as
   the operator facing it from the front (+X) sees it, Y to the right, Z up, the direction the PnP example's cycle
   travels — or X (seen from its side, the arm's reach in profile); the operator switches it on any page and the
   choice holds for every page of the browser tab. */
function sideAxis() { return sessionStorage.getItem("hmi.side") === "X" ? "X" : "Y"; }
function toggleSideAxis() { sessionStorage.setItem("hmi.side", sideAxis() === "X" ? "Y" : "X"); }
const AXIS_COLORS = ["#d0312d", "#2e9b4f", "#1a5fb4"];          // X red, Y green, Z blue (ISO colours)
const ZOOMS = [0.5, 1, 2, 4];                                   // 1: ±1000 mm across the narrower side
const RED = "#c0241a", VIOLET = "#6a2fa8";

/* ---- the TM5-700's kinematics, from the one data file src/cbt_hmi/pages/tm5_700.json (checked against the simulator's
   src/tmsim/robot/kinematics.py by tests/hmi/test_hmi_robot_view.py). Matrices are 4x4 row lists. ---- */
const ARM = { data: null };
const armReady = fetch(dataFileAddress("tm5_700.json")).then((r) => r.json()).then((d) => { ARM.data = d; })
  .catch(() => { /* no arm data: the view draws no arm and the page leaves the reach check to the robot */ });
const RAD = Math.PI / 180;

/* TM poses: X, Y, Z in mm, RX, RY, RZ in degrees, fixed-axis X-Y-Z rotations: R = Rz · Ry · Rx */
function rotation(p) {
  const [a, b, c] = [p.RX, p.RY, p.RZ].map((d) => d * RAD);
  const [ca, sa, cb, sb, cc, sc] = [Math.cos(a), Math.sin(a), Math.cos(b), Math.sin(b), Math.cos(c), Math.sin(c)];
  return [[cc * cb, cc * sb * sa - sc * ca, cc * sb * ca + sc * sa],
          [sc * cb, sc * sb * sa + cc * ca, sc * sb * ca - cc * sa],
          [-sb, cb * sa, cb * ca]];
}
const column = (m, i) => [m[0][i], m[1][i], m[2][i]];
const applyRot = (m, v) => [0, 1, 2].map((r) => m[r][0] * v[0] + m[r][1] * v[1] + m[r][2] * v[2]);
const poseMatrix = (p) => { const r = rotation(p); return [[...r[0], p.X], [...r[1], p.Y], [...r[2], p.Z], [0, 0, 0, 1]]; };
const matMul = (m, n) => m.map((row) => [0, 1, 2, 3].map((j) => row.reduce((s, v, k) => s + v * n[k][j], 0)));
function rigidInverse(m) {
  const r = [0, 1, 2].map((i) => [m[0][i], m[1][i], m[2][i]]);
  const t = r.map((row) => -(row[0] * m[0][3] + row[1] * m[1][3] + row[2] * m[2][3]));
  return [[...r[0], t[0]], [...r[1], t[1]], [...r[2], t[2]], [0, 0, 0, 1]];
}
/* standard DH step of joint i at angle q (deg): Rz(q + offset) Tz(d) Tx(a) Rx(alpha) */
function dhMatrix(j, q) {
  const th = (q + j.offset) * RAD, al = j.alpha * RAD;
  const [ct, st, ca, sa] = [Math.cos(th), Math.sin(th), Math.cos(al), Math.sin(al)];
  return [[ct, -st * ca, st * sa, j.a * ct], [st, ct * ca, -ct * sa, j.a * st], [0, sa, ca, j.d], [0, 0, 0, 1]];
}
/* base-to-joint frames T0 (base) .. T6 (flange) for joint angles J1..J6 (deg) */
function armFrames(joints) {
  const frames = [[[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]];
  ARM.data.joints.forEach((j, i) => frames.push(matMul(frames[i], dhMatrix(j, joints[i]))));
  return frames;
}
const origin = (m) => [m[0][3], m[1][3], m[2][3]];
/* the points the arm is drawn through: base, shoulder, elbow, wrist 1-3, flange, TCP */
function armPoints(joints, tcp) {
  const f = armFrames(joints), pts = [[0, 0, 0], ...f.slice(1).map(origin)];
  return tcp ? [...pts, tcp] : pts;
}

/* the joint angles J1..J6 read by CBT_ReadActualPosition, null while not valid */
function readJoints() {
  const v = live.values, pos = v.ReadPos_Valid && v.ReadPos_Position;
  return pos && Array.isArray(pos.Joints) && pos.Joints.length === 6 ? pos.Joints : null;
}

/* the tool the robot uses now, from the position read: flange⁻¹ · TCP (identity without a valid position);
   the targets are taken in the robot base, as the view draws them */
function currentTool() {
  const joints = readJoints(), tcp = joints && live.values.ReadPos_Position.TCP;
  if (!ARM.data || !tcp) return null;
  return matMul(rigidInverse(armFrames(joints)[6]), poseMatrix(tcp));
}

/* closed-form inverse kinematics of the flange pose `t` (joints 2, 3, 4 parallel: up to 8 solutions), the same
   construction as the simulator's kinematics._analytic; {solutions: [[J1..J6]], singular, planar} */
function analyticIK(t) {
  const J = ARM.data.joints, d1 = J[0].d, a2 = J[1].a, a3 = J[2].a, d4 = J[3].d, d6 = J[5].d;
  const z6 = [t[0][2], t[1][2], t[2][2]];
  const p5 = [0, 1, 2].map((i) => t[i][3] - d6 * z6[i]);
  const r = Math.hypot(p5[0], p5[1]);
  const out = { solutions: [], singular: false, planar: false, axis: r < Math.abs(d4) };
  if (out.axis) return out;
  const phi = Math.atan2(p5[1], p5[0]), base = Math.asin(Math.max(-1, Math.min(1, d4 / r)));
  for (const t1 of [phi - base, phi - (Math.PI - base)]) {
    const c1 = Math.cos(t1), s1 = Math.sin(t1);
    const invA1 = [[c1, s1, 0, 0], [0, 0, -1, d1], [-s1, c1, 0, 0], [0, 0, 0, 1]];
    const z1 = [-s1, c1, 0];
    const c5 = -(z1[0] * z6[0] + z1[1] * z6[1]);
    if (Math.abs(c5) > 1 - 1e-9) { out.singular = true; continue; }
    const z16 = [0, 1, 2].map((j) => t[0][j] * z1[0] + t[1][j] * z1[1] + t[2][j] * z1[2]);
    const m1t = matMul(invA1, t);
    for (const t5 of [Math.acos(c5), -Math.acos(c5)]) {
      const s5 = Math.sin(t5), t6 = Math.atan2(-z16[1] / s5, z16[0] / s5);
      const m14 = matMul(m1t, rigidInverse(matMul(dhMatrix(J[4], t5 / RAD), dhMatrix(J[5], t6 / RAD))));
      const x = m14[0][3], y = m14[1][3];
      const c3 = (x * x + y * y - a2 * a2 - a3 * a3) / (2 * a2 * a3);
      if (Math.abs(c3) > 1) { out.planar = true; continue; }
      for (const t3 of [Math.acos(c3), -Math.acos(c3)]) {
        const t2 = Math.atan2(y, x) - Math.atan2(a3 * Math.sin(t3), a2 + a3 * Math.cos(t3));
        const t4 = Math.atan2(m14[1][0], m14[0][0]) - t2 - t3;
        out.solutions.push([t1 / RAD, t2 / RAD - J[1].offset, t3 / RAD, t4 / RAD - J[3].offset, t5 / RAD, t6 / RAD]);
      }
    }
  }
  return out;
}

/* a joint angle brought within its limit by whole turns, or null when no turn fits */
function withinLimit(q, limit) {
  for (const v of [q - 360 * Math.round(q / 360), q - 360 * Math.round(q / 360) + 360, q - 360 * Math.round(q / 360) - 360])
    if (Math.abs(v) <= limit + 1e-6) return v;
  return null;
}

/* joint angles (deg) beyond the TM5-700's joint ranges: the reason, else null */
function jointRefusal(joints) {
  if (!ARM.data) return null;
  for (const [i, j] of ARM.data.joints.entries())
    if (Math.abs(joints[i]) > j.limit) return `${j.name} ${fmt(joints[i])}° is beyond its range ±${j.limit}°`;
  return null;
}

const fmt = (v) => (Math.round(v * 10) / 10).toString();

/* Can the TM5-700 reach this TCP pose (robot base, the tool in use now)? {reason} when not, else {joints} (the
   solution nearest to the arm's present joints, for drawing) — {} when the check cannot tell (no arm data, or
   the wrist straight, where only the robot's numerical solver decides). */
function reachCheck(pose) {
  if (!ARM.data) return {};
  const tool = currentTool();
  const flange = tool ? matMul(poseMatrix(pose), rigidInverse(tool)) : poseMatrix(pose);
  const J = ARM.data.joints, d6 = J[5].d;
  const wrist = [0, 1, 2].map((i) => flange[i][3] - d6 * flange[i][2]);
  const fromShoulder = Math.hypot(wrist[0], wrist[1], wrist[2] - J[0].d);
  const maxReach = J[1].a + J[2].a + Math.abs(J[3].d) + J[4].d;
  const where = `X ${fmt(pose.X)} Y ${fmt(pose.Y)} Z ${fmt(pose.Z)}`;
  if (fromShoulder > maxReach + 1)
    return { short: `out of reach (${Math.round(fromShoulder)} > ${Math.round(maxReach)} mm)`, reason: `${where} is out of reach: the wrist would be ${Math.round(fromShoulder)} mm from the ` +
      `shoulder; the ${ARM.data.model} reaches ${Math.round(maxReach)} mm (rated reach ${ARM.data.reach_mm} mm)` };
  const ik = analyticIK(flange);
  if (ik.axis) return { short: "too close to the base axis", reason: `${where} is too close to the robot's base axis: the wrist cannot come nearer than ` +
    `${Math.abs(J[3].d)} mm to it` };
  const now = readJoints() || ARM.data.home_joints;
  let best = null, beyond = null;
  const target = origin(flange);
  for (const q of ik.solutions) {
    if (Math.hypot(...origin(armFrames(q)[6]).map((v, i) => v - target[i])) > 0.5) continue;   // as the simulator: verified
    const fitted = q.map((v, i) => withinLimit(v, J[i].limit));
    const bad = fitted.findIndex((v) => v === null);
    if (bad >= 0) { beyond = beyond || `${J[bad].name} would need ${fmt(q[bad])}° (range ±${J[bad].limit}°)`; continue; }
    const cost = fitted.reduce((s, v, i) => s + (v - now[i]) ** 2, 0);
    if (!best || cost < best.cost) best = { joints: fitted, cost };
  }
  if (best) return { joints: best.joints };
  if (ik.singular) return {};
  if (beyond) return { short: `beyond the joint ranges: ${beyond}`, reason: `${where} is beyond the joint ranges in this orientation: ${beyond}` };
  return { short: "out of reach in this orientation", reason: `${where} is out of reach in this orientation (RX ${fmt(pose.RX)} RY ${fmt(pose.RY)} ` +
    `RZ ${fmt(pose.RZ)}): the arm cannot bend to it` };
}

/* the arc of a circular move: from `a` through `b` to `c` (points as [x, y, z]); null when they are in line */
function arcPoints(a, b, c, steps = 40) {
  const sub = (p, q) => p.map((v, i) => v - q[i]), dot = (p, q) => p.reduce((s, v, i) => s + v * q[i], 0);
  const cross = (p, q) => [p[1] * q[2] - p[2] * q[1], p[2] * q[0] - p[0] * q[2], p[0] * q[1] - p[1] * q[0]];
  const u = sub(b, a), v = sub(c, a), w = cross(u, v), ww = dot(w, w);
  if (ww < 1e-6) return null;
  const k = cross(w, u).map((x) => x * dot(v, v)), l = cross(v, w).map((x) => x * dot(u, u));
  const centre = a.map((x, i) => x + (k[i] + l[i]) / (2 * ww));
  const r0 = sub(a, centre), n = w.map((x) => x / Math.sqrt(ww)), r1 = cross(n, r0);
  const angle = (p) => { const d = sub(p, centre); return Math.atan2(dot(d, r1), dot(d, r0)); };
  const norm = (t) => (t < 0 ? t + 2 * Math.PI : t);
  const end = norm(angle(c));
  return Array.from({ length: steps + 1 }, (_, i) => {
    const t = (end * i) / steps;
    return centre.map((x, j) => x + r0[j] * Math.cos(t) + r1[j] * Math.sin(t));
  });
}

function niceStep(span) {
  const raw = span / 5, mag = 10 ** Math.floor(Math.log10(raw));
  return [1, 2, 5, 10].map((f) => f * mag).find((s) => s >= raw);
}

/* The fixed scale of a projection: at zoom 1 the narrower side of the view spans 1800 mm (the 700 mm reach with
   room around it); the view is centred on the base, or on the TCP when zoomed in beyond 1, never on the target. */
function viewScale(W, H, zoom) { return Math.min(W, H) / (1800 / zoom); }

function drawProjection(canvas, h, v, title, tcp, arm) {
  const rect = canvas.getBoundingClientRect();
  canvas.width = Math.max(60, Math.round(rect.width)); canvas.height = Math.max(60, Math.round(rect.height));
  const ctx = canvas.getContext("2d"), W = canvas.width, H = canvas.height;
  const idx = { X: 0, Y: 1, Z: 2 }, hi = idx[h], vi = idx[v];
  const pv = VIEW.preview, zoom = VIEW.zoom, scale = viewScale(W, H, zoom);
  const home = [0, 0, v === "Z" ? 350 : 0];                       // the side view looks at the arm's height
  const centre = zoom > 1 && tcp ? [tcp.X, tcp.Y, tcp.Z] : home;
  const X = (p) => W / 2 + (p[hi] - centre[hi]) * scale, Y = (p) => H / 2 - (p[vi] - centre[vi]) * scale;
  const inView = (p) => X(p) >= 0 && X(p) <= W && Y(p) >= 0 && Y(p) <= H;
  ctx.fillStyle = "#f6f8fa"; ctx.fillRect(0, 0, W, H);
  const step = niceStep(Math.min(W, H) / scale);                 // grid, labelled along the bottom and left edges
  const h0 = centre[hi] - W / 2 / scale, h1 = centre[hi] + W / 2 / scale;
  const v0 = centre[vi] - H / 2 / scale, v1 = centre[vi] + H / 2 / scale;
  const at = (i, g) => [0, 1, 2].map((k) => (k === i ? g : 0));
  ctx.strokeStyle = "#d5dce3"; ctx.lineWidth = 1; ctx.beginPath();
  for (let g = Math.ceil(h0 / step) * step; g <= h1; g += step) { const x = X(at(hi, g)); ctx.moveTo(x, 0); ctx.lineTo(x, H); }
  for (let g = Math.ceil(v0 / step) * step; g <= v1; g += step) { const y = Y(at(vi, g)); ctx.moveTo(0, y); ctx.lineTo(W, y); }
  ctx.stroke();
  ctx.font = "14px sans-serif"; ctx.fillStyle = "#3d4852"; ctx.textBaseline = "alphabetic";
  const labelGap = ctx.measureText("-0000").width + 8;           // a coordinate label every line that has room
  let lastX = -Infinity;
  for (let g = Math.ceil(h0 / step) * step; g <= h1; g += step) {
    const x = X(at(hi, g));
    if (x - lastX >= labelGap && x > 20 && x < W - 20) { ctx.textAlign = "center"; ctx.fillText(String(Math.round(g)), x, H - 4); lastX = x; }
  }
  let lastY = Infinity;
  ctx.textAlign = "left";
  for (let g = Math.ceil(v0 / step) * step; g <= v1; g += step) {
    const y = Y(at(vi, g));
    if (lastY - y >= 22 && y > 34 && y < H - 22) { ctx.fillText(String(Math.round(g)), 3, y + 5); lastY = y; }
  }
  if (h === "X" && v === "Y") {                                  // rated reach of the TM5-700 around the base
    ctx.setLineDash([6, 4]); ctx.strokeStyle = "#6b7785"; ctx.lineWidth = 1.5; ctx.beginPath();
    ctx.arc(X([0, 0, 0]), Y([0, 0, 0]), ((ARM.data && ARM.data.reach_mm) || 700) * scale, 0, 2 * Math.PI);
    ctx.stroke(); ctx.setLineDash([]);
  }
  const arrow = (from, dir, len, color, label) => {
    const x0 = X(from), y0 = Y(from), dx = dir[hi], dy = -dir[vi];
    const x1 = x0 + dx * len, y1 = y0 + dy * len;
    ctx.strokeStyle = color; ctx.fillStyle = color; ctx.lineWidth = 2;
    ctx.beginPath(); ctx.moveTo(x0, y0); ctx.lineTo(x1, y1); ctx.stroke();
    if (label && Math.hypot(dx, dy) > 0.3) ctx.fillText(label, x1 + 2, y1 + 5);
  };
  const frame = (pose, len, labels) => {                         // the axes of a frame, projected
    const m = rotation(pose);
    [0, 1, 2].forEach((i) => arrow([pose.X, pose.Y, pose.Z], column(m, i), len, AXIS_COLORS[i], labels ? labels[i] : ""));
  };
  const polyline = (pts, color, width, dash) => {
    ctx.strokeStyle = color; ctx.lineWidth = width; ctx.setLineDash(dash || []); ctx.lineJoin = "round"; ctx.beginPath();
    pts.forEach((p, i) => (i ? ctx.lineTo(X(p), Y(p)) : ctx.moveTo(X(p), Y(p))));
    ctx.stroke(); ctx.setLineDash([]);
  };
  frame({ X: 0, Y: 0, Z: 0, RX: 0, RY: 0, RZ: 0 }, 26);
  if (arm) {                                                     // the arm, from the joint angles read
    polyline(arm, "#8795a3", 7); polyline(arm, "#4a5661", 2);
    ctx.fillStyle = "#4a5661";
    arm.slice(1, 7).forEach((p) => { ctx.beginPath(); ctx.arc(X(p), Y(p), 3.5, 0, 7); ctx.fill(); });
  }
  if (VIEW.trail.length > 1) polyline(VIEW.trail, "#34a853", 1.5);
  if (pv && pv.frame) frame(pv.frame, 30, ["X'", "Y'", "Z'"]);
  if (pv && pv.path && pv.path.length) {
    const color = pv.refused ? RED : VIOLET;
    if (pv.arm) polyline(pv.arm, VIOLET, 2, [3, 3]);                // where the arm will be
    polyline(pv.path, color, pv.refused ? 3 : 2, [6, 4]);
    const t = pv.path[pv.path.length - 1];
    const tx = Math.min(Math.max(X(t), 10), W - 10), ty = Math.min(Math.max(Y(t), 10), H - 10);
    ctx.strokeStyle = color; ctx.lineWidth = 2.5; ctx.beginPath();
    if (pv.refused) { ctx.moveTo(tx - 7, ty - 7); ctx.lineTo(tx + 7, ty + 7); ctx.moveTo(tx + 7, ty - 7); ctx.lineTo(tx - 7, ty + 7); }
    else ctx.arc(tx, ty, 6, 0, 2 * Math.PI);
    ctx.stroke();
    if (pv.target && !pv.refused && inView(t)) frame(pv.target, 16);
    ctx.fillStyle = color; ctx.font = "bold 14px sans-serif";
    const label = pv.refused ? (inView(t) ? "unreachable" : "target off view") : "target";
    const right = tx > W - ctx.measureText(label).width - 12;      // keep the label inside the view
    ctx.textAlign = right ? "right" : "left";
    ctx.fillText(label, tx + (right ? -10 : 10), ty < 40 ? ty + 20 : ty - 8); ctx.textAlign = "left";
    ctx.font = "14px sans-serif";
  }
  if (tcp) {
    frame(tcp, 20);
    ctx.fillStyle = "#e07b00"; ctx.beginPath(); ctx.arc(X([tcp.X, tcp.Y, tcp.Z]), Y([tcp.X, tcp.Y, tcp.Z]), 4.5, 0, 7); ctx.fill();
  }
  const head = `${title} ${h}→ ${v}↑ · grid ${step} mm`;           // title and grid pitch, top left
  ctx.font = "14px sans-serif";
  ctx.fillStyle = "rgba(246,248,250,0.85)"; ctx.fillRect(0, 0, ctx.measureText(head).width + 10, 20);
  ctx.fillStyle = "#1d2733"; ctx.fillText(head, 5, 15);
  canvas.dataset.scale = String(scale);                           // px per mm, for the tests
  canvas.dataset.grid = String(step);
  canvas.dataset.axes = `${h}-${v}`;
  canvas.dataset.arm = arm ? JSON.stringify(arm.map((p) => [Math.round(X(p)), Math.round(Y(p))])) : "";
}

/* the robot view's own controls and texts: 34 px touch targets, 14 px text (the 9-inch panel's minimum) */
function robotViewStyle() {
  if (document.getElementById("robotview-style")) return;
  const style = document.createElement("style");
  style.id = "robotview-style";
  style.textContent = `.robotview .viewfoot { align-items: center; font-size: 14px; color: #3d4852; min-height: 34px; }
    .robotview .viewfoot .pos { font-size: 14px; color: #3d4852; min-width: 0; overflow: hidden;
      text-overflow: ellipsis; white-space: nowrap; }
    .robotview .viewfoot .note { flex: 1; min-width: 0; color: #5a2a91; white-space: normal; line-height: 16px; }
    .robotview .viewfoot .note.refused { color: #b0211a; font-weight: bold; order: -1; flex: none; }
    .robotview .zoom { display: flex; align-items: center; gap: 4px; flex: none; }
    .robotview .zoom #side-axis { font-size: 14px; margin-right: 6px; }
    .robotview .zoom button { min-width: 34px; height: 34px; padding: 0 6px; font-size: 18px; line-height: 1; }
    .robotview .zoom span { min-width: 30px; text-align: center; }`;
  document.head.append(style);
}

/* the view in `container`; `preview()` (optional) returns {path: [[x,y,z]...], target: pose, frame: pose, note} */
function robotView(container, preview) {
  robotViewStyle();
  container.classList.add("robotview");
  container.innerHTML = `<div class="views"><canvas id="view-top"></canvas><canvas id="view-side"></canvas></div>
    <div class="viewfoot"><span class="pos" id="tcp-pos">X — Y — Z —</span><span class="note" id="view-note"></span>
    <span class="zoom"><button type="button" id="side-axis"></button>
    <button type="button" id="zoom-out" aria-label="Zoom out" title="Zoom out">−</button>
    <span id="zoom-level"></span><button type="button" id="zoom-in" aria-label="Zoom in" title="Zoom in">+</button></span></div>`;
  /* what the two canvases show, as last drawn: a poll that changes none of it draws nothing (docs/hmi.md,
     Performance); the canvases' sizes are part of it, so a resized view is drawn again */
  let drawn = "";
  const redraw = () => {
    VIEW.preview = preview ? preview() : null;
    const pos = live.values.ReadPos_Valid && live.values.ReadPos_Position ? live.values.ReadPos_Position : null;
    const p = pos ? pos.TCP : null;
    const arm = readJoints() && ARM.data ? armPoints(readJoints(), [p.X, p.Y, p.Z]) : null;
    const top = container.querySelector("#view-top"), side = container.querySelector("#view-side");
    const size = (c) => { const r = c.getBoundingClientRect(); return [Math.round(r.width), Math.round(r.height)]; };
    const scene = JSON.stringify([VIEW.preview, p, arm, VIEW.trailSeq, VIEW.zoom, sideAxis(), Boolean(ARM.data),
      size(top), size(side)]);
    if (scene !== drawn) {
      drawProjection(top, "X", "Y", "Top", p, arm);
      drawProjection(side, sideAxis(), "Z", "Side", p, arm);
      drawn = scene;
    }
    const other = sideAxis() === "X" ? "Y" : "X", toggle = container.querySelector("#side-axis");
    setText(toggle, `${other}–Z view`);
    setAttr(toggle, "title", `Show the side view ${other}–Z (on every page)`);
    setAttr(toggle, "aria-label", `Show the side view ${other}–Z (on every page)`);
    // without the PLC the last position is no longer valid (####, as every value); a short text when the robot gives
    // none, so the preview's note beside it keeps its room at 800x480
    setText(container.querySelector("#tcp-pos"), !live.online && !live.fault ? "TCP ####" : p ?
      `TCP X ${p.X.toFixed(1)} Y ${p.Y.toFixed(1)} Z ${p.Z.toFixed(1)}` : "TCP not valid");
    const note = container.querySelector("#view-note"), pv = VIEW.preview;
    setText(note, pv && pv.refused ? `✕ ${pv.refused.short}` : (pv && pv.note) || "");
    setAttr(note, "title", pv && pv.refused ? pv.refused.reason : "");
    note.classList.toggle("refused", Boolean(pv && pv.refused));
    setText(container.querySelector("#zoom-level"), `${VIEW.zoom}×`);
    setDisabled(container.querySelector("#zoom-out"), VIEW.zoom === ZOOMS[0]);
    setDisabled(container.querySelector("#zoom-in"), VIEW.zoom === ZOOMS[ZOOMS.length - 1]);
  };
  const zoomBy = (d) => {
    const i = Math.max(0, Math.min(ZOOMS.length - 1, ZOOMS.indexOf(VIEW.zoom) + d));
    VIEW.zoom = ZOOMS[i];
    sessionStorage.setItem("hmi.zoom", String(VIEW.zoom));
    redraw();
  };
  if (!ZOOMS.includes(VIEW.zoom)) VIEW.zoom = 1;
  container.querySelector("#side-axis").onclick = () => { toggleSideAxis(); redraw(); };
  container.querySelector("#zoom-out").onclick = () => zoomBy(-1);
  container.querySelector("#zoom-in").onclick = () => zoomBy(1);
  live.listeners.push(redraw);
  live.listeners.push(fetchTrail);
  armReady.then(redraw);
  return redraw;
}

/* new trail points from the server, every 4th poll */
let trailBusy = false;
async function fetchTrail() {
  if (trailBusy || live.polls % 4) return;
  trailBusy = true;
  try {
    const data = await api(`/api/trail?since=${VIEW.next}`);
    const changed = data.complete ? data.points.length > 0 : JSON.stringify(data.points) !== JSON.stringify(VIEW.trail);
    if (changed) {
      VIEW.trail = data.complete ? VIEW.trail.concat(data.points) : data.points;
      if (VIEW.trail.length > 2000) VIEW.trail = VIEW.trail.slice(-2000);
      VIEW.trailSeq += 1;
    }
    VIEW.next = data.next;
  } catch (e) { /* the trail is a nicety: the next poll tries again */ }
  trailBusy = false;
}

/* ---- previews of the motion pages, from the fields as entered ---- */
function formPose(root, prefix) {
  const pose = {};
  for (const k of ["X", "Y", "Z", "RX", "RY", "RZ"]) {
    const el = root.querySelector(`[data-path="${prefix}.${k}"]`);
    const v = el ? Number(el.value) : NaN;
    if (!el || el.value.trim() === "" || !Number.isFinite(v)) return null;
    pose[k] = v;
  }
  return pose;
}
const xyz = (p) => [p.X, p.Y, p.Z];
const MOTION_TYPES = { stCBT_MovAbsParam: "moveabs", stCBT_MovRelParam: "moverel", stCBT_MovCircleParam: "movecircle",
  stCBT_BaseParam: "changebase" };

/* the poses a motion form would send the robot to: {kind, targets: [pose], path, note} or {joints} (joint formats) */
function motionTargets(root, param) {
  const spec = param && MAP.variables[param.split("[")[0]];
  const key = spec && MOTION_TYPES[spec.type];
  if (!key) return null;
  const ctx = formContext(root, param);
  const tcp = live.values.ReadPos_Valid && live.values.ReadPos_Position ? live.values.ReadPos_Position.TCP : null;
  const fmtName = ctx.DataFormat || "";
  if (key === "changebase") {
    const f = formPose(root, `${param}.Transformation`);
    return { key, frame: f, targets: [], note: f ? "X' Y' Z': the new base" : "" };
  }
  if (fmtName.startsWith("J")) {
    const j = formPose(root, `${param}.TargetPosition`);
    const joints = j && [j.X, j.Y, j.Z, j.RX, j.RY, j.RZ];
    if (key === "moverel" && joints) {
      const now = readJoints();
      return { key, joints: now ? joints.map((v, i) => v + now[i]) : null, targets: [], note: "joint offsets" };
    }
    return { key, joints, targets: [], note: "joint values" };
  }
  if (key === "moveabs") {
    const t = formPose(root, `${param}.TargetPosition`);
    if (!t) return { key, targets: [], note: "" };
    return { key, targets: [t], members: ["TargetPosition"], path: tcp ? [xyz(tcp), xyz(t)] : [xyz(t)], note: `${ctx.MovementCommand} to the target` };
  }
  if (!tcp) return { key, targets: [], note: "preview needs the TCP position" };
  if (key === "moverel") {
    const o = formPose(root, `${param}.TargetPosition`);
    if (!o) return { key, targets: [], note: "" };
    const d = fmtName.startsWith("T") ? applyRot(rotation(tcp), xyz(o)) : xyz(o);       // tool frame or base
    const t = { X: tcp.X + d[0], Y: tcp.Y + d[1], Z: tcp.Z + d[2], RX: tcp.RX + o.RX, RY: tcp.RY + o.RY, RZ: tcp.RZ + o.RZ };
    return { key, targets: [t], members: ["TargetPosition"], path: [xyz(tcp), xyz(t)], note: fmtName.startsWith("T") ? "offset in the tool frame" : "offset in the base" };
  }
  const a = formPose(root, `${param}.ArcPoint`), e = formPose(root, `${param}.EndPoint`);
  if (!a || !e) return { key, targets: [], note: "" };
  const arc = arcPoints(xyz(tcp), xyz(a), xyz(e));
  return arc ? { key, targets: [a, e], members: ["ArcPoint", "EndPoint"], path: arc, note: "arc through the arc point" } :
    { key, targets: [], note: "the three points are in line: no circle" };
}

/* the reason the TM5-700 cannot go where the form says ({short, reason}), else null; sets m.joints for drawing */
function reachRefusal(m) {
  if (!m) return null;
  if (m.joints) {
    const why = jointRefusal(m.joints);
    return why ? { short: why, reason: why, member: "TargetPosition" } : null;
  }
  for (const [i, t] of m.targets.entries()) {
    const r = reachCheck(t);
    if (r.reason) return { ...r, member: m.members[i] };
    if (t === m.targets[m.targets.length - 1]) m.armJoints = r.joints;
  }
  return null;
}

function motionPreview(key, root, param) {
  const m = motionTargets(root, param);
  if (!m) return null;
  const refused = reachRefusal(m);
  const joints = refused ? null : m.joints || m.armJoints;
  const t = m.targets[m.targets.length - 1];
  const arm = joints && ARM.data ? armPoints(joints, t ? xyz(t) : null) : null;
  return { path: m.path, target: t, frame: m.frame, note: m.note, refused, arm };
}
