/* CBT HMI: one script for every page. A page is described in PAGES; forms are built from the PLC-HMI
   variable table served at /api/mapping, so ranges and enumerations live in one place (src/cbt_hmi/pages/mapping.json).
   The server checks every write again; the checks here only spare the operator a round trip. */
"use strict";

const POLL_MS = 50;            // 20 updates per second (issue: >= 10)

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
  BlendingValue: 0, PrecisePositioning: false, RobotPoseEnable: false };   // ExitNode: engineer only, left as it is
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
  changebase: { title: "Change Base",
    done: () => "the robot accepted the base; it applies to the motions queued after it.", group: "ChangeBase", param: "ChangeBase_Param", legend: "Base Settings",
    presets: { "Set Default Robot Base": { Transformation: T(0, 0, 0, 0, 0, 0), ExitNode: false } } },
  changetcp: { title: "Change TCP", view: false,
    done: () => "the robot accepted the tool; it applies to the motions queued after it.", group: "ChangeTCP", param: "ChangeTCP_Param", legend: "Tool Settings",
    presets: { "Set Null Tool Offset": { TCPOffset: T(0, 0, 0, 0, 0, 0), Weight: 0,
      MomentOfInertia: { Ixx: 0, Iyy: 0, Izz: 0 }, MassCenter: T(0, 0, 0, 0, 0, 0), ExitNode: false } } },
  moverel: { title: "Move Relative",
    done: (c) => (c.BlendingEnable === "TRUE" ? "the robot accepted the motion (blended: the next one may follow)." : "the robot arrived at the target."), group: "MoveRel", param: "MoveRel_Param",
    presets: { "Preset Values": { ...MOTION, MovementCommand: 0, DataFormat: 1, Speed: 20,
      TargetPosition: T(0, 0, 0, 0, 0, 0) } } },
  moveabs: { title: "Move Absolute",
    done: (c) => (c.BlendingEnable === "TRUE" ? "the robot accepted the motion (blended: the next one may follow)." : "the robot arrived at the target."), group: "MoveAbs", param: "MoveAbs_Param",
    presets: { "Preset Values": { ...MOTION, TargetPosition: { ...HOME },
      RobotPose: { Pose1: 0, Pose2: 0, Pose3: 0 } } } },
  movecircle: { title: "Move Circle",
    done: (c) => (c.BlendingEnable === "TRUE" ? "the robot accepted the motion (blended: the next one may follow)." : "the robot arrived at the target."), group: "MoveCircle", param: "MoveCircle_Param",
    presets: { "Preset Values": { DataFormat: 0, ArcPoint: T(450, 50, 400), EndPoint: T(400, 100, 400),
      Speed: 30, AccelTime: 200, BlendingEnable: false, BlendingValue: 0, ArcAngle: 0,
      PrecisePositioning: false, ExitNode: false } } },
  setoutput: { title: "Digital Output",
    done: (c) => (c.WaitUntilSet === "TRUE" && c.Immediate !== "TRUE" ? "the robot switched the output." : "the robot accepted the command."), group: "SetOutput", param: "SetOutput_Param", legend: "Output Settings",
    presets: { "Close Gripper (End Module DO0)": { Module: 1, Channel: 0, Value: true, Immediate: false,
      WaitUntilSet: true, ExitNode: false },
      "Open Gripper (End Module DO0)": { Module: 1, Channel: 0, Value: false, Immediate: false,
      WaitUntilSet: true, ExitNode: false } } },
  stop: { title: "Stop Motion", group: "Stop", param: "Stop_Param", legend: "Stop Settings", execLabel: "Stop",
    release: "the robot stopped and its queue is cleared",   // a push button: Execute is reset once the stop is
                             // done, which releases the robot
    act: true,               // its presets send the stop when pressed (issue 25 item 2)
    presets: { "Stop Immediately": { Mode: 1 }, "Stop and Discard All": { Mode: 3 } } },
};
const DEFAULT_STATUS = ["Busy", "Done", "CommandAborted", "Error", "ErrorID", "ErrorDescrip", "CmdID_Ack"];
const BAD = new Set(["Error"]), BUSY = new Set(["Busy", "CommandAborted"]);

