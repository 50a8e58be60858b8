/* CBT HMI: one script for every page. A command page is built from its page description (src/cbt_hmi/pages/desc/,
   carried by the variable table served at /api/mapping under page_descriptions); its fields come from the variable
   table, so ranges and enumerations live in one place (mapping.json, generated from the program and the
   descriptions). Main, PnP, Jog / Teach and Program are hand-written (their own scripts). The server checks every
   write again; the checks here only spare the operator a round trip. */
"use strict";

const POLL_MS = 50;            // 20 updates per second (issue: >= 10)

/* the fields' labels by structure member or variable name, from the page descriptions (MAP.labels) */
const LABELS = {};
/* A text of the user's (a page description's title, label or legend, a POU name) as HTML that shows it as written:
   markup in it is shown, never run (a page description is a file anyone with the pages folder can edit). */
const HTML_ESCAPES = { "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;", "'": "&#39;" };
function esc(text) { return String(text).replace(/[&<>"']/g, (c) => HTML_ESCAPES[c]); }

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
  setText(el, text);
  setClass(el, kind);
}

/* ---------- writing the page ---------- */
/* Every poll (20 a second) runs the page's listeners, and most of what they show has not changed since the last
   one. A write into the page costs the panel's browser a new frame (style, layout, paint) even when it writes the
   value already there, so the listeners write through these helpers: each one compares first and writes only a
   change (docs/hmi.md, Performance). A changed value still shows at the next poll. */
function setText(el, text) {
  const t = String(text);
  if (el.textContent !== t) el.textContent = t;
}
/* an attribute; null or undefined removes it */
function setAttr(el, name, value) {
  if (value === null || value === undefined) {
    if (el.hasAttribute(name)) el.removeAttribute(name);
    return;
  }
  const v = String(value);
  if (el.getAttribute(name) !== v) el.setAttribute(name, v);
}
function setData(el, key, value) {
  const v = String(value);
  if (el.dataset[key] !== v) el.dataset[key] = v;
}
/* the whole class attribute (HTML and SVG elements alike) */
function setClass(el, cls) {
  if ((el.getAttribute("class") || "") !== cls) el.setAttribute("class", cls);
}
function setHidden(el, flag) {
  if (el.hidden !== Boolean(flag)) el.hidden = Boolean(flag);
}
function setDisabled(el, flag) {
  if (el.disabled !== Boolean(flag)) el.disabled = Boolean(flag);
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

/* A field whose label does not fit its grid cell ("Motion Command" at 800x480) takes two cells: a label the
   operator needs is never cut with "…". Checked again whenever the fields' area changes size (its scroll bar
   appears once the fields are filled, the panel is drawn larger from 1280x800). */
function uncutLabels(root) {
  const check = () => {
    for (const label of root.querySelectorAll(".field > label")) {
      if (textWiderThanBox(label)) label.parentElement.classList.add("span2");
    }
  };
  check();
  if (!root.dataset.uncut) {
    root.dataset.uncut = "watched";
    new ResizeObserver(check).observe(root);
  }
}
/* the text's laid-out width against the element's content box, to the sub-pixel: scrollWidth is rounded, and a label
   0.2 px too wide is already cut with "…" */
function textWiderThanBox(el) {
  const range = document.createRange();
  range.selectNodeContents(el);
  const s = getComputedStyle(el), box = el.getBoundingClientRect().width - parseFloat(s.paddingLeft) -
    parseFloat(s.paddingRight) - parseFloat(s.borderLeftWidth) - parseFloat(s.borderRightWidth);
  return range.getBoundingClientRect().width > box + 0.01;
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
      fs.innerHTML = `<legend>${esc(LABELS[field] || field)}${range}</legend>`;
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
  fs.innerHTML = `<legend>${esc(legendText)}</legend>`;
  const grid = document.createElement("div");
  grid.className = "grid wide";
  for (const [field, spec] of scalars) grid.append(makeField(`${path}.${field}`, spec, LABELS[field] || field));
  const row = document.createElement("div");
  row.className = "checks";
  for (const [field, spec] of checks) row.append(makeField(`${path}.${field}`, spec, LABELS[field] || field));
  if (scalars.length) fs.append(grid);
  if (checks.length) fs.append(row);
  /* the target (a pose: Target Position, Arc and End Point, the base, the TCP offset) first, in sight at 800x480
     without scrolling; the settings under it, then the optional Robot Pose */
  const pose = container.querySelector('fieldset[data-member="RobotPose"]');
  container.insertBefore(fs, pose);
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
  div.innerHTML = `<h2>${esc(title)}</h2>`;
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
        setData(cell, "value", "invalid");
        const led = cell.querySelector(".led");
        if (led) led.classList.toggle("on", false);      // toggle with its force writes only a change
      } else setText(cell, "####");
      continue;
    }
    const v = live.values[cell.dataset.status];
    if (cell.classList.contains("lamp")) { setData(cell, "value", v === true); continue; }
    const led = cell.querySelector(".led");
    if (led) { led.classList.toggle("on", v === true); setData(cell, "value", v === true); continue; }
    let text = v === undefined || v === null ? "" : String(v);
    if (cell.dataset.status === "PnP_Segment" && typeof v === "number" && PNP_SEGMENTS[v])
      text = `${v + 1} ${PNP_SEGMENTS[v]}`;            // the drawing numbers segments from 1
    if (cell.dataset.status.endsWith("ErrorID") && typeof v === "number")
      text = "16#" + v.toString(16).toUpperCase().padStart(4, "0");
    setText(cell, text);
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
  setText(pillPlc, fault ? `PLC fault — ${what}` : live.online ? "PLC online" : "PLC offline");
  setAttr(pillPlc, "title", fault ? fault.message : "");
  setClass(pillPlc, "pill " + (live.online ? "" : "alarm"));
  const [text, kind] = fault ? ["Robot link closed", "alarm"] : lost ? ["Robot ####", ""] :
    ROBOT_PILL[live.robot] || ROBOT_PILL.unknown;
  setText(pillRobot, text);
  setClass(pillRobot, "pill " + kind);
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
/* The page's values come on one streamed answer, GET /api/stream: the server sends the /api/read answer of the
   page's variables every 50 ms on one connection (docs/hmi.md, Updates); each answer is a poll, as each read was.
   A fetch of /api/read per poll cost the panel's browser 8-10 % of a core whatever the page did with the answer;
   the stream's own cost is about 1 % (an idle page about 4 % with its own work on each answer). A stream that
   fails, ends or brings nothing for READ_TIMEOUT_MS is a poll without an answer (the values turn invalid), and the
   page opens a new one POLL_MS later. After a command the page opens a new stream at once (live.kick): every
   answer that follows was read after the command, none still on its way from before it. A hidden page (another
   tab in front) reads /api/read instead, at the pace the browser lets its timers run: it does not hold one of the
   six connections a browser keeps to one server while nobody looks at it. */
const MAX_ANSWER = 4 * 1024 * 1024;          // a line longer than any answer of MAX_NAMES variables: not our server
const pause = (ms) => new Promise((resume) => setTimeout(resume, ms));
function startPolling(names) {
  names = [...new Set([...names, ...STOP_VARS].filter((n) => MAP.variables[n]))];   // the Stop key's answer
  const pillPlc = document.getElementById("pill-plc"), pillRobot = document.getElementById("pill-robot");
  const address = "/api/stream?names=" + names.map(encodeURIComponent).join(",");
  let current = null, kicked = false;      // the open stream's AbortController; a new stream was asked for
  live.kick = () => { if (current) { kicked = true; current.abort(); } };
  /* the answers of one stream, each polled; "hidden" when it was left for the page being hidden, else it failed */
  async function stream() {
    const control = current = new AbortController();
    let silent = setTimeout(() => control.abort(), READ_TIMEOUT_MS);
    try {
      const response = await fetch(address, { headers: ACCESS.key ? { "X-HMI-Key": ACCESS.key } : {},
        signal: control.signal });
      if (!response.ok || !response.body) return "failed";
      const reader = response.body.getReader(), decoder = new TextDecoder();
      let text = "";
      while (document.visibilityState !== "hidden") {
        const { value, done } = await reader.read();
        if (done || control.signal.aborted) return "failed";   // aborted: a part that came before the command
        text += decoder.decode(value, { stream: true });
        for (let end = text.indexOf("\n"); end >= 0; end = text.indexOf("\n")) {
          const data = JSON.parse(text.slice(0, end));
          text = text.slice(end + 1);
          if (!data.ok) return "failed";
          clearTimeout(silent);
          silent = setTimeout(() => control.abort(), READ_TIMEOUT_MS);
          poll(data);
        }
        if (text.length > MAX_ANSWER) return "failed";
      }
      return "hidden";
    } catch (e) {
      return "failed";             // refused, cut, silent for READ_TIMEOUT_MS (aborted) or not JSON
    } finally {
      clearTimeout(silent);
      control.abort();
      current = null;
    }
  }
  async function run() {
    for (;;) {
      if (document.visibilityState === "hidden") {
        let data = null;
        try { data = await readVars(names); } catch (e) { /* no answer */ }
        poll(data);
        await pause(POLL_MS);
      } else if (await stream() === "hidden") {
        await pause(POLL_MS);
      } else if (kicked) {
        kicked = false;                 // left for a new stream after a command: no poll lost, none waited for
      } else {
        poll(null);
        await pause(POLL_MS);
      }
    }
  }
  /* one poll: ``data`` an answer of /api/read, null when none came */
  function poll(data) {
    if (data) {
      Object.assign(live.values, data.values);
      live.polls += 1;
      live.fault = data.plc === "fault" ? data.fault : null;
      live.online = !live.fault;          // after a major fault the values are the last ones, no longer valid
      live.robot = data.robot;
      live.clock = data.clock;
      live.lostAt = 0;
      alarmsAfterRead(data);
    } else {
      live.online = false; live.fault = null;
      live.lostAt = live.lostAt || Date.now();
      alarmsAfterRead(null);
    }
    showPlcState(pillPlc, pillRobot);
    showStatus();
    for (const f of live.listeners) f();
  }
  run();
}

/* ---------- page frame ---------- */
function frame(title, isMain) {
  document.title = "CBT HMI – " + title;
  document.body.innerHTML = `<div class="panel">
    <header>${isMain ? "" : '<a class="menu" id="btn-menu" href="index.html">◀ Main Menu</a>'}
      <h1>${esc(title)}</h1><span class="pill" id="pill-role">${ACCESS.role[0].toUpperCase() + ACCESS.role.slice(1)}</span><span class="pill" id="pill-robot">Robot …</span><span class="pill" id="pill-plc">PLC …</span>${stopKeyHtml()}</header>
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
  const main = frame("Main", true);
  main.innerHTML = `<div class="areas">
    <div class="area"><h2>Configuration</h2><div class="tiles">
      <a href="connect.html" id="nav-connect">Connect</a><a href="changebase.html" id="nav-changebase">Change Base</a>
      <a href="changetcp.html" id="nav-changetcp">Change TCP</a><a href="setoutput.html" id="nav-setoutput">Digital Output</a></div></div>
    <div class="area"><h2>Motion</h2><div class="tiles">
      <a href="moverel.html" id="nav-moverel">Move Relative</a><a href="moveabs.html" id="nav-moveabs">Move Absolute</a>
      <a href="movecircle.html" id="nav-movecircle">Move Circle</a><a href="pnp.html" id="nav-pnp">PnP Sequence</a>
      <a href="stop.html" id="nav-stop" class="stop">Stop Motion</a></div></div>${cellArea()}
      ${robotStatusStrip()}</div><div class="viewcol"><div id="robotview"></div></div>`;
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
  const lamps = [[active, "active", active.endsWith("Active") ? "Active" : "Busy"],
    ["Robot_Paused", "paused", "Paused"], ["Robot_Stopping", "stopping", "Stopping"]]
    .filter(([name]) => MAP.variables[name]);      // a user's program has no robot connection state
  div.innerHTML = lamps.map(([name, kind, text]) => `<span data-status="${name}" class="lamp ${kind}">${text}</span>`)
    .join("\n    ");
  return [div, lamps.map(([name]) => name)];
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
    // the values judged, kept: the answer reported after the release below is the one the FB gave, whatever the
    // polls show meanwhile (Execute FALSE clears Done and Error)
    const v = { ...live.values };
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

/* the Done text of a page description: the first entry whose "when" matches the form (checkbox TRUE/FALSE, the
   selected enumeration name) */
function doneText(page, context) {
  const same = (want, have) => have === (want === true ? "TRUE" : want === false ? "FALSE" : String(want));
  const hit = (page.done || []).find((d) => Object.entries(d.when || {}).every(([k, v]) => same(v, context[k])));
  return hit ? hit.text : undefined;
}

/* A command page built from its page description (cbt_hmi/pages/desc/<key>.json): the FB instance's parameter
   structure (or the described inputs) as fields, the presets, Execute, the lamps and the command status block. */
async function fbPage(key, page) {
  const group = page.instance, param = page.parameters ? page.parameters.variable : "";
  const execVar = page.command.variable, execLabel = page.command.label;
  const main = frame(page.title, false);
  Object.assign(LABELS, page.labels || {});
  hideRobotPill();                           // custom.js: a user's program without the robot connection
  const params = document.createElement("div");
  params.className = "params";
  if (param) {
    buildStruct(params, param, MAP.variables[param].type, page.parameters.legend);
  } else {
    params.append(inputsFieldset(page.inputs, page.legend || "Settings"));      // custom.js
  }
  const side = document.createElement("div");
  side.className = "side";
  const buttons = document.createElement("div");
  buttons.className = "buttons";
  const presets = page.presets || {};
  /* A preset fills only the fields this role may change: a locked field keeps the PLC's value (the operator's
     Connect page showed the preset's port, not the one in use). A preset that would fill none of them, or whose
     values this role cannot send, is disabled rather than a key that only changes what the page shows. */
  const presetFields = (values) => (param ? inputsUnder(params, param).map((el) =>
    [el, pick(values, el.dataset.path.slice(param.length))]) :
    Object.entries(values).map(([v, val]) => [params.querySelector(`[data-path="${v}"]`), val]))
    .filter(([el, val]) => el && !el.disabled && val !== undefined && val !== null);
  const presetKeys = [];
  Object.keys(presets).forEach((name, i) => {
    const b = document.createElement("button");
    b.className = "wide"; b.id = i ? `btn-preset-${i + 1}` : "btn-preset"; b.textContent = name;
    b.onclick = () => {
      if (page.act) {                          // Stop page: "Stop Immediately" stops now, not only fills the form
        if (param) fillFrom(params, param, presets[name]);
        sendStop(presets[name].Mode, name);
        return;
      }
      for (const [el, val] of presetFields(presets[name])) setInput(el, val);
      params.dispatchEvent(new Event("fill"));
      refreshLimits(params, param);
      message(`${name}: fields filled, press ${execLabel} to send.`);
    };
    presetKeys.push([b, name]);
    buttons.append(b);
  });
  const exec = document.createElement("button");
  exec.className = "primary" + (page.reset ? "" : " wide");     // red is the header's Stop key only
  exec.id = "btn-execute"; exec.textContent = execLabel;
  exec.disabled = !mayWrite(execVar);
  for (const [b, name] of presetKeys)
    b.disabled = exec.disabled || (!page.act && presetFields(presets[name]).length === 0);
  exec.onclick = () => {
    const result = collect(params, param);
    if (result.error) { message(result.error + " — nothing was sent.", "error"); return; }
    executeCommand(execVar, result.values, page.title).then((sent) => {
      if (sent && page.release) releaseWhenFinished(group, page.title, page.release);
      else if (sent) watchResult(group, page.title, doneText(page, formContext(params, param)));
    });
  };
  buttons.append(exec);
  if (page.reset) {                            // Disconnect: the command's variable FALSE ends what it holds
    const off = document.createElement("button");
    off.id = "btn-" + page.reset.label.toLowerCase().replace(/[^a-z0-9]+/g, "-");
    off.textContent = page.reset.label;
    off.onclick = async () => {
      try { await api("/api/write", { values: { [execVar]: false } }); message(`${page.reset.label}: ${page.reset.text}`, "ok"); }
      catch (e) { message(`${page.reset.label}: ${e.message}`, "error"); }
    };
    buttons.append(off);
  }
  const statusRows = page.status.map((item) => [item.label, item.variable]);
  const [lamps, lampNames] = page.lamp ? indicators(page.lamp) : [null, []];
  side.append(buttons, ...(lamps ? [lamps] : []), statusTable("Command Status", statusRows));
  const left = document.createElement("div");
  left.className = "left";
  left.append(params);
  let redraw;
  if (page.robot_status) {
    const box = document.createElement("div");
    box.className = "area connectinfo";
    box.innerHTML = `<h2>Robot</h2>${robotStatusStrip()}<p></p>`;
    box.querySelector("p").textContent = page.robot_status;
    left.append(box);
  }
  if (page.view !== false) {                 // Change TCP needs its whole panel for the tool data
    const view = document.createElement("div");
    view.id = "robotview";
    left.append(view);
    redraw = robotView(view, () => motionPreview(key, params, param));
  } else {
    params.classList.add("full");
    redraw = () => {};
  }
  main.append(left, side);
  uncutLabels(params);
  const inputs = page.inputs.map((item) => item.variable);
  try {
    const data = await readVars(param ? [param] : inputs);
    if (param) fillFrom(params, param, data.values[param]);
    else for (const v of inputs) setInput(params.querySelector(`[data-path="${v}"]`), data.values[v]);
  } catch (e) { message("Cannot read the current parameters: " + e.message, "error"); }
  watchLimits(params, param);
  params.addEventListener("input", redraw);        // the target preview follows the typing
  params.addEventListener("change", redraw);
  startPolling([...statusRows.map(([, v]) => v), ...lampNames, "Connect_Connected", "ReadPos_Valid",
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
  Object.assign(LABELS, MAP.labels || {});
  const described = (MAP.page_descriptions || {})[key] || (MAP.custom_pages || {})[key];
  if (described && described.instance) fbPage(key, described);        // a page driving an FB instance
  else if (described) customPage(key);                                // custom.js: a page of the user's cell
  else if (key === "main") (MAP.variables.Connect_Connected ? mainPage() : customIndexPage());
  else if (key === "pnp") pnpPage();
  else if (key === "jog") jogPage();
  else if (key === "program") programPage();
  else {                                     // the server serves only the pages of the table: not reached
    frame("CBT HMI", true);
    message(`No page '${key}' is described.`, "error");
  }
}

document.addEventListener("DOMContentLoaded", boot);
