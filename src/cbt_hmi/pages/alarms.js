/* CBT HMI – alarms, the Robot tile and FB results.
   The alarm list belongs to the server (src/cbt_hmi/web/alarms.py, ISA-18.2): one alarm per cause with its
   consequences as details, priority, states, timestamps of the controller's clock, acknowledge shared by every
   panel, a history of 1000 entries. The pages only show it: every /api/read answer carries the alarm list's
   change count, and the page asks /api/alarms when it changed.
   - Alarm banner on every page: the unacknowledged alarm of the highest priority, with its operator remedy.
   - Alarm list on the main page (time, priority, alarm, state; first-out marked; a tapped row shows the whole
     alarm, its remedy and its consequences on the message line); History opens the last 500 entries.
   - The panel's own communication alarm when the HMI server does not answer (it cannot be in the server's list).
   - Robot tile on the main page: project state, robot error, E-stop, mode, link; Play and Stop Project press
     the robot's stick buttons through CBT_ProjectControl; Back to Listen Node stops and plays the project.
   - watchResult: the message line reports what the FB answered, with the operator's remedy for an ErrorID.
   Operator remedies of the ErrorIDs come from errors.json, generated from docs/library/errors.tsv. */
"use strict";

const PROJECT_CMD = { play: 0, pause: 1, stop: 2 };      // eCBT_ProjectCmd
const alarms = { seq: null, list: [], history: [], texts: {}, asking: false, historyWanted: 0 };

function idText(id) { return "16#" + Number(id).toString(16).toUpperCase().padStart(4, "0"); }
function robotCode(code) { return "16#" + (Number(code) >>> 0).toString(16).toUpperCase().padStart(8, "0"); }
function operatorRemedy(id) { const row = alarms.texts[idText(id)]; return row ? row.operator || "" : ""; }

/* An FB's ErrorDescrip is written for the engineer, and a few name a function block ("Robot not connected: CBT_Connect
   is retrying (see its ErrorID); nothing sent"). The operator reads it up to that clause, then the operator remedy of
   the ErrorID table; the whole text stays in the Command Status area and on the FB's page. alarms.py's
   operator_text is the same rule for the alarm texts (test_hmi_operator_review.py checks both on every ErrorID). */
function operatorText(descrip) {
  const text = String(descrip || ""), at = text.search(/\bCBT_\w/);
  if (at < 0) return text;
  const cut = text.lastIndexOf(": ", at);
  return cut > 0 ? text.slice(0, cut) : "";
}

async function loadAlarms() {
  try { alarms.texts = await (await fetch(dataFileAddress("errors.json"))).json(); } catch (e) { alarms.texts = {}; }
}

/* called by every poll with the /api/read answer (null: no answer) */
function alarmsAfterRead(data) {
  if (data && data.alarms !== alarms.seq && !alarms.asking) fetchAlarms();
  drawBanner();
}

async function fetchAlarms() {
  alarms.asking = true;
  try {
    const data = await api(`/api/alarms?history=${alarms.historyWanted}`);
    alarms.seq = data.seq;
    alarms.list = data.alarms;
    if (data.history) alarms.history = data.history;
    drawAlarms();
  } catch (e) { /* the next poll asks again: the read answer still carries the new count */ }
  finally { alarms.asking = false; }
}

async function acknowledge(body) {
  try {
    await api("/api/alarms/ack", body);
    await fetchAlarms();
  } catch (e) { message("Acknowledge: " + e.message, "error"); }
}

const PRIORITY_SHOWN = { high: "High", medium: "Medium", low: "Low" };
const STATE_SHOWN = { "active-unacknowledged": "active, unack.", "active-acknowledged": "active, ack.",
  "returned-unacknowledged": "returned, unack.", normal: "normal" };     // the list's column; tap a row: whole

function alarmLine(a) {
  return `${a.source}${a.id ? " " + a.id : ""}: ${a.text}`;
}