let MAP = null;
/* online: the last read was answered; robot: the server's summary of the robot (connected, Listen node, project);
   clock: the controller's date and time of the last answer; lostAt: when the answers stopped (browser time) */
const live = { values: {}, online: false, fault: null, listeners: [], kick: null, polls: 0, robot: "", clock: "",
  lostAt: 0 };

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
  if (!spec) return false;
  const member = path.split(".").pop();           // ExitNode: engineer only in every structure (server checks too)
  const needed = (MAP.engineering_members || []).includes(member) ? "engineer" : spec.role || "operator";
  return ROLE_RANK[ACCESS.role] >= ROLE_RANK[needed];
}

async function api(path, body, timeoutMs) {
  const headers = ACCESS.key ? { "X-HMI-Key": ACCESS.key } : {};
  const options = body === undefined ? { headers } :
    { method: "POST", headers: { ...headers, "Content-Type": "application/json" }, body: JSON.stringify(body) };
  if (timeoutMs) options.signal = AbortSignal.timeout(timeoutMs);
  let response;
  try { response = await fetch(path, options); }
  catch (e) { throw new Error("No answer from the PLC web server: check that the demo is running"); }
  const data = await response.json().catch(() => ({ ok: false, error: `HTTP ${response.status}` }));
  if (!data.ok) throw new Error(data.error || `HTTP ${response.status}`);
  return data;
}
/* A poll not answered within READ_TIMEOUT_MS counts as "no answer": the values turn invalid within a second. */
const READ_TIMEOUT_MS = 800;
const readVars = (names) => api("/api/read?names=" + names.map(encodeURIComponent).join(","), undefined, READ_TIMEOUT_MS);

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
    const inner = def.fields[part];        // a structure member's range holds for its members (TargetPosition.X)
    spec = spec.min !== undefined && inner.min === undefined ?
      { ...inner, min: spec.min, max: spec.max, ranges: spec.ranges } : inner;
  }
  return spec;
}

/* returns [value, null] or [null, error text] */
function checkValue(path, spec, raw, context) {
  const def = typeDef(spec.type);
  const name = LABELS[path.split(".").pop()] || path.split(".").pop();
  if (def && def.enum) {
    const text = Object.keys(def.enum).find((k) => def.enum[k] === Number(raw));
    const refused = context && refusedCombination(spec, text, context, name);
    return refused ? [null, refused] : [Number(raw), null];
  }
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
  const r = applicableRange(spec, context || {});      // the library's range for the selected format
  if (r && (value < r.min || value > r.max))
    return [null, `${name}: ${value} is out of range ${r.min}..${r.max}${r.unit ? " " + r.unit : ""}` +
      (r.error ? ` (the FB would refuse it with ${r.error})` : "")];
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
    if (Math.max(...Object.keys(def.enum).map((k) => k.length)) > 10) box.classList.add("span2");   // StopDiscardAll
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
  const h = document.createElement("span");          // filled by refreshLimits: follows the selected format
  h.className = "hint";
  h.textContent = spec.ranges || spec.allowed ? "" : rangeHint(spec, {});
  box.append(h);
  return box;
}

