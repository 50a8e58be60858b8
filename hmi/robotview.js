/* CBT HMI: the robot view of the main page and of every motion page. Two projections (top X-Y, side X-Z) at
   one scale with a grid, a scale bar and the robot base frame; the TCP with its tool axes; the trail the server
   keeps (/api/trail, so it does not start when the page opens); and, on a motion page, the target of the
   parameters as entered, previewed before Execute. */
"use strict";

const VIEW = { trail: [], next: 0, preview: null };
const AXIS_COLORS = ["#d0312d", "#2e9b4f", "#1a5fb4"];          // X red, Y green, Z blue (ISO colours)

/* TM poses: X, Y, Z in mm, RX, RY, RZ in degrees, fixed-axis X-Y-Z rotations: R = Rz · Ry · Rx */
function rotation(p) {
  const [a, b, c] = [p.RX, p.RY, p.RZ].map((d) => (d * Math.PI) / 180);
  const [ca, sa, cb, sb, cc, sc] = [Math.cos(a), Math.sin(a), Math.cos(b), Math.sin(b), Math.cos(c), Math.sin(c)];
  return [[cc * cb, cc * sb * sa - sc * ca, cc * sb * ca + sc * sa],
          [sc * cb, sc * sb * sa + cc * ca, sc * sb * ca - cc * sa],
          [-sb, cb * sa, cb * ca]];
}
const column = (m, i) => [m[0][i], m[1][i], m[2][i]];
const applyRot = (m, v) => [0, 1, 2].map((r) => m[r][0] * v[0] + m[r][1] * v[1] + m[r][2] * v[2]);

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

