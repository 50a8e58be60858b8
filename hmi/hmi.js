/* CBT HMI: one script for every page. A page is described in PAGES; forms are built from the PLC-HMI
   variable table served at /api/mapping, so ranges and enumerations live in one place (hmi/mapping.json).
   The server checks every write again; the checks here only spare the operator a round trip. */
"use strict";

const POLL_MS = 50;            // 20 updates per second (issue: >= 10)
const TRAIL_POINTS = 400;

const LABELS = {
  TargetPosition: "Target Position (mm, °)", ArcPoint: "Arc Point (mm, °)", EndPoint: "End Point (mm, °)",
  Transformation: "Base (mm, °)", TCPOffset: "TCP Offset (mm, °)", MassCenter: "Mass Center (mm, °)",
  MomentOfInertia: "Moment of Inertia (kg·mm²)", RobotPose: "Robot Pose", MovementCommand: "Motion Command",
  DataFormat: "Data Format", AccelTime: "Accel Time", BlendingEnable: "Enable Blending",
  BlendingValue: "Blending", PrecisePositioning: "Enable Precise Point", RobotPoseEnable: "Enable Robot Pose",
  ExitNode: "Exit Listen Node", ArcAngle: "Arc Angle", Command: "Command",
  Module: "I/O Module", Channel: "Output Number", Value: "Output ON", Immediate: "Immediate (not queued)",
  WaitUntilSet: "Done when set", Mode: "Stop Mode",
  Connect_AddressIP: "Robot IP Address", Connect_Dest_PortIP: "Port", Connect_Time_Out: "Timeout",
};

const HOME = { X: 400, Y: 0, Z: 400, RX: 180, RY: 0, RZ: 90 };
const T = (x, y, z, rx = 180, ry = 0, rz = 90) => ({ X: x, Y: y, Z: z, RX: rx, RY: ry, RZ: rz });
const MOTION = { MovementCommand: 1, DataFormat: 1, Speed: 50, AccelTime: 200, BlendingEnable: false,
  BlendingValue: 0, PrecisePositioning: false, RobotPoseEnable: false, ExitNode: false };
const PNP_SEGMENTS = ["Approach pick", "Pick", "Retreat", "Approach place", "Place", "Retreat"];
const PNP_PRESET = [        // same cycle as the initial values in examples/GlobalVariables.st
  { ...MOTION, TargetPosition: T(350, -200, 400), BlendingEnable: true, BlendingValue: 50 },
  { ...MOTION, MovementCommand: 0, DataFormat: 1, Speed: 30, TargetPosition: T(350, -200, 250), PrecisePositioning: true },
  { ...MOTION, MovementCommand: 0, DataFormat: 1, Speed: 30, TargetPosition: T(350, -200, 400) },
  { ...MOTION, TargetPosition: T(350, 200, 400), BlendingEnable: true, BlendingValue: 50 },
  { ...MOTION, MovementCommand: 0, DataFormat: 1, Speed: 30, TargetPosition: T(350, 200, 250), PrecisePositioning: true },
  { ...MOTION, MovementCommand: 0, DataFormat: 1, Speed: 30, TargetPosition: T(350, 200, 400) },
];

const PAGES = {
  connect: { title: "Connect", group: "Connect", execLabel: "Connect",
    inputs: ["Connect_AddressIP", "Connect_Dest_PortIP", "Connect_Time_Out"], legend: "Connection Settings",
    presets: { "Preset Values": { Connect_AddressIP: "127.0.0.1", Connect_Dest_PortIP: 5890, Connect_Time_Out: 10 } },
    status: ["Connected", "Busy", "Error", "ErrorID", "ErrorDescrip", "LastConnTime", "LastLostTime", "Reconnecting",
      "RetryCount"] },
  changebase: { title: "Change Base", group: "ChangeBase", param: "ChangeBase_Param", legend: "Base Settings",
    presets: { "Set Default Robot Base": { Transformation: T(0, 0, 0, 0, 0, 0), ExitNode: false } } },
  changetcp: { title: "Change TCP", group: "ChangeTCP", param: "ChangeTCP_Param", legend: "Tool Settings",
    presets: { "Set Null Tool Offset": { TCPOffset: T(0, 0, 0, 0, 0, 0), Weight: 0,
      MomentOfInertia: { Ixx: 0, Iyy: 0, Izz: 0 }, MassCenter: T(0, 0, 0, 0, 0, 0), ExitNode: false } } },
  moverel: { title: "Move Relative", group: "MoveRel", param: "MoveRel_Param",
    presets: { "Preset Values": { ...MOTION, MovementCommand: 0, DataFormat: 1, Speed: 20,
      TargetPosition: T(0, 0, 0, 0, 0, 0) } } },
  moveabs: { title: "Move Absolute", group: "MoveAbs", param: "MoveAbs_Param",
    presets: { "Preset Values": { ...MOTION, TargetPosition: { ...HOME },
      RobotPose: { Pose1: 0, Pose2: 0, Pose3: 0 } } } },
  movecircle: { title: "Move Circle", group: "MoveCircle", param: "MoveCircle_Param",
    presets: { "Preset Values": { DataFormat: 0, ArcPoint: T(450, 50, 400), EndPoint: T(400, 100, 400),
      Speed: 30, AccelTime: 200, BlendingEnable: false, BlendingValue: 0, ArcAngle: 0,
      PrecisePositioning: false, ExitNode: false } } },
  setoutput: { title: "Digital Output", group: "SetOutput", param: "SetOutput_Param", legend: "Output Settings",
    presets: { "Close Gripper (End Module DO0)": { Module: 1, Channel: 0, Value: true, Immediate: false,
      WaitUntilSet: true, ExitNode: false },
      "Open Gripper (End Module DO0)": { Module: 1, Channel: 0, Value: false, Immediate: false,
      WaitUntilSet: true, ExitNode: false } } },
  stop: { title: "Stop Motion", group: "Stop", param: "Stop_Param", legend: "Stop Settings", execLabel: "Stop",
    release: true,           // a push button: Execute is reset once the stop is done, which releases the robot
    presets: { "Stop Immediately": { Mode: 1 }, "Stop and Discard All": { Mode: 3 } } },
};
const DEFAULT_STATUS = ["Busy", "Done", "CommandAborted", "Error", "ErrorID", "ErrorDescrip", "CmdID_Ack"];
const BAD = new Set(["Error"]), BUSY = new Set(["Busy", "CommandAborted"]);