/* builds fieldsets for a struct variable (or array element) rooted at `path` */
function buildStruct(container, path, typeName, legendText) {
  const def = typeDef(typeName);
  const scalars = [], checks = [];
  for (const [field, spec] of Object.entries(def.fields)) {
    const fdef = typeDef(spec.type);
    if (fdef && fdef.fields) {                  // a pose: one row of six, the range once in the legend
      const fs = document.createElement("fieldset");
      fs.className = "pose";
      fs.dataset.member = field;
      const range = spec.min === undefined ? "" :
        ` <span class="range">${spec.min === -spec.max ? "±" + spec.max : spec.min + ".." + spec.max}</span>`;
      fs.innerHTML = `<legend>${LABELS[field] || field}${range}</legend>`;
      const grid = document.createElement("div");
      grid.className = "grid six";
      for (const [sub, subSpec] of Object.entries(fdef.fields)) {
        const box = makeField(`${path}.${field}.${sub}`, leafSpec(`${path}.${field}.${sub}`) || subSpec, sub);
        box.querySelector(".hint").remove();
        grid.append(box);
      }
      fs.append(grid);
      container.append(fs);
    } else if (spec.type === "BOOL") checks.push([field, spec]);
    else scalars.push([field, spec]);
  }
  const fs = document.createElement("fieldset");
  fs.innerHTML = `<legend>${legendText}</legend>`;
  const grid = document.createElement("div");
  grid.className = "grid wide";
  for (const [field, spec] of scalars) grid.append(makeField(`${path}.${field}`, spec, LABELS[field] || field));
  const row = document.createElement("div");
  row.className = "checks";
  for (const [field, spec] of checks) row.append(makeField(`${path}.${field}`, spec, LABELS[field] || field));
  if (scalars.length) fs.append(grid);
  if (checks.length) fs.append(row);
  container.prepend(fs);
  const pose = container.querySelector('fieldset[data-member="RobotPose"]');
  const poseOn = container.querySelector(`[data-path="${path}.RobotPoseEnable"]`);
  if (pose && poseOn) {                          // shown only when it is sent (PTP CPP with Enable Robot Pose)
    const show = () => { pose.hidden = !poseOn.checked; };
    poseOn.addEventListener("change", show);
    container.addEventListener("fill", show);
    show();
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
  root.dispatchEvent(new Event("fill"));
}

/* collect + check the inputs under `prefix`; returns {values} or {error} */
function collect(root, prefix) {
  const els = inputsUnder(root, prefix);
  const context = formContext(root, prefix);
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
  if (!first) first = physicalRefusal(root, prefix);   // limits.js: angle and joint ranges, the TM5-700's reach
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

/* Without answers from the PLC no value is shown as if it were valid: texts read ####, lamps go grey
   (data-value "invalid"), and the panel is hatched (style.css, .plc-offline). */
function showStatus() {
  const invalid = !live.online && !live.fault;
  for (const cell of document.querySelectorAll("[data-status]")) {
    if (invalid) {
      if (cell.classList.contains("lamp") || cell.querySelector(".led")) {
        cell.dataset.value = "invalid";
        const led = cell.querySelector(".led");
        if (led) led.classList.remove("on");
      } else if (cell.textContent !== "####") cell.textContent = "####";
      continue;
    }
    const v = live.values[cell.dataset.status];
    if (cell.classList.contains("lamp")) { cell.dataset.value = String(v === true); continue; }
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

/* ---------- PLC state in the header ---------- */
/* After a major fault the PLC stops scanning and closes its sockets; the server stays up and says so
   (docs/hmi.md, "PLC fault"): the header names the fault, the page is greyed out as no longer valid. */
/* The robot pill says the robot's real state, as the server sums it up from CBT_Connect, the Listen-node flag
   and CBT_RobotStatus: grey when it can take commands (connected, in its Listen node, project running), amber or
   red when not. Without answers from the PLC it is unknown. */
const ROBOT_PILL = { ready: ["Robot ready", ""], connected: ["Robot connected", ""],
  "not connected": ["Robot not connected", "warn"], "left the Listen node": ["Robot left Listen node", "alarm"],
  "project stopped": ["Robot project stopped", "warn"], "E-stop": ["Robot E-stop", "alarm"],
  "robot error": ["Robot error", "alarm"], unknown: ["Robot …", ""] };
function showPlcState(pillPlc, pillRobot) {
  const fault = live.fault, lost = !live.online && !fault;
  const what = fault ? (fault.what.length > 40 ? fault.what.slice(0, 39) + "…" : fault.what) : "";
  pillPlc.textContent = fault ? `PLC fault — ${what}` : live.online ? "PLC online" : "PLC offline";
  pillPlc.title = fault ? fault.message : "";
  pillPlc.className = "pill " + (live.online ? "" : "alarm");
  const [text, kind] = fault ? ["Robot link closed", "alarm"] : lost ? ["Robot ####", ""] :
    ROBOT_PILL[live.robot] || ROBOT_PILL.unknown;
  if (pillRobot.textContent !== text) pillRobot.textContent = text;
  pillRobot.className = "pill " + kind;
  const panel = document.querySelector(".panel");
  if (lost !== panel.classList.contains("plc-offline")) {
    panel.classList.toggle("plc-offline", lost);
    message(lost ? "No answer from the PLC: the values shown as #### are not valid; nothing can be sent." :
      "The PLC answers again.", lost ? "error" : "");
  }
  if (Boolean(fault) !== panel.classList.contains("plc-fault")) {
    panel.classList.toggle("plc-fault", Boolean(fault));
    if (fault) message(`PLC major fault: ${fault.message}. The PLC has stopped: the values shown are the last `
      + "ones before the fault and are not valid; nothing can be sent until the PLC is restarted.", "error");
  }
}

/* ---------- polling ---------- */
function startPolling(names) {
  names = [...new Set([...names, ...STOP_VARS].filter((n) => MAP.variables[n]))];   // the Stop key's answer
  const pillPlc = document.getElementById("pill-plc"), pillRobot = document.getElementById("pill-robot");
  async function tick() {
    try {
      const data = await readVars(names);
      Object.assign(live.values, data.values);
      live.polls += 1;
      live.fault = data.plc === "fault" ? data.fault : null;
      live.online = !live.fault;          // after a major fault the values are the last ones, no longer valid
      live.robot = data.robot;
      live.clock = data.clock;
      live.lostAt = 0;
      alarmsAfterRead(data);
    } catch (e) {
      live.online = false; live.fault = null;
      live.lostAt = live.lostAt || Date.now();
      alarmsAfterRead(null);
    }
    showPlcState(pillPlc, pillRobot);
    showStatus();
    for (const f of live.listeners) f();
    const timer = setTimeout(next, POLL_MS);
    live.kick = () => { clearTimeout(timer); next(); };   // poll at once after a command was sent
  }
  function next() { live.kick = null; tick(); }
  tick();
}

/* ---------- page frame ---------- */
function frame(title, isMain) {
  document.title = "CBT HMI – " + title;
  document.body.innerHTML = `<div class="panel">
    <header>${isMain ? "" : '<a class="menu" id="btn-menu" href="index.html">◀ Main Menu</a>'}
      <h1>${title}</h1><span class="pill" id="pill-role">${ACCESS.role[0].toUpperCase() + ACCESS.role.slice(1)}</span><span class="pill" id="pill-robot">Robot …</span><span class="pill" id="pill-plc">PLC …</span>${stopKeyHtml()}</header>
    <main id="main"></main><div id="message">${ACCESS.role === "monitor" ?
      "Monitor mode (read only): open the operator address printed at start-up to operate." : "Ready."}</div></div>`;
  alarmBanner(document.querySelector(".panel"));
  const key = document.getElementById("hdr-stop");
  if (key) key.onclick = () => sendStop(STOP_IMMEDIATE, "Stop");
  return document.getElementById("main");
}

/* The Stop key: the last key of the header, so it sits in the top right corner of every page, and the only red
   key of the panel (ISA-101). It sends the stop at once through the PLC's CBT_Stop instance (Stop_Execute with
   Stop_Param.Mode), for the operator as for the engineer: a stop is never refused for the role. The PLC latches
   it (the PnP cycle stays Stopped until a new Start), so releasing Execute afterwards never moves the robot. */
const STOP_IMMEDIATE = 1, STOP_DISCARD_ALL = 3;          // eCBT_StopMode in mapping.json
const STOP_VARS = ["Stop_Done", "Stop_Error", "Stop_ErrorID", "Stop_ErrorDescrip"];
function stopKeyHtml() {
  if (!MAP || !MAP.variables.Stop_Execute) return "";   // a user's program without CBT_Stop
  return `<button class="danger" id="hdr-stop" title="Stop the robot now"${mayWrite("Stop_Execute") ? "" :
    " disabled"}>■ Stop</button>`;
}
async function sendStop(mode, what) {
  if (await executeCommand("Stop_Execute", { "Stop_Param.Mode": mode }, what)) {
    releaseWhenFinished("Stop", what, "the robot stopped and its queue is cleared");
  }
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
      <a href="stop.html" id="nav-stop" class="stop">Stop Motion</a></div></div>${cellArea()}
    </div><div class="viewcol"><div id="robotview"></div>${robotStatusStrip()}</div>`;
  for (const [key, page] of Object.entries(MAP.custom_pages || {})) {
    document.getElementById(`nav-${key}`).textContent = page.title;     // the user's text, never as HTML
  }
  robotView(document.getElementById("robotview"));
  robotTile(document.getElementById("robotview"));
  document.querySelector("header h1").insertAdjacentHTML("afterend",
    '<a class="menu" id="nav-jog" href="jog.html">Jog / Teach</a>' +
    '<a class="menu" id="nav-program" href="program.html">Ladder</a>');
  startPolling(["Connect_Connected", "ReadPos_Valid", "ReadPos_Position", ...ROBOT_STATUS, ...ROBOT_TILE_VARS]);
}

/* make demo --pages: the pages described for the user's cell (custom.js), one tile each beside the shipped ones */
function cellArea() {
  const pages = Object.entries(MAP.custom_pages || {});
  if (!pages.length) return "";
  const tile = ([key, page]) => `<a href="${key}.html" id="nav-${key}"></a>`;
  return `<div class="area" id="cell-area"><h2>Your cell</h2><div class="tiles">${pages.map(tile).join("")}</div></div>`;
}

/* the robot's state on every page: In Listen node, Paused, Stopping, queue depth, last ErrorID */
const ROBOT_STATUS = ["Robot_InListenNode", "Robot_Paused", "Robot_Stopping", "Robot_QueueDepth", "Robot_LastErrorID"];
function robotStatusStrip() {
  return `<div class="robot-status">
    <span>In Listen node <span data-status="Robot_InListenNode"><span class="led"></span></span></span>
    <span>Paused <span data-status="Robot_Paused"><span class="led busy"></span></span></span>
    <span>Stopping <span data-status="Robot_Stopping"><span class="led bad"></span></span></span>
    <span>Queue <b data-status="Robot_QueueDepth"></b></span>
    <span>Last ErrorID <b data-status="Robot_LastErrorID"></b></span></div>`;
}

/* Active / Paused / Stopping lamps of a command page (Busy where the FB has no Active output) */
function indicators(active) {
  const div = document.createElement("div");
  div.className = "indicators";
  div.innerHTML = `<span data-status="${active}" class="lamp active">${active.endsWith("Active") ? "Active" : "Busy"}</span>
    <span data-status="Robot_Paused" class="lamp paused">Paused</span>
    <span data-status="Robot_Stopping" class="lamp stopping">Stopping</span>`;
  return [div, [active, "Robot_Paused", "Robot_Stopping"]];
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

/* Push-button commands (CBT_Stop): reset Execute once Done or Error shows (within 10 s), after holding it
   HOLD_DONE_MS so the operator sees Done on the page before the FB clears it. */
const HOLD_DONE_MS = 1500;
function releaseWhenFinished(group, what, doneText) {
  const deadline = Date.now() + 10000, firstPoll = live.polls + 2;   // values read after the command was sent
  const check = async () => {
    const v = live.values;
    const finished = live.polls >= firstPoll && (v[`${group}_Done`] === true || v[`${group}_Error`] === true);
    if (!finished && Date.now() < deadline) { setTimeout(check, POLL_MS); return; }
    if (finished && v[`${group}_Done`] === true) {
      message(`${what}: Done – ${doneText}; releasing …`, "ok");
      await new Promise((resume) => setTimeout(resume, HOLD_DONE_MS));
    }
    try {
      await api("/api/write", { values: { [`${group}_Execute`]: false } });
      if (finished && v[`${group}_Error`] === true) message(errorMessage(what, v, group), "error");
      else if (finished) message(`${what}: Done – ${doneText}.`, "ok");
      else message(`${what}: the robot did not answer within 10 s; the command is released.`, "error");
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
    if (page.act) b.disabled = !mayWrite(`${group}_Execute`);
    b.onclick = () => {
      if (page.act) {                          // Stop page: "Stop Immediately" stops now, not only fills the form
        if (page.param) fillFrom(params, page.param, page.presets[name]);
        sendStop(page.presets[name].Mode, name);
        return;
      }
      if (page.param) fillFrom(params, page.param, page.presets[name]);
      else for (const [v, val] of Object.entries(page.presets[name])) setInput(params.querySelector(`[data-path="${v}"]`), val);
      refreshLimits(params, page.param || "");
      message(exec.disabled ? `${name}: fields filled; sending them needs ${ACCESS.role === "monitor" ?
        "the operator address" : "the engineer address"}.` : `${name}: fields filled, press ${page.execLabel || "Execute"} to send.`);
    };
    buttons.append(b);
  });
  const exec = document.createElement("button");
  exec.className = "primary" + (key === "connect" ? "" : " wide");     // red is the header's Stop key only
  exec.id = "btn-execute"; exec.textContent = page.execLabel || "Execute";
  exec.disabled = !mayWrite(`${group}_Execute`);
  exec.onclick = () => {
    const result = collect(params, page.param || "");
    if (result.error) { message(result.error + " — nothing was sent.", "error"); return; }
    executeCommand(`${group}_Execute`, result.values, page.title).then((sent) => {
      if (sent && page.release) releaseWhenFinished(group, page.title, page.release);
      else if (sent) watchResult(group, page.title, page.done && page.done(formContext(params, page.param)));
    });
  };
  buttons.append(exec);
  if (key === "connect") {
    const off = document.createElement("button");
    off.id = "btn-disconnect"; off.textContent = "Disconnect";
    off.onclick = async () => {
      try { await api("/api/write", { values: { Connect_Execute: false } }); message("Disconnect: the PLC closes the connection to the robot.", "ok"); }
      catch (e) { message("Disconnect: " + e.message, "error"); }
    };
    buttons.append(off);
  }
  const statusNames = page.status || DEFAULT_STATUS;
  const [lamps, lampNames] = indicators(MAP.variables[`${group}_Active`] ? `${group}_Active` : `${group}_Busy`);
  side.append(buttons, ...(key === "connect" ? [] : [lamps]),
    statusTable("Command Status", statusNames.map((s) => [s, `${group}_${s}`])));
  const left = document.createElement("div");
  left.className = "left";
  left.append(params);
  let redraw;
  if (key === "connect") {
    const box = document.createElement("div");
    box.className = "area connectinfo";
    box.innerHTML = `<h2>Robot</h2>${robotStatusStrip()}<p>The PLC connects to the robot's Listen node (TMflow, port 5890)
      and checks it every 500 ms; a silent link is reported 1.0 to 1.5 s later (16#2006), then it reconnects by
      itself while Connect is on (Reconnecting, RetryCount).</p>`;
    left.append(box);
  }
  if (page.view !== false) {                 // Change TCP needs its whole panel for the tool data
    const view = document.createElement("div");
    view.id = "robotview";
    left.append(view);
    redraw = robotView(view, () => motionPreview(key, params, page.param));
  } else {
    params.classList.add("full");
    redraw = () => {};
  }
  main.append(left, side);
  const toRead = page.param ? [page.param] : page.inputs;
  try {
    const data = await readVars(toRead);
    if (page.param) fillFrom(params, page.param, data.values[page.param]);
    else for (const v of page.inputs) setInput(params.querySelector(`[data-path="${v}"]`), data.values[v]);
  } catch (e) { message("Cannot read the current parameters: " + e.message, "error"); }
  watchLimits(params, page.param || "");
  params.addEventListener("input", redraw);        // the target preview follows the typing
  params.addEventListener("change", redraw);
  startPolling([...statusNames.map((s) => `${group}_${s}`), ...lampNames, "Connect_Connected", "ReadPos_Valid",
    "ReadPos_Position", ...ROBOT_STATUS]);
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
  if (MAP.custom_pages && MAP.custom_pages[key]) customPage(key);    // custom.js: a page description file
  else if (key === "main") (MAP.variables.Connect_Connected ? mainPage() : customIndexPage());
  else if (key === "pnp") pnpPage();
  else if (key === "jog") jogPage();
  else if (key === "program") programPage();
  else fbPage(key);
}

document.addEventListener("DOMContentLoaded", boot);