function alarmWhole(a) {
  const more = a.details.length ? `  Consequences: ${a.details.map((d) => d.text).join("; ")}.` : "";
  return `${a.time}  ${PRIORITY_SHOWN[a.priority]}  ${a.state.replace("-", ", ")}  ${alarmLine(a)}` +
    `${a.remedy ? " — " + a.remedy : ""}` +
    `${a.first_out ? "  (first out)" : ""}${more}`;
}

/* The banner: the panel's own communication alarm while the server does not answer, else the unacknowledged
   alarm of the highest priority (the server lists them highest priority first, newest first). */
function drawBanner() {
  const banner = document.getElementById("alarm-banner");
  if (!banner) return;
  const text = banner.querySelector(".text"), ack = banner.querySelector("button");
  if (!live.online && !live.fault && live.lostAt) {      // every write compares first (hmi.js, setText …)
    setHidden(banner, false);
    setData(banner, "priority", "high");
    setHidden(ack, true);
    setText(text, `${live.clock ? live.clock.slice(0, 19) : "—"}  High  PLC communication lost: no answer from the ` +
      "PLC — check the PLC and the network cable; the values shown as #### are not valid.");
    return;
  }
  const open = alarms.list.filter((a) => a.state.endsWith("unacknowledged"));
  setHidden(banner, open.length === 0);
  setHidden(ack, false);
  if (!open.length) return;
  const a = open[0];
  setData(banner, "priority", a.priority);
  setData(banner, "number", a.number);
  const shown = `${a.time.slice(0, 19)}  ${PRIORITY_SHOWN[a.priority]}  ${alarmLine(a)}` +
    (a.remedy ? ` — ${a.remedy}` : "") + (a.details.length ? `  [${a.details.length} consequence` +
    `${a.details.length > 1 ? "s" : ""}]` : "") + (open.length > 1 ? `  (+${open.length - 1} more)` : "");
  setText(text, shown);
}

function drawAlarms() {
  drawBanner();
  const table = document.getElementById("alarm-history");
  if (!table) return;
  table.innerHTML = "<tr><th>Time</th><th>Prio</th><th>Alarm</th><th>State</th></tr>";
  if (!alarms.list.length) {
    table.insertRow().insertCell().textContent = "No alarms.";
    table.rows[1].cells[0].colSpan = 4;
  }
  for (const a of alarms.list) {
    const tr = table.insertRow();
    tr.className = a.state + " " + a.priority;
    tr.dataset.number = a.number;
    tr.insertCell().textContent = a.time.slice(11, 19);
    tr.insertCell().textContent = PRIORITY_SHOWN[a.priority];
    const line = document.createElement("span");     // at most two lines: the row stays one 34 px touch target
    line.textContent = (a.first_out ? "① " : "") + alarmLine(a) + (a.details.length ? ` (+${a.details.length})` : "");
    tr.insertCell().append(line);
    tr.insertCell().textContent = STATE_SHOWN[a.state];
    tr.onclick = () => message(alarmWhole(a));
  }
  drawHistory();
}

function drawHistory() {
  const table = document.getElementById("alarm-log");
  if (!table) return;
  table.innerHTML = "<tr><th>Date and time</th><th>Event</th><th>Alarm</th></tr>";
  for (const e of alarms.history) {
    const tr = table.insertRow();
    tr.insertCell().textContent = e.time;
    tr.insertCell().textContent = e.event + (e.by ? ` (${e.by})` : "");
    tr.insertCell().textContent = `#${e.alarm} ${PRIORITY_SHOWN[e.priority] || ""} ${e.source}${e.id ? " " + e.id : ""}: ` +
      (e.detail ? `consequence: ${e.detail}` : e.text);
  }
}