let MAP = null;
const live = { values: {}, online: false, trail: [], listeners: [], kick: null, polls: 0 };

/* ---------- server access ---------- */
/* The access key comes in the address printed at start-up (…/#key=…): kept for this browser tab only and
   removed from the address bar so it is not bookmarked or shared by accident. Without a key the HMI is a
   read-only monitor; the server checks every write again (docs/hmi.md, Access control). */
const ACCESS = { key: "", role: "monitor" };
function takeAccessKey() {
  const match = /(?:^#|&)key=([A-Za-z0-9_-]+)/.exec(location.hash);
  if (match) {
    sessionStorage.setItem("hmi-key", match[1]);
    history.replaceState(null, "", location.pathname + location.search);
  }
  ACCESS.key = sessionStorage.getItem("hmi-key") || "";
}
const ROLE_RANK = { monitor: 0, operator: 1, engineer: 2 };
function mayWrite(path) {
  const spec = MAP.variables[path.split(/[.[]/)[0]];
  return Boolean(spec) && ROLE_RANK[ACCESS.role] >= ROLE_RANK[spec.role || "operator"];
}

async function api(path, body) {
  const headers = ACCESS.key ? { "X-HMI-Key": ACCESS.key } : {};
  const options = body === undefined ? { headers } :
    { method: "POST", headers: { ...headers, "Content-Type": "application/json" }, body: JSON.stringify(body) };
  let response;
  try { response = await fetch(path, options); }
  catch (e) { throw new Error("No answer from the PLC web server: check that the demo is running"); }
  const data = await response.json().catch(() => ({ ok: false, error: `HTTP ${response.status}` }));
  if (!data.ok) throw new Error(data.error || `HTTP ${response.status}`);
  return data;
}
const readVars = (names) => api("/api/read?names=" + names.map(encodeURIComponent).join(","));

function message(text, kind = "") {
  const el = document.getElementById("message");
  el.textContent = text;
  el.className = kind;
}

/* ---------- the variable table ---------- */
function typeDef(name) { return MAP.types[name]; }

function leafSpec(path) {
  const rootName = path.split(/[.[]/)[0];
  let spec = MAP.variables[rootName];
  if (!spec) return null;
  const rest = path.slice(rootName.length).replace(/^\[\d+\]/, "");
  for (const part of rest.split(".").filter(Boolean)) {
    const def = typeDef(spec.type);
    if (!def || !def.fields || !def.fields[part]) return null;
    spec = def.fields[part];
  }
  return spec;
}

function rangeText(spec) {
  if (spec.min === undefined) return spec.unit || "";
  return `${spec.min}..${spec.max}${spec.unit ? " " + spec.unit : ""}`;
}

/* returns [value, null] or [null, error text] */
function checkValue(path, spec, raw, context) {
  const def = typeDef(spec.type);
  const name = LABELS[path.split(".").pop()] || path.split(".").pop();
  if (def && def.enum) return [Number(raw), null];
  if (spec.type === "BOOL") return [Boolean(raw), null];
  if (spec.type.startsWith("STRING")) {
    if (spec.pattern === "ipv4" && !/^(25[0-5]|2[0-4]\d|1?\d?\d)(\.(25[0-5]|2[0-4]\d|1?\d?\d)){3}$/.test(raw))
      return [null, `${name}: '${raw}' is not an IPv4 address such as 192.168.1.10`];
    if (spec.maxlen && raw.length > spec.maxlen) return [null, `${name}: at most ${spec.maxlen} characters`];
    return [raw, null];
  }
  const text = String(raw).trim();
  const isReal = spec.type === "REAL" || spec.type === "LREAL";
  if (text === "" || !(isReal ? /^[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$/ : /^[-+]?\d+$/).test(text))
    return [null, `${name}: enter ${isReal ? "a number" : "a whole number"}`];
  const value = Number(text);
  let max = spec.max;
  const fmt = context && context.DataFormat;          // e.g. "CAR_Abs": 2nd letter speed, 3rd blending unit
  if (fmt && path.endsWith(".Speed") && fmt[1] === "P") max = Math.min(max, 100);
  if (fmt && path.endsWith(".BlendingValue") && fmt[2] === "P") max = Math.min(max, 100);
  if ((spec.min !== undefined && value < spec.min) || (max !== undefined && value > max))
    return [null, `${name}: ${value} is out of range ${spec.min}..${max}${spec.unit ? " " + spec.unit : ""}`];
  return [value, null];
}

/* ---------- form building ---------- */
function makeField(path, spec, label) {
  const def = typeDef(spec.type);
  const box = document.createElement("div");
  box.className = "field";
  const id = "f_" + path.replace(/[^A-Za-z0-9]/g, "_");
  let input;
  if (spec.type === "BOOL") {
    box.classList.add("check");
    input = document.createElement("input");
    input.type = "checkbox";
  } else if (def && def.enum) {
    input = document.createElement("select");
    for (const [k, v] of Object.entries(def.enum)) input.add(new Option(k, v));
  } else {
    input = document.createElement("input");
    input.type = "text";
    if (!spec.type.startsWith("STRING")) {
      input.inputMode = "decimal";
      if (spec.min !== undefined) { input.dataset.min = spec.min; input.dataset.max = spec.max; }
    }
  }
  input.id = id;
  input.dataset.path = path;
  if (!mayWrite(path)) { input.disabled = true; box.title = ACCESS.role === "monitor" ?
    "Monitor mode: open the operator address printed at start-up to operate" : "Engineering setting (engineer access)"; }
  const lab = document.createElement("label");
  lab.htmlFor = id;
  lab.textContent = label;
  if (spec.type === "BOOL") { box.append(input, lab); return box; }
  box.append(lab, input);
  const hint = rangeText(spec);
  if (hint) { const h = document.createElement("span"); h.className = "hint"; h.textContent = hint; box.append(h); }
  return box;
}

/* builds fieldsets for a struct variable (or array element) rooted at `path` */
function buildStruct(container, path, typeName, legendText) {
  const def = typeDef(typeName);
  const scalars = [];
  for (const [field, spec] of Object.entries(def.fields)) {
    const fdef = typeDef(spec.type);
    if (fdef && fdef.fields) {
      const fs = document.createElement("fieldset");
      fs.innerHTML = `<legend>${LABELS[field] || field}</legend>`;
      const grid = document.createElement("div");
      grid.className = "grid six";
      for (const [sub, subSpec] of Object.entries(fdef.fields))
        grid.append(makeField(`${path}.${field}.${sub}`, subSpec, sub));
      fs.append(grid);
      container.append(fs);
    } else {
      scalars.push([field, spec]);
    }
  }
  if (scalars.length) {
    const fs = document.createElement("fieldset");
    fs.innerHTML = `<legend>${legendText}</legend>`;
    const grid = document.createElement("div");
    grid.className = "grid wide";
    for (const [field, spec] of scalars) grid.append(makeField(`${path}.${field}`, spec, LABELS[field] || field));
    fs.append(grid);
    container.prepend(fs);
  }
}

function inputsUnder(root, prefix) {
  if (!prefix) return [...root.querySelectorAll("[data-path]")];
  return [...root.querySelectorAll("[data-path]")].filter(
    (el) => el.dataset.path === prefix || el.dataset.path.startsWith(prefix + "."));
}

function setInput(el, value) {
  if (value === undefined || value === null) return;
  if (el.type === "checkbox") el.checked = Boolean(value);
  else if (el.tagName === "SELECT") {
    const def = typeDef(leafSpec(el.dataset.path).type);
    el.value = typeof value === "string" && def.enum[value] !== undefined ? def.enum[value] : value;
  } else el.value = typeof value === "number" ? String(Math.round(value * 1000) / 1000) : value;
  el.classList.remove("invalid");
}

function pick(obj, rel) {
  return rel.split(".").filter(Boolean).reduce((o, k) => (o == null ? undefined : o[k]), obj);
}

/* fill every input under `prefix` from a nested value object */
function fillFrom(root, prefix, valueObj) {
  for (const el of inputsUnder(root, prefix)) setInput(el, pick(valueObj, el.dataset.path.slice(prefix.length)));
}

/* collect + check the inputs under `prefix`; returns {values} or {error} */
function collect(root, prefix) {
  const els = inputsUnder(root, prefix);
  const context = {};
  for (const el of els)
    if (el.dataset.path.endsWith(".DataFormat")) context.DataFormat = el.options[el.selectedIndex].text;
  const values = {};
  let first = null;
  for (const el of els) {
    if (el.disabled) continue;                       // a setting this role may not change is not sent
    const raw = el.type === "checkbox" ? el.checked : el.value;
    const [value, error] = checkValue(el.dataset.path, leafSpec(el.dataset.path), raw, context);
    el.classList.toggle("invalid", Boolean(error));
    if (error && !first) first = error;
    if (!error) values[el.dataset.path] = value;
  }
  return first ? { error: first } : { values };
}

/* ---------- status area ---------- */
function statusTable(title, rows) {
  const div = document.createElement("div");
  div.className = "status";
  div.innerHTML = `<h2>${title}</h2>`;
  const table = document.createElement("table");
  for (const [label, varName] of rows) {
    const spec = MAP.variables[varName];
    const tr = table.insertRow();
    tr.insertCell().textContent = label;
    const cell = tr.insertCell();
    cell.dataset.status = varName;
    if (spec.type === "BOOL") {
      const led = document.createElement("span");
      led.className = "led" + (BAD.has(label) ? " bad" : BUSY.has(label) ? " busy" : "");
      cell.append(led);
    } else cell.className = "text";
  }
  div.append(table);
  return div;
}

function showStatus() {
  for (const cell of document.querySelectorAll("[data-status]")) {
    const v = live.values[cell.dataset.status];
    const led = cell.querySelector(".led");
    if (led) { led.classList.toggle("on", v === true); cell.dataset.value = String(v === true); continue; }
    let text = v === undefined || v === null ? "" : String(v);
    if (cell.dataset.status === "PnP_Segment" && typeof v === "number" && PNP_SEGMENTS[v])
      text = `${v + 1} ${PNP_SEGMENTS[v]}`;            // the drawing numbers segments from 1
    if (cell.dataset.status.endsWith("ErrorID") && typeof v === "number")
      text = "16#" + v.toString(16).toUpperCase().padStart(4, "0");
    if (cell.textContent !== text) cell.textContent = text;
  }
}

/* ---------- polling ---------- */
function startPolling(names) {
  names = [...new Set([...names, ...alarmVariables()].filter((n) => MAP.variables[n]))];
  const pillPlc = document.getElementById("pill-plc"), pillRobot = document.getElementById("pill-robot");
  async function tick() {
    try {
      const data = await readVars(names);
      Object.assign(live.values, data.values);
      live.polls += 1;
      live.online = true;
      const p = live.values.ReadPos_Position && live.values.ReadPos_Position.TCP;
      if (live.values.ReadPos_Valid && p) {
        const last = live.trail[live.trail.length - 1];
        if (!last || Math.abs(last.X - p.X) + Math.abs(last.Y - p.Y) + Math.abs(last.Z - p.Z) > 0.2) {
          live.trail.push({ X: p.X, Y: p.Y, Z: p.Z });
          if (live.trail.length > TRAIL_POINTS) live.trail.shift();
        }
      }
    } catch (e) { live.online = false; }
    pillPlc.textContent = live.online ? "PLC online" : "PLC offline";
    pillPlc.className = "pill " + (live.online ? "on" : "off");
    const connected = live.values.Connect_Connected === true;
    pillRobot.textContent = connected ? "Robot connected" : "Robot not connected";
    pillRobot.className = "pill " + (connected ? "on" : "off");
    showStatus();
    checkAlarms();
    for (const f of live.listeners) f();
    const timer = setTimeout(next, POLL_MS);
    live.kick = () => { clearTimeout(timer); next(); };   // poll at once after a command was sent
  }
  function next() { live.kick = null; tick(); }
  tick();
}

/* ---------- live robot view (top X-Y and side X-Z) ---------- */
function drawView(canvas, h, v, title) {
  const rect = canvas.getBoundingClientRect();
  canvas.width = Math.max(50, rect.width); canvas.height = Math.max(50, rect.height);
  const ctx = canvas.getContext("2d"), W = canvas.width, H = canvas.height;
  ctx.clearRect(0, 0, W, H);
  const pts = live.trail;
  let lo = { h: -100, v: -100 }, hi = { h: 600, v: 600 };
  for (const p of pts) { lo = { h: Math.min(lo.h, p[h]), v: Math.min(lo.v, p[v]) }; hi = { h: Math.max(hi.h, p[h]), v: Math.max(hi.v, p[v]) }; }
  const scale = Math.min((W - 30) / (hi.h - lo.h), (H - 24) / (hi.v - lo.v));
  const X = (x) => 22 + (x - lo.h) * scale, Y = (y) => H - 14 - (y - lo.v) * scale;
  ctx.strokeStyle = "#c9d1d9"; ctx.lineWidth = 1;
  ctx.beginPath(); ctx.moveTo(X(0), 0); ctx.lineTo(X(0), H); ctx.moveTo(0, Y(0)); ctx.lineTo(W, Y(0)); ctx.stroke();
  ctx.fillStyle = "#44505c"; ctx.font = "11px sans-serif";
  ctx.fillText(`${title}  (${h} → , ${v} ↑, mm)`, 4, 12);
  if (!pts.length) { ctx.fillText("no position yet: connect the robot", 4, 28); return; }
  ctx.strokeStyle = "#2e9b4f"; ctx.lineWidth = 2; ctx.beginPath();
  pts.forEach((p, i) => (i ? ctx.lineTo(X(p[h]), Y(p[v])) : ctx.moveTo(X(p[h]), Y(p[v]))));
  ctx.stroke();
  const last = pts[pts.length - 1];
  ctx.fillStyle = "#e07b00"; ctx.beginPath(); ctx.arc(X(last[h]), Y(last[v]), 5, 0, 7); ctx.fill();
}

function robotView(container) {
  container.innerHTML = `<h2>Live robot view: TCP path from CBT_ReadActualPosition</h2>
    <div class="views"><canvas id="view-top"></canvas><canvas id="view-side"></canvas></div>
    <div class="pos" id="tcp-pos">X — Y — Z —</div>
    <div class="robot-status">
      <span>In Listen node <span data-status="Robot_InListenNode"><span class="led"></span></span></span>
      <span>Stopping <span data-status="Robot_Stopping"><span class="led busy"></span></span></span>
      <span>Queue <b data-status="Robot_QueueDepth"></b></span>
      <span>Last ErrorID <b data-status="Robot_LastErrorID"></b></span></div>`;
  live.listeners.push(() => {
    drawView(document.getElementById("view-top"), "X", "Y", "Top view");
    drawView(document.getElementById("view-side"), "X", "Z", "Side view");
    const p = live.values.ReadPos_Position && live.values.ReadPos_Position.TCP;
    document.getElementById("tcp-pos").textContent = live.values.ReadPos_Valid && p ?
      `X ${p.X.toFixed(1)}  Y ${p.Y.toFixed(1)}  Z ${p.Z.toFixed(1)}  RX ${p.RX.toFixed(1)}  RY ${p.RY.toFixed(1)}  RZ ${p.RZ.toFixed(1)}` :
      "position not valid (robot not connected)";
  });
}

/* ---------- page frame ---------- */
function frame(title, isMain) {
  document.title = "CBT HMI – " + title;
  document.body.innerHTML = `<div class="panel">
    <header>${isMain ? "" : '<a class="menu" id="btn-menu" href="index.html">◀ Main Menu</a>'}
      <h1>${title}</h1><span class="pill ${ACCESS.role === "monitor" ? "off" : "on"}" id="pill-role">${ACCESS.role[0].toUpperCase() + ACCESS.role.slice(1)}</span><span class="pill" id="pill-robot">Robot …</span><span class="pill" id="pill-plc">PLC …</span></header>
    <main id="main"></main><div id="message">${ACCESS.role === "monitor" ?
      "Monitor mode (read only): open the operator address printed at start-up to operate." : "Ready."}</div></div>`;
  alarmBanner(document.querySelector(".panel"));
  return document.getElementById("main");
}

function mainPage() {
  const main = frame("CBT Commands – Main", true);
  main.innerHTML = `<div class="areas">
    <div class="area"><h2>Configuration</h2><div class="tiles">
      <a href="connect.html" id="nav-connect">Connect</a><a href="changebase.html" id="nav-changebase">Change Base</a>
      <a href="changetcp.html" id="nav-changetcp">Change TCP</a><a href="setoutput.html" id="nav-setoutput">Digital Output</a></div></div>
    <div class="area"><h2>Motion</h2><div class="tiles">
      <a href="moverel.html" id="nav-moverel">Move Relative</a><a href="moveabs.html" id="nav-moveabs">Move Absolute</a>
      <a href="movecircle.html" id="nav-movecircle">Move Circle</a><a href="pnp.html" id="nav-pnp">PnP Sequence</a>
      <a href="stop.html" id="nav-stop" class="stop">Stop Motion</a></div></div>
    </div><div class="robotview" id="robotview"></div>`;
  robotView(document.getElementById("robotview"));
  robotTile(document.getElementById("robotview"));
  document.querySelector("header h1").insertAdjacentHTML("afterend",
    '<a class="menu" id="nav-program" href="program.html">Program (Ladder)</a>');
  startPolling(["Connect_Connected", "ReadPos_Valid", "ReadPos_Position", "Robot_InListenNode", "Robot_QueueDepth",
    "Robot_Stopping", "Robot_LastErrorID"]);
}

async function executeCommand(execVar, values, what) {
  message(`Sending ${what} …`);
  try {
    await api("/api/execute", { execute: execVar, values });
    if (live.kick) live.kick();
    message(`${what}: sent, waiting for the function block's answer …`);
    return true;
  } catch (e) { message(`${what}: ${e.message}`, "error"); return false; }
}

/* Push-button commands (CBT_Stop): reset Execute once Done or Error shows, within 10 s. */
function releaseWhenFinished(group, what) {
  const deadline = Date.now() + 10000, firstPoll = live.polls + 2;   // values read after the command was sent
  const check = async () => {
    const v = live.values;
    const finished = live.polls >= firstPoll && (v[`${group}_Done`] === true || v[`${group}_Error`] === true);
    if (!finished && Date.now() < deadline) { setTimeout(check, POLL_MS); return; }
    try {
      await api("/api/write", { values: { [`${group}_Execute`]: false } });
      if (finished && v[`${group}_Error`] === true)
        message(`${what}: Error ${idText(v[`${group}_ErrorID`])} – ${v[`${group}_ErrorDescrip`] || ""}; Execute reset.`, "error");
      else if (finished) message(`${what}: done, Execute reset.`, "ok");
      else message(`${what}: no answer within 10 s; Execute reset.`, "error");
    } catch (e) { message(`${what}: cannot reset Execute: ${e.message}`, "error"); }
  };
  setTimeout(check, POLL_MS);
}

async function fbPage(key) {
  const page = PAGES[key], group = page.group;
  const main = frame(page.title, false);
  const params = document.createElement("div");
  params.className = "params";
  if (page.param) {
    buildStruct(params, page.param, MAP.variables[page.param].type, page.legend || "Motion Settings");
  } else {
    const fs = document.createElement("fieldset");
    fs.innerHTML = `<legend>${page.legend}</legend>`;
    const grid = document.createElement("div");
    grid.className = "grid wide";
    for (const v of page.inputs) grid.append(makeField(v, MAP.variables[v], LABELS[v] || v));
    fs.append(grid);
    params.append(fs);
  }
  const side = document.createElement("div");
  side.className = "side";
  const buttons = document.createElement("div");
  buttons.className = "buttons";
  Object.keys(page.presets).forEach((name, i) => {
    const b = document.createElement("button");
    b.className = "wide"; b.id = i ? `btn-preset-${i + 1}` : "btn-preset"; b.textContent = name;
    b.onclick = () => {
      if (page.param) fillFrom(params, page.param, page.presets[name]);
      else for (const [v, val] of Object.entries(page.presets[name])) setInput(params.querySelector(`[data-path="${v}"]`), val);
      message(`${name}: fields filled, press ${page.execLabel || "Execute"} to send.`);
    };
    buttons.append(b);
  });
  const exec = document.createElement("button");
  exec.className = (key === "stop" ? "danger" : "primary") + (key === "connect" ? "" : " wide");
  exec.id = "btn-execute"; exec.textContent = page.execLabel || "Execute";
  exec.disabled = !mayWrite(`${group}_Execute`);
  exec.onclick = () => {
    const result = collect(params, page.param || "");
    if (result.error) { message(result.error + " — nothing was sent.", "error"); return; }
    executeCommand(`${group}_Execute`, result.values, page.title).then((sent) => {
      if (sent && page.release) releaseWhenFinished(group, page.title);
      else if (sent) watchResult(group, page.title);
    });
  };
  buttons.append(exec);
  if (key === "connect") {
    const off = document.createElement("button");
    off.className = "danger"; off.id = "btn-disconnect"; off.textContent = "Disconnect";
    off.onclick = async () => {
      try { await api("/api/write", { values: { Connect_Execute: false } }); message("Disconnect: Execute reset.", "ok"); }
      catch (e) { message("Disconnect: " + e.message, "error"); }
    };
    buttons.append(off);
  }
  const statusNames = page.status || DEFAULT_STATUS;
  side.append(buttons, statusTable("Command Status", statusNames.map((s) => [s, `${group}_${s}`])));
  main.append(params, side);
  const toRead = page.param ? [page.param] : page.inputs;
  try {
    const data = await readVars(toRead);
    if (page.param) fillFrom(params, page.param, data.values[page.param]);
    else for (const v of page.inputs) setInput(params.querySelector(`[data-path="${v}"]`), data.values[v]);
  } catch (e) { message("Cannot read the current parameters: " + e.message, "error"); }
  startPolling([...statusNames.map((s) => `${group}_${s}`), "Connect_Connected"]);
}

function buildPnP() {
  const main = frame("PnP Sequence", false);
  main.innerHTML = `<div class="pnpdraw"><svg id="pnp-svg" viewBox="0 0 520 330" preserveAspectRatio="xMidYMid meet"></svg>
      <div class="pos" id="pnp-note">Side view (X/Y → , Z ↑). Orange: segment in progress. Green: live TCP.</div></div>
    <div class="side"><div class="buttons">
      <button class="wide" id="btn-preset">Preset Values</button>
      <button class="primary" id="btn-execute">Execute</button><button class="danger" id="btn-stop">Stop</button>
      <button class="warn" id="btn-pause">Pause</button><button id="btn-resume">Resume</button></div>
    <div id="pnp-status"></div></div>
    <dialog id="seg-dialog"><header><h1 id="seg-title">Segment</h1></header><div class="body" id="seg-body"></div>
      <div class="actions"><button id="seg-cancel">Cancel</button><button class="primary" id="seg-apply">Apply</button></div></dialog>`;
  const statusBox = document.getElementById("pnp-status");
  statusBox.append(statusTable("Cycle Status", [["Execute", "PnP_Example_Execute"], ["Segment", "PnP_Segment"],
    ["Waiting", "PnP_Waiting"], ["Gripper closed", "PnP_GripperClosed"], ["Cycles", "PnP_CycleCount"],
    ["Busy", "PnP_MoveBusy"], ["Error", "PnP_MoveError"], ["ErrorID", "PnP_MoveErrorID"], ["ErrorDescrip", "PnP_MoveErrorDescrip"],
    ["CmdID_Ack", "PnP_Move_CmdID_Ack"]]));
  statusBox.append(statusTable("Program Control", [["Busy", "ProgramControl_Busy"], ["Done", "ProgramControl_Done"],
    ["Error", "ProgramControl_Error"], ["ErrorDescrip", "ProgramControl_ErrorDescrip"]]));
  statusBox.style.cssText = "display:flex;flex-direction:column;gap:4px;flex:1;min-height:0";
  return main;
}

let pnpParams = null;

let pnpGeometry = null;

/* static part: the six segments and their Edit buttons, rebuilt only when the parameters change so a tap
   on an Edit button never lands on an element that a status update has just replaced */
function drawPnP() {
  const svg = document.getElementById("pnp-svg");
  if (!pnpParams) return;
  const pts = pnpParams.map((p) => p.TargetPosition);
  const alongY = Math.abs(pts[3].Y - pts[0].Y) >= Math.abs(pts[3].X - pts[0].X);
  const horiz = (p) => (alongY ? p.Y : p.X);
  let h0 = Math.min(...pts.map(horiz)), h1 = Math.max(...pts.map(horiz));
  let v0 = Math.min(...pts.map((p) => p.Z)), v1 = Math.max(...pts.map((p) => p.Z));
  if (h1 - h0 < 50) { h0 -= 50; h1 += 50; }
  if (v1 - v0 < 50) { v0 -= 25; v1 += 25; }
  const s = Math.min(300 / (h1 - h0), 200 / (v1 - v0));
  const X = (p) => 110 + (horiz(p) - h0) * s + (300 - (h1 - h0) * s) / 2;
  const Y = (p) => 290 - (p.Z - v0) * s;
  pnpGeometry = { X, Y };
  let out = `<defs><marker id="arrow" viewBox="0 0 10 10" refX="9" refY="5" markerWidth="6" markerHeight="6" orient="auto-start-reverse">
    <path d="M0,0 L10,5 L0,10 z" fill="#2368a8"/></marker>
    <clipPath id="pnp-clip"><rect x="0" y="0" width="520" height="300"/></clipPath></defs>`;
  for (let i = 0; i < 6; i++) {
    const a = pts[(i + 5) % 6], b = pts[i];
    const [x1, y1, x2, y2] = [X(a), Y(a), X(b), Y(b)];
    let mx = (x1 + x2) / 2, my = (y1 + y2) / 2, d;
    const vertical = Math.abs(x1 - x2) < 8;
    const shift = vertical ? (i === 1 || i === 4 ? -5 : 5) : 0;   // down and up side by side, not on top
    if (vertical) d = `M${x1 + shift},${y1} L${x2 + shift},${y2}`;
    else if (i === 0) {            // return travel: drawn as an arc above the approach so the two do not overlap
      const cy = Math.min(y1, y2) - 70;
      d = `M${x1},${y1} Q${mx},${cy} ${x2},${y2}`; my = (y1 + y2) / 4 + cy / 2;
    } else d = `M${x1},${y1} L${x2},${y2}`;
    if (vertical) mx += i === 1 || i === 4 ? -46 : 46;
    else my += 16;
    out += `<path class="seg" id="seg-${i}" d="${d}"/>`;
    out += `<g class="edit" id="edit-${i}" data-seg="${i}"><rect x="${mx - 40}" y="${my - 11}" width="80" height="22"/>
      <text x="${mx}" y="${my + 4}" text-anchor="middle">${i + 1} Edit</text></g>`;
  }
  pts.forEach((p) => { out += `<circle class="pt" cx="${X(p)}" cy="${Y(p)}" r="4"/>`; });
  out += `<polyline class="trail" id="pnp-trail" points="" clip-path="url(#pnp-clip)"/>
    <circle class="tcp" id="pnp-tcp" r="6" cx="-20" cy="-20"/>`;
  out += `<text x="10" y="318" font-size="11" fill="#44505c">1 ${PNP_SEGMENTS[0]} · 2 ${PNP_SEGMENTS[1]} · 3 ${PNP_SEGMENTS[2]} · 4 ${PNP_SEGMENTS[3]} · 5 ${PNP_SEGMENTS[4]} · 6 ${PNP_SEGMENTS[5]}</text>`;
  svg.innerHTML = out;
  for (const g of svg.querySelectorAll(".edit")) g.onclick = () => openSegment(Number(g.dataset.seg));
  updatePnP();
}

/* dynamic part: segment in progress and live TCP trail, updated in place at every poll */
function updatePnP() {
  if (!pnpGeometry) return;
  const { X, Y } = pnpGeometry;
  const active = live.values.PnP_Example_Execute || live.values.PnP_MoveBusy ? live.values.PnP_Segment : -1;
  for (let i = 0; i < 6; i++) document.getElementById(`seg-${i}`).classList.toggle("active", i === active);
  document.getElementById("pnp-trail").setAttribute("points", live.trail.map((p) => `${X(p)},${Y(p)}`).join(" "));
  const last = live.trail[live.trail.length - 1];
  if (last) {
    const dot = document.getElementById("pnp-tcp");
    dot.setAttribute("cx", X(last)); dot.setAttribute("cy", Y(last));
  }
}

function openSegment(i) {
  const dialog = document.getElementById("seg-dialog"), body = document.getElementById("seg-body");
  const root = `PnP_MoveParameters[${i}]`;
  body.innerHTML = "";
  buildStruct(body, root, MAP.variables.PnP_MoveParameters.type, "Motion Settings");
  fillFrom(body, root, pnpParams[i]);
  document.getElementById("seg-title").textContent = `Segment ${i + 1}: ${PNP_SEGMENTS[i]} – CBT_MoveAbsolute parameters`;
  document.getElementById("seg-cancel").onclick = () => dialog.close();
  document.getElementById("seg-apply").onclick = async () => {
    const result = collect(body, root);
    if (result.error) { message(result.error + " — nothing was sent.", "error"); return; }
    try {
      await api("/api/write", { values: result.values });
      await loadPnP();
      dialog.close();
      message(`Segment ${i + 1} updated in the PLC.`, "ok");
    } catch (e) { message(`Segment ${i + 1}: ${e.message}`, "error"); }
  };
  dialog.showModal();
}

async function loadPnP() {
  const data = await readVars(["PnP_MoveParameters"]);
  pnpParams = data.values.PnP_MoveParameters;
  drawPnP();
}

async function pnpPage() {
  buildPnP();
  const flatPreset = {};
  PNP_PRESET.forEach((seg, i) => {
    const walk = (obj, prefix) => {
      for (const [k, v] of Object.entries(obj)) {
        if (v !== null && typeof v === "object") walk(v, `${prefix}.${k}`);
        else if (leafSpec(`${prefix}.${k}`)) flatPreset[`${prefix}.${k}`] = v;
      }
    };
    walk(seg, `PnP_MoveParameters[${i}]`);
  });
  document.getElementById("btn-preset").onclick = async () => {
    try { await api("/api/write", { values: flatPreset }); await loadPnP(); message("Preset PnP cycle written to the PLC.", "ok"); }
    catch (e) { message("Preset Values: " + e.message, "error"); }
  };
  const setRun = async (on) => {
    try {
      await api("/api/write", { values: { PnP_Example_Execute: on } });
      message(on ? "PnP cycle started: it repeats while Execute stays on." : "PnP stop requested: the cycle ends after the current move.", "ok");
    } catch (e) { message("PnP: " + e.message, "error"); }
  };
  document.getElementById("btn-execute").onclick = () => setRun(true);
  document.getElementById("btn-stop").onclick = () => setRun(false);
  const control = (cmd, what) => executeCommand("ProgramControl_Execute", { "ProgramControl_Param.Command": cmd }, what);
  document.getElementById("btn-pause").onclick = () => control(MAP.types.eCBT_PrgControlCmd.enum.Pause, "Pause");
  document.getElementById("btn-resume").onclick = () => control(MAP.types.eCBT_PrgControlCmd.enum.Resume, "Resume");
  live.listeners.push(updatePnP);
  try { await loadPnP(); } catch (e) { message("Cannot read the PnP parameters: " + e.message, "error"); }
  startPolling(["PnP_Example_Execute", "PnP_Segment", "PnP_Waiting", "PnP_GripperClosed", "PnP_CycleCount", "PnP_MoveBusy",
    "PnP_MoveError", "PnP_MoveErrorID", "PnP_MoveErrorDescrip", "PnP_Move_CmdID_Ack",
    "ProgramControl_Busy", "ProgramControl_Done", "ProgramControl_Error", "ProgramControl_ErrorDescrip",
    "Connect_Connected", "ReadPos_Valid", "ReadPos_Position"]);
}

async function boot() {
  // One page shell (index.html) serves every page: the file name in the address names the page.
  const file = decodeURIComponent(location.pathname.split("/").pop() || "index.html");
  const name = file.replace(/\.html$/, "");
  const key = name === "index" ? "main" : name;
  document.body.dataset.page = key;
  takeAccessKey();
  try {
    MAP = await api("/api/mapping");
    ACCESS.role = (await api("/api/session")).role;
    await loadAlarms();
  } catch (e) {
    frame("CBT HMI", true);
    message("Cannot load the variable table: " + e.message, "error");
    return;
  }
  document.body.dataset.role = ACCESS.role;
  if (key === "main") mainPage();
  else if (key === "pnp") pnpPage();
  else if (key === "program") programPage();
  else fbPage(key);
}

document.addEventListener("DOMContentLoaded", boot);