function drawProjection(canvas, h, v, title, tcp) {
  const rect = canvas.getBoundingClientRect();
  canvas.width = Math.max(60, Math.round(rect.width)); canvas.height = Math.max(60, Math.round(rect.height));
  const ctx = canvas.getContext("2d"), W = canvas.width, H = canvas.height;
  const idx = { X: 0, Y: 1, Z: 2 }, hi = idx[h], vi = idx[v];
  const pv = VIEW.preview;
  const pts = [[0, 0, 0], ...VIEW.trail.slice(-600)];
  if (tcp) pts.push([tcp.X, tcp.Y, tcp.Z]);
  if (pv && pv.path) pts.push(...pv.path);
  if (pv && pv.frame) pts.push([pv.frame.X, pv.frame.Y, pv.frame.Z]);
  let [h0, h1, v0, v1] = [Infinity, -Infinity, Infinity, -Infinity];
  for (const p of pts) { h0 = Math.min(h0, p[hi]); h1 = Math.max(h1, p[hi]); v0 = Math.min(v0, p[vi]); v1 = Math.max(v1, p[vi]); }
  const pad = 20, minSpan = 600;
  const grow = (lo, hiV) => { const m = (lo + hiV) / 2, s = Math.max(hiV - lo, minSpan) / 2 + pad; return [m - s, m + s]; };
  [h0, h1] = grow(h0, h1); [v0, v1] = grow(v0, v1);
  const M = 30;                                             // px kept free at each side for labels and arrows
  const scale = Math.min((W - 2 * M) / (h1 - h0), (H - 2 * M) / (v1 - v0));
  const ox = M + ((W - 2 * M) - (h1 - h0) * scale) / 2, oy = M + ((H - 2 * M) - (v1 - v0) * scale) / 2;
  const X = (p) => ox + (p[hi] - h0) * scale, Y = (p) => oy + (v1 - p[vi]) * scale;
  ctx.fillStyle = "#f6f8fa"; ctx.fillRect(0, 0, W, H);
  const step = niceStep(Math.max(h1 - h0, v1 - v0));       // grid
  ctx.strokeStyle = "#e1e6eb"; ctx.lineWidth = 1; ctx.beginPath();
  for (let g = Math.ceil(h0 / step) * step; g <= h1; g += step) { const x = X([g, g, g].map((q, i) => (i === hi ? g : 0))); ctx.moveTo(x, 0); ctx.lineTo(x, H); }
  for (let g = Math.ceil(v0 / step) * step; g <= v1; g += step) { const y = Y([g, g, g].map((q, i) => (i === vi ? g : 0))); ctx.moveTo(0, y); ctx.lineTo(W, y); }
  ctx.stroke();
  if (h === "X" && v === "Y") {                              // reach of the TM5-700 around the base
    ctx.setLineDash([4, 4]); ctx.strokeStyle = "#b6c0ca"; ctx.beginPath();
    ctx.arc(X([0, 0, 0]), Y([0, 0, 0]), 700 * scale, 0, 2 * Math.PI); ctx.stroke(); ctx.setLineDash([]);
  }
  const arrow = (from, dir, len, color, label) => {
    const x0 = X(from), y0 = Y(from), dx = dir[hi], dy = -dir[vi];
    const x1 = x0 + dx * len, y1 = y0 + dy * len;
    ctx.strokeStyle = color; ctx.fillStyle = color; ctx.lineWidth = 2;
    ctx.beginPath(); ctx.moveTo(x0, y0); ctx.lineTo(x1, y1); ctx.stroke();
    if (label && Math.hypot(dx, dy) > 0.3) ctx.fillText(label, x1 + 2, y1 + 3);
  };
  ctx.font = "10px sans-serif";
  const frame = (pose, len, labels) => {                     // the axes of a frame, projected
    const m = rotation(pose);
    [0, 1, 2].forEach((i) => arrow([pose.X, pose.Y, pose.Z], column(m, i), len, AXIS_COLORS[i], labels ? labels[i] : ""));
  };
  frame({ X: 0, Y: 0, Z: 0, RX: 0, RY: 0, RZ: 0 }, 26, ["X", "Y", "Z"]);
  ctx.fillStyle = "#24425f"; ctx.fillText("Base", X([0, 0, 0]) + 4, Y([0, 0, 0]) + 12);
  if (VIEW.trail.length > 1) {
    ctx.strokeStyle = "#34a853"; ctx.lineWidth = 1.5; ctx.beginPath();
    VIEW.trail.forEach((p, i) => (i ? ctx.lineTo(X(p), Y(p)) : ctx.moveTo(X(p), Y(p))));
    ctx.stroke();
  }
  if (pv && pv.frame) frame(pv.frame, 30, ["X'", "Y'", "Z'"]);
  if (pv && pv.path && pv.path.length) {
    ctx.strokeStyle = "#7a3db8"; ctx.lineWidth = 2; ctx.setLineDash([6, 4]); ctx.beginPath();
    pv.path.forEach((p, i) => (i ? ctx.lineTo(X(p), Y(p)) : ctx.moveTo(X(p), Y(p))));
    ctx.stroke(); ctx.setLineDash([]);
    const t = pv.path[pv.path.length - 1];
    ctx.strokeStyle = "#7a3db8"; ctx.beginPath(); ctx.arc(X(t), Y(t), 6, 0, 2 * Math.PI); ctx.stroke();
    ctx.fillStyle = "#7a3db8";
    const right = X(t) > W - 60;                               // keep the label inside the view
    ctx.textAlign = right ? "right" : "left"; ctx.fillText("target", X(t) + (right ? -8 : 8), Y(t) - 6); ctx.textAlign = "left";
    if (pv.target) frame(pv.target, 16);
  }
  if (tcp) {
    frame(tcp, 20);
    ctx.fillStyle = "#e07b00"; ctx.beginPath(); ctx.arc(X([tcp.X, tcp.Y, tcp.Z]), Y([tcp.X, tcp.Y, tcp.Z]), 4.5, 0, 7); ctx.fill();
  }
  const bar = niceStep((W / scale) / 1.5) / 2;               // scale bar, bottom right
  const bx = W - 10 - bar * scale, by = H - 8;
  ctx.strokeStyle = "#24425f"; ctx.lineWidth = 2; ctx.beginPath();
  ctx.moveTo(bx, by - 4); ctx.lineTo(bx, by); ctx.lineTo(W - 10, by); ctx.lineTo(W - 10, by - 4); ctx.stroke();
  ctx.fillStyle = "#24425f"; ctx.textAlign = "right"; ctx.fillText(`${bar} mm`, W - 10, by - 6); ctx.textAlign = "left";
  ctx.fillStyle = "#44505c"; ctx.font = "11px sans-serif";
  ctx.fillText(`${title}  (${h} →, ${v} ↑)`, 6, 12);
}