/* called by frame(): the banner under the header of every page */
function alarmBanner(panel) {
  const banner = document.createElement("div");
  banner.id = "alarm-banner";
  banner.className = "alarm-banner";
  banner.hidden = true;
  banner.innerHTML = '<span class="text"></span><button id="btn-alarm-ack">Acknowledge</button>';
  const button = banner.querySelector("button");
  button.disabled = ACCESS.role === "monitor";
  button.onclick = () => { if (banner.dataset.number) acknowledge({ alarms: [Number(banner.dataset.number)] }); };
  banner.querySelector(".text").onclick = () => {
    const a = alarms.list.find((x) => String(x.number) === banner.dataset.number);
    if (a) message(alarmWhole(a));
  };
  panel.querySelector("header").after(banner);
}

/* ---------- Robot tile (main page) ---------- */
function robotTile(container) {
  alarms.historyWanted = 500;
  const area = document.createElement("div");
  area.className = "robot-tile";
  area.innerHTML = `<div class="row"><table class="robot-state">
      <tr><td>Project</td><td id="robot-project" data-invalid></td></tr>
      <tr><td>Robot error</td><td><span id="robot-error" data-invalid></span></td></tr>
      <tr><td>Safety / mode</td><td id="robot-safety" data-invalid></td></tr>
      <tr><td>Link</td><td id="robot-link" data-invalid></td></tr></table>
    <div class="buttons"><button id="btn-project-play">Play</button><button id="btn-project-stop">Stop Project</button>
      <button id="btn-alarm-ack-all">Acknowledge all</button><button id="btn-alarm-history">History</button>
      <button id="btn-back-to-node" hidden>Back to Listen Node</button></div></div>
    <div class="alarm-list" aria-label="Alarms"><table id="alarm-history"></table></div>
    <dialog id="alarm-log-dialog"><header><h1>Alarm history (controller time, newest first)</h1></header>
      <div class="body"><table id="alarm-log"></table></div>
      <div class="actions"><button id="btn-alarm-history-close">Close</button></div></dialog>`;
  container.append(area);
  const texts = { play: ["Play", "the robot project runs"], stop: ["Stop Project", "the robot project stopped"] };
  const press = (command) => executeCommand("Project_Execute", { Project_Command: PROJECT_CMD[command] }, texts[command][0])
    .then((sent) => sent && releaseWhenFinished("Project", texts[command][0], texts[command][1]));
  for (const [id, command] of [["btn-project-play", "play"], ["btn-project-stop", "stop"]]) {
    const b = area.querySelector("#" + id);
    b.disabled = !mayWrite("Project_Execute");
    b.onclick = () => press(command);
  }
  const back = area.querySelector("#btn-back-to-node");
  back.disabled = !mayWrite("Project_Execute");
  back.onclick = () => backToListenNode();
  const ackAll = area.querySelector("#btn-alarm-ack-all");
  ackAll.disabled = ACCESS.role === "monitor";
  ackAll.onclick = () => acknowledge({ all: true });
  const dialog = area.querySelector("#alarm-log-dialog");
  area.querySelector("#btn-alarm-history").onclick = () => { drawHistory(); dialog.showModal(); };
  area.querySelector("#btn-alarm-history-close").onclick = () => dialog.close();
  live.listeners.push(drawRobotTile);
  drawAlarms();
}

/* The robot left its Listen node (an Exit Listen Node, a flow path): Play alone does not bring it back while its
   project runs, so the project is stopped and played again through CBT_ProjectControl; TMflow's project then
   enters the Listen node and CBT_Connect reconnects by itself. */
async function backToListenNode() {
  const what = "Back to Listen Node";
  if (!(await executeCommand("Project_Execute", { Project_Command: PROJECT_CMD.stop }, what))) return;
  if (!(await projectFinished(what))) return;
  if (!(await executeCommand("Project_Execute", { Project_Command: PROJECT_CMD.play }, what))) return;
  if (await projectFinished(what)) message(`${what}: Done – the robot project runs again; the PLC reconnects to its Listen node.`, "ok");
}

