/* CBT HMI – alarms, the Robot tile and FB results (issue 14).
   - Alarm banner on every page: the newest unacknowledged alarm with its ErrorID, text and remedy.
   - Alarm history on the main page (time, source, ErrorID or robot code, text, active / gone, acknowledged;
     a tapped row shows whole on the message line), kept for the browser tab while pages change; Acknowledge marks alarms seen (it does not reset the PLC).
   - Robot tile on the main page: project state, robot error (the robot's code and text), E-stop, mode, link;
     Play and Stop press the robot's stick buttons through CBT_ProjectControl (Project_Command/Project_Execute).
   - watchResult: the message line reports what the FB answered (Done, Error with ErrorID and text,
     CommandAborted), never "sent" as a success.
   ErrorID texts, causes and remedies come from errors.json, generated from docs/library/errors.tsv. */
"use strict";

/* [key, source shown, error flag, ErrorID variable, text variable] */
const ALARM_SOURCES = [
  ["connect", "Connection", "Connect_Error", "Connect_ErrorID", "Connect_ErrorDescrip"],
  ["pnp", "PnP sequence", "PnP_MoveError", "PnP_MoveErrorID", "PnP_MoveErrorDescrip"],
  ["project", "Project control", "Project_Error", "Project_ErrorID", "Project_ErrorDescrip"],
  ...["ChangeBase", "ChangeTCP", "MoveRel", "MoveAbs", "MoveCircle", "ProgramControl", "SetOutput", "Stop"]
    .map((g) => [g.toLowerCase(), (Object.values(PAGES).find((p) => p.group === g) || { title: g }).title,
      `${g}_Error`, `${g}_ErrorID`, `${g}_ErrorDescrip`]),
];
const PROJECT_CMD = { play: 0, pause: 1, stop: 2 };      // eCBT_ProjectCmd
const alarms = { list: [], active: {}, texts: {}, sawConnected: false };

function alarmVariables() {
  return [...ALARM_SOURCES.flatMap((s) => s.slice(2)), "RobotStatus_Valid", "RobotStatus", "Connect_Reconnecting",
    "Connect_RetryCount", "Robot_LastErrorID", "Connect_Connected", "Project_Busy", "Project_Done"]
    .filter((n) => MAP.variables[n]);
}

function idText(id) { return "16#" + Number(id).toString(16).toUpperCase().padStart(4, "0"); }
function robotCode(code) { return "16#" + (Number(code) >>> 0).toString(16).toUpperCase().padStart(8, "0"); }

async function loadAlarms() {
  try { alarms.texts = await (await fetch("errors.json")).json(); } catch (e) { alarms.texts = {}; }
  try {
    const kept = JSON.parse(sessionStorage.getItem("cbt-alarms") || "[]");
    alarms.list = kept.map((a) => ({ ...a, time: new Date(a.time), gone: a.gone && new Date(a.gone) }));
    for (const a of alarms.list) if (!a.gone) alarms.active[a.key] = a;
  } catch (e) { alarms.list = []; }
}

function saveAlarms() { sessionStorage.setItem("cbt-alarms", JSON.stringify(alarms.list)); }

/* One alarm for a whole outage: CBT_Connect shows Error only during its back-off waits (FALSE during each
   attempt), so its own Error would raise and clear an alarm on every retry. While Connect_Reconnecting is TRUE
   the connection alarm stays active under one key; its ErrorID is the latest reason seen (Connect_ErrorID of
   the loss or of the last failed attempt, else the connection's Robot_LastErrorID), updated in place. A first
   connect that failed at Time_Out is retried the same way (Execute held): "not connected" unless this tab saw
   the link up before. */