/* the view in `container`; `preview()` (optional) returns {path: [[x,y,z]...], target: pose, frame: pose, note} */
function robotView(container, preview) {
  container.classList.add("robotview");
  container.innerHTML = `<div class="views"><canvas id="view-top"></canvas><canvas id="view-side"></canvas></div>
    <div class="viewfoot"><span class="pos" id="tcp-pos">X — Y — Z —</span><span class="note" id="view-note"></span></div>`;
  const redraw = () => {
    VIEW.preview = preview ? preview() : null;
    const p = live.values.ReadPos_Valid && live.values.ReadPos_Position ? live.values.ReadPos_Position.TCP : null;
    drawProjection(document.getElementById("view-top"), "X", "Y", "Top view", p);
    drawProjection(document.getElementById("view-side"), "X", "Z", "Side view", p);
    document.getElementById("tcp-pos").textContent = p ?
      `TCP X ${p.X.toFixed(1)}  Y ${p.Y.toFixed(1)}  Z ${p.Z.toFixed(1)}  RX ${p.RX.toFixed(1)}  RY ${p.RY.toFixed(1)}  RZ ${p.RZ.toFixed(1)}` :
      "TCP not valid (robot not connected)";
    document.getElementById("view-note").textContent = (VIEW.preview && VIEW.preview.note) || "";
  };
  live.listeners.push(redraw);
  live.listeners.push(fetchTrail);
  return redraw;
}

/* new trail points from the server, every 4th poll */
let trailBusy = false;
async function fetchTrail() {
  if (trailBusy || live.polls % 4) return;
  trailBusy = true;
  try {
    const data = await api(`/api/trail?since=${VIEW.next}`);
    VIEW.trail = data.complete ? VIEW.trail.concat(data.points) : data.points;
    if (VIEW.trail.length > 2000) VIEW.trail = VIEW.trail.slice(-2000);
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
    if (!Number.isFinite(v)) return null;
    pose[k] = v;
  }
  return pose;
}
const xyz = (p) => [p.X, p.Y, p.Z];

function motionPreview(key, root, param) {
  if (!["moveabs", "moverel", "movecircle", "changebase"].includes(key)) return null;
  const ctx = formContext(root, param);
  const tcp = live.values.ReadPos_Valid && live.values.ReadPos_Position ? live.values.ReadPos_Position.TCP : null;
  const fmt = ctx.DataFormat || "";
  if (key === "changebase") {
    const f = formPose(root, `${param}.Transformation`);
    return f ? { frame: f, note: "X' Y' Z': the new base" } : { note: "" };
  }
  if (fmt.startsWith("J")) return { note: "joint values: no Cartesian preview" };
  if (key === "moveabs") {
    const t = formPose(root, `${param}.TargetPosition`);
    if (!t) return { note: "" };
    return { path: tcp ? [xyz(tcp), xyz(t)] : [xyz(t)], target: t, note: `${ctx.MovementCommand} to the target` };
  }
  if (!tcp) return { note: "preview needs the TCP position" };
  if (key === "moverel") {
    const o = formPose(root, `${param}.TargetPosition`);
    if (!o) return { note: "" };
    const d = fmt.startsWith("T") ? applyRot(rotation(tcp), xyz(o)) : xyz(o);       // tool frame or base
    const t = { X: tcp.X + d[0], Y: tcp.Y + d[1], Z: tcp.Z + d[2], RX: tcp.RX + o.RX, RY: tcp.RY + o.RY, RZ: tcp.RZ + o.RZ };
    return { path: [xyz(tcp), xyz(t)], target: t, note: fmt.startsWith("T") ? "offset in the tool frame" : "offset in the base" };
  }
  if (key === "movecircle") {
    const a = formPose(root, `${param}.ArcPoint`), e = formPose(root, `${param}.EndPoint`);
    if (!a || !e) return { note: "" };
    const arc = arcPoints(xyz(tcp), xyz(a), xyz(e));
    return arc ? { path: arc, target: e, note: "arc through the arc point" } : { note: "the three points are in line: no circle" };
  }
  return null;
}