function projectFinished(what) {
  const firstPoll = live.polls + 2, deadline = Date.now() + 10000;
  return new Promise((resolve) => {
    const check = async () => {
      const v = live.values;
      if (live.polls >= firstPoll && (v.Project_Done === true || v.Project_Error === true)) {
        const ok = v.Project_Done === true;
        if (!ok) message(`${what}: Error ${idText(v.Project_ErrorID)} – ${operatorText(v.Project_ErrorDescrip)}. ` +
          operatorRemedy(v.Project_ErrorID), "error");
        try { await api("/api/write", { values: { Project_Execute: false } }); } catch (e) { /* reported below */ }
        resolve(ok);
      } else if (Date.now() > deadline) {
        message(`${what}: the robot did not answer within 10 s.`, "error");
        resolve(false);
      } else setTimeout(check, POLL_MS);
    };
    setTimeout(check, POLL_MS);
  });
}

function drawRobotTile() {
  const v = live.values, rs = v.RobotStatus, valid = v.RobotStatus_Valid === true && rs;
  const set = (id, text, bad) => {
    const el = document.getElementById(id);
    setText(el, text);
    setClass(el, bad ? "bad" : "");
  };
  setHidden(document.getElementById("btn-back-to-node"), live.robot !== "left the Listen node");
  if (!live.online && !live.fault) {
    for (const id of ["robot-project", "robot-error", "robot-safety", "robot-link"]) set(id, "####", false);
    return;
  }
  set("robot-project", !valid ? "unknown (no Ethernet Slave data)" :
    rs.ProjectRunning ? (rs.ProjectPaused ? "paused" : "running") + ` at ${rs.ProjectSpeed} %` : "stopped",
  valid && !rs.ProjectRunning);
  set("robot-error", !valid ? "—" : rs.RobotError ? `code ${robotCode(rs.ErrorCode)}: ${rs.ErrorText}` : "none",
    valid && rs.RobotError);
  set("robot-safety", !valid ? "—" : `${rs.EStop ? "E-STOP pressed" : "E-stop released"}, ${rs.AutoMode ? "auto" : "manual"} mode`,
    valid && rs.EStop);
  set("robot-link", !v.Connect_Connected ? (v.Connect_Reconnecting ? "reconnecting …" : "Listen node not connected") :
    v.Robot_InListenNode === false ? "connected, robot outside its Listen node" : "Listen node connected",
  !v.Connect_Connected || v.Robot_InListenNode === false);
}
const ROBOT_TILE_VARS = ["RobotStatus_Valid", "RobotStatus", "Connect_Reconnecting", "Connect_Connected",
  "Robot_InListenNode", "Project_Busy", "Project_Done", "Project_Error", "Project_ErrorID", "Project_ErrorDescrip"];

/* ---------- the FB's answer on the message line ---------- */
function errorMessage(what, v, group) {
  const id = v[`${group}_ErrorID`], remedy = operatorRemedy(id);
  return `${what}: Error ${idText(id)} – ${operatorText(v[`${group}_ErrorDescrip`])}.${remedy ? " " + remedy : ""}`;
}

function watchResult(group, what, doneText) {      // doneText: what Done means for this command
  const firstPoll = live.polls + 2, deadline = Date.now() + 30000;
  const check = () => {
    const v = live.values;
    if (live.polls >= firstPoll) {
      if (v[`${group}_Error`] === true) { message(errorMessage(what, v, group), "error"); return; }
      if (v[`${group}_CommandAborted`] === true) {
        message(`${what}: aborted (CommandAborted) – a stop cleared it, or a new command replaced it.`, "error");
        return;
      }
      if (v[`${group}_Done`] === true || (group === "Connect" && v.Connect_Connected === true)) {
        message(doneText ? `${what}: Done – ${doneText}` : `${what}: done.`, "ok");
        return;
      }
    }
    if (Date.now() < deadline) setTimeout(check, POLL_MS);
    else message(`${what}: sent; no result within 30 s (the robot is still busy with it).`);
  };
  setTimeout(check, POLL_MS);
}