function reconnectingAlarm(v) {
  const held = alarms.active["connect:reconnecting"], lost = held ? held.lost : alarms.sawConnected;
  const id = v.Connect_ErrorID || (held && held.id) || v.Robot_LastErrorID || 0;
  const known = alarms.texts[idText(id)];
  const reason = v.Connect_Error === true && v.Connect_ErrorID === id && v.Connect_ErrorDescrip ? v.Connect_ErrorDescrip
    : held && held.id === id ? held.reason : known ? known.text : "";
  const attempt = v.Connect_RetryCount ? ` (attempt ${v.Connect_RetryCount})` : "";
  return { source: "Connection", id, reason, lost,
    text: `${lost ? "Connection lost, reconnecting" : "Not connected, retrying"}${attempt}${reason ? " — " + reason : ""}` };
}

/* what is in alarm now: {key: {source, id | code, text}} */
function currentAlarms() {
  const v = live.values, now = {}, reconnecting = v.Connect_Reconnecting === true;
  if (reconnecting) now["connect:reconnecting"] = reconnectingAlarm(v);
  for (const [key, source, flag, idVar, textVar] of ALARM_SOURCES)
    if (v[flag] === true && v[idVar] && !(reconnecting && key === "connect"))
      now[`${key}:${v[idVar]}`] = { source, id: v[idVar], text: v[textVar] || "" };
  const rs = v.RobotStatus;
  if (v.RobotStatus_Valid === true && rs) {
    if (rs.RobotError) now[`robot:${rs.ErrorCode}`] = { source: "Robot", code: rs.ErrorCode, text: rs.ErrorText || "Robot error" };
    if (rs.EStop) now.estop = { source: "Robot", text: "Emergency stop pressed" };
  }
  return now;
}

function checkAlarms() {
  if (!live.online) return;
  if (live.values.Connect_Connected === true) alarms.sawConnected = true;
  const now = currentAlarms(), stamp = new Date();
  let changed = false;
  for (const [key, a] of Object.entries(now)) {
    const held = alarms.active[key];
    if (held) {                     // still active: its reason may change, it stays one (acknowledged) entry
      if (held.id !== a.id || held.text !== a.text) { Object.assign(held, a); changed = true; }
      continue;
    }
    const entry = { ...a, key, time: stamp, ack: false, gone: null };
    alarms.list.unshift(entry);
    alarms.active[key] = entry;
    changed = true;
  }
  for (const [key, entry] of Object.entries(alarms.active)) {
    if (now[key]) continue;
    entry.gone = stamp;
    delete alarms.active[key];
    changed = true;
  }
  if (!changed) return;
  alarms.list.length = Math.min(alarms.list.length, 100);
  saveAlarms();
  drawAlarms();
}

function alarmLine(a) {
  const what = a.id ? idText(a.id) : a.code !== undefined ? `code ${robotCode(a.code)}` : "";
  return `${a.source}${what ? " " + what : ""}: ${a.text}`;
}

function remedyOf(a) { return a.id && alarms.texts[idText(a.id)] ? alarms.texts[idText(a.id)].remedy : ""; }

function acknowledge(entries) {
  for (const a of entries) a.ack = true;
  saveAlarms();
  drawAlarms();
}

function drawAlarms() {
  const banner = document.getElementById("alarm-banner");
  if (banner) {
    const open = alarms.list.filter((a) => !a.ack);
    banner.hidden = open.length === 0;
    if (open.length) {
      const a = open[0], remedy = remedyOf(a);
      banner.querySelector(".text").textContent = `${a.time.toLocaleTimeString()}  ${alarmLine(a)}` +
        (remedy ? ` — ${remedy}` : "") + (open.length > 1 ? `  (+${open.length - 1} more)` : "");
    }
  }
  const table = document.getElementById("alarm-history");
  if (!table) return;
  table.innerHTML = "<tr><th>Time</th><th>Alarm</th><th>State</th></tr>";
  for (const a of alarms.list.slice(0, 30)) {
    const tr = table.insertRow();
    tr.className = (a.gone ? "gone" : "active") + (a.ack ? " ack" : "");
    tr.insertCell().textContent = a.time.toLocaleTimeString();
    tr.insertCell().textContent = alarmLine(a);
    tr.insertCell().textContent = (a.gone ? "gone" : "active") + (a.ack ? ", acknowledged" : "");
    tr.onclick = () => message(`${a.time.toLocaleTimeString()}  ${alarmLine(a)}` + (remedyOf(a) ? ` — ${remedyOf(a)}` : ""));
  }
}

/* called by frame(): the banner under the header of every page */
function alarmBanner(panel) {
  const banner = document.createElement("div");
  banner.id = "alarm-banner";
  banner.className = "alarm-banner";
  banner.hidden = true;
  banner.innerHTML = '<span class="text"></span><button id="btn-alarm-ack">Acknowledge</button>';
  banner.querySelector("button").onclick = () => {
    const open = alarms.list.filter((a) => !a.ack);
    if (open.length) acknowledge([open[0]]);
  };
  panel.querySelector("header").after(banner);
  drawAlarms();
}

/* ---------- Robot tile (main page) ---------- */
function robotTile(container) {
  const area = document.createElement("div");
  area.className = "robot-tile";
  area.innerHTML = `<div class="row"><table class="robot-state">
      <tr><td>Project</td><td id="robot-project"></td></tr>
      <tr><td>Robot error</td><td id="robot-error"></td></tr>
      <tr><td>Safety / mode</td><td id="robot-safety"></td></tr>
      <tr><td>Link</td><td id="robot-link"></td></tr></table>
    <div class="buttons"><button class="primary" id="btn-project-play">Play</button>
      <button class="danger" id="btn-project-stop">Stop Project</button></div></div>
    <div class="alarms-head">Alarms <button id="btn-alarm-ack-all">Acknowledge all</button></div>
    <div class="alarm-list"><table id="alarm-history"></table></div>`;
  container.append(area);
  const press = (command, what) => {
    executeCommand("Project_Execute", { Project_Command: PROJECT_CMD[command] }, what).then((sent) => {
      if (sent) releaseWhenFinished("Project", what);
    });
  };
  for (const [id, command, what] of [["btn-project-play", "play", "Project Play"], ["btn-project-stop", "stop", "Project Stop"]]) {
    const b = area.querySelector("#" + id);
    b.disabled = !mayWrite("Project_Execute");
    b.onclick = () => press(command, what);
  }
  area.querySelector("#btn-alarm-ack-all").onclick = () => acknowledge(alarms.list);
  live.listeners.push(drawRobotTile);
  drawAlarms();
}

function drawRobotTile() {
  const v = live.values, rs = v.RobotStatus, valid = v.RobotStatus_Valid === true && rs;
  const set = (id, text, bad) => {
    const el = document.getElementById(id);
    if (el.textContent !== text) el.textContent = text;
    el.className = bad ? "bad" : "";
  };
  set("robot-project", !valid ? "unknown (no Ethernet Slave data)" :
    rs.ProjectRunning ? (rs.ProjectPaused ? "paused" : "running") + ` at ${rs.ProjectSpeed} %` : "stopped",
  valid && !rs.ProjectRunning);
  set("robot-error", !valid ? "—" : rs.RobotError ? `code ${robotCode(rs.ErrorCode)}: ${rs.ErrorText}` : "none",
    valid && rs.RobotError);
  set("robot-safety", !valid ? "—" : `${rs.EStop ? "E-STOP pressed" : "E-stop released"}, ${rs.AutoMode ? "auto" : "manual"} mode`,
    valid && rs.EStop);
  set("robot-link", v.Connect_Connected ? "Listen node connected" :
    v.Connect_Reconnecting ? "reconnecting …" : "Listen node not connected", !v.Connect_Connected);
}

/* ---------- the FB's answer on the message line ---------- */
function watchResult(group, what, doneText) {      // doneText: what Done means for this command
  const firstPoll = live.polls + 2, deadline = Date.now() + 30000;
  const check = () => {
    const v = live.values;
    if (live.polls >= firstPoll) {
      if (v[`${group}_Error`] === true) {
        message(`${what}: Error ${idText(v[`${group}_ErrorID`])} – ${v[`${group}_ErrorDescrip`] || ""}`, "error");
        return;
      }
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
    else message(`${what}: sent; no result within 30 s (the FB is still busy).`);
  };
  setTimeout(check, POLL_MS);
}
