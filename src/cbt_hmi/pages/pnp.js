/* CBT HMI: the PnP Sequence page. The six CBT_MoveAbsolute segments of PnP_Example drawn in side view over the
   whole panel (the side view every page shows: Y–Z, or X–Z when the operator chose it, robotview.js sideAxis),
   at one scale with a scale bar and the base height marked; each segment carries its name on the
   path (tap it to edit the segment), the one in progress is orange, and the TCP trail comes from the server.
   The cycle's state (PnP_State) is the PLC's: the page shows it with what the operator can do next, and offers
   Start, End Cycle and Reset only when the PLC takes them. */
"use strict";

let pnpParams = null;
let pnpGeometry = null;
let pnpTrailShown = { el: null, seq: -1 };         // the trail polyline and the trail it shows (updatePnP)

/* the segments and the preset cycle (same as the initial values in examples/GlobalVariables.st); the PnP page
   stays hand-written: a path drawing with six editable segments is more than a page description says */
const PNP_SEGMENTS = ["Approach pick", "Pick", "Retreat", "Approach place", "Place", "Retreat"];
const T = (x, y, z, rx = 180, ry = 0, rz = 90) => ({ X: x, Y: y, Z: z, RX: rx, RY: ry, RZ: rz });
const MOTION = { MovementCommand: 1, DataFormat: 1, Speed: 50, AccelTime: 200, BlendingEnable: false,
  BlendingValue: 0, PrecisePositioning: false, RobotPoseEnable: false };   // ExitNode: engineer only, left as it is
const PNP_PRESET = [
  { ...MOTION, TargetPosition: T(350, -200, 400), BlendingEnable: true, BlendingValue: 50 },
  { ...MOTION, MovementCommand: 0, DataFormat: 1, Speed: 30, TargetPosition: T(350, -200, 250), PrecisePositioning: true },
  { ...MOTION, MovementCommand: 0, DataFormat: 1, Speed: 30, TargetPosition: T(350, -200, 400) },
  { ...MOTION, TargetPosition: T(350, 200, 400), BlendingEnable: true, BlendingValue: 50 },
  { ...MOTION, MovementCommand: 0, DataFormat: 1, Speed: 30, TargetPosition: T(350, 200, 250), PrecisePositioning: true },
  { ...MOTION, MovementCommand: 0, DataFormat: 1, Speed: 30, TargetPosition: T(350, 200, 400) },
];

const PNP_STATES = ["Idle", "Running", "Stopping", "Stopped", "Faulted"];   // ePnP_State, in its order
const PNP_STATE_TEXT = {
  Idle: "Ready. Press Start to run the cycle.",
  Running: "The cycle is running. End Cycle stops after the current segment; Stop Motion stops the robot at once.",
  Stopping: "Stopping: the robot is ending the current command.",
  Stopped: "Stopped by Stop Motion. Nothing moves until you press Start; the cycle then goes on where it stopped.",
  Faulted: "The cycle stopped on a fault. Remove the cause, press Reset, then Start.",
};

function pnpState() {
  const v = live.values.PnP_State;
  return typeof v === "number" ? PNP_STATES[v] : v;
}

/* What the operator can do now, from the PLC's state: [button enabled by id, explanation] */
function pnpOptions() {
  const v = live.values, state = pnpState();
  const connected = v.Connect_Connected === true, stopHeld = v.Robot_Stopping === true;
  const startable = (state === "Idle" || state === "Stopped") && connected && !stopHeld;
  let text = PNP_STATE_TEXT[state] || "Waiting for the PLC …";
  if (state === "Faulted" && v.PnP_OutcomeUnknown)
    text = `Fault ${idText(v.PnP_MoveErrorID)}: the robot's answer was lost, the last command may have run. ` +
      "Press Reset, then Start: the cycle first checks where the robot is and goes on from there.";
  else if (state === "Faulted" && v.PnP_MoveError)       // the operator's words, not the FB's (alarms.js)
    text = `Fault ${idText(v.PnP_MoveErrorID)}: ${operatorText(v.PnP_MoveErrorDescrip)}. ` +
      `${operatorRemedy(v.PnP_MoveErrorID) || "Remove the cause."} Here: press Reset, then Start.`;
  if ((state === "Idle" || state === "Stopped") && !connected)
    text = v.Connect_Execute === true ?                      // Connect is on: CBT_Connect reconnects by itself
      "The link to the robot is down and the PLC is reconnecting: wait for Robot ready in the header, then press Start." :
      "The robot is not connected: connect it on the Connect page, then press Start.";
  else if ((state === "Idle" || state === "Stopped") && stopHeld)
    text = "Stop Motion is still active: wait until it is released, then press Start.";
  if (v.PnP_OutcomeUnknown && (state === "Idle" || state === "Stopped"))
    text += " The last command may have run: Start first checks where the robot is and goes on from there.";
  const enabled = { "btn-execute": startable && mayWrite("PnP_Example_Execute"),   // never for the monitor address
    "btn-stop": state === "Running" && v.PnP_Example_Execute === true && mayWrite("PnP_Example_Execute"),
    "btn-reset": state === "Faulted" && mayWrite("PnP_Reset") };
  return { state, text, enabled };
}

function showPnPState() {
  const box = document.getElementById("pnp-state");
  if (!box) return;
  const { state, text, enabled } = pnpOptions();
  if (state === "Faulted" && box.dataset.state !== "Faulted")      // the line no longer says "Start: … Running"
    message(`Cycle: Faulted – ${text}`, "error");
  setData(box, "state", state || "");                 // every write compares first (hmi.js, setText …)
  setText(document.getElementById("pnp-state-name"), state ? `Cycle: ${state}` : "Cycle: –");
  setText(document.getElementById("pnp-state-text"), text);
  for (const [id, on] of Object.entries(enabled)) setDisabled(document.getElementById(id), !on);
}

function buildPnP() {
  const main = frame("PnP Sequence", false);
  main.innerHTML = `<div class="pnpdraw"><svg id="pnp-svg"></svg>
      <div class="pnpfoot" style="display:flex;align-items:center;gap:8px">
        <span class="pos" id="pnp-note" style="flex:1;font-size:14px;color:#3d4852"></span>
        <button type="button" id="pnp-side" style="flex:none;min-height:34px;min-width:34px;font-size:14px"></button></div></div>
    <div class="side"><div class="pnp-state" id="pnp-state" data-state="">
        <b id="pnp-state-name">Cycle: –</b><span id="pnp-state-text">Waiting for the PLC …</span></div>
      <div class="buttons">
      <button class="primary" id="btn-execute" disabled>Start</button><button id="btn-stop" disabled>End Cycle</button>
      <button id="btn-reset" disabled>Reset</button><button id="btn-preset">Preset Values</button>
      <button id="btn-pause">Pause</button><button id="btn-resume">Resume</button></div>
    <div id="pnp-status"></div></div>
    <dialog id="seg-dialog"><header><h1 id="seg-title">Segment</h1></header><div class="body" id="seg-body"></div>
      <div class="actions"><button id="seg-cancel">Cancel</button><button class="primary" id="seg-apply">Apply</button></div></dialog>`;
  const statusBox = document.getElementById("pnp-status");
  const [lamps] = indicators("PnP_MoveActive");
  statusBox.append(lamps);
  statusBox.append(statusTable("Cycle Status", [["State", "PnP_State"], ["Segment", "PnP_Segment"],
    ["Waiting", "PnP_Waiting"], ["Gripper closed", "PnP_GripperClosed"], ["Cycles", "PnP_CycleCount"],
    ["Busy", "PnP_MoveBusy"], ["Error", "PnP_MoveError"], ["ErrorID", "PnP_MoveErrorID"], ["ErrorDescrip", "PnP_MoveErrorDescrip"]]));
  statusBox.style.cssText = "display:flex;flex-direction:column;gap:4px;flex:1;min-height:0";
  return main;
}

/* static part, rebuilt only when the parameters or the panel size change, so a tap on a label never lands on
   an element that a status update has just replaced */
function drawPnP() {
  const svg = document.getElementById("pnp-svg");
  if (!pnpParams) return;
  const box = svg.getBoundingClientRect();
  const W = Math.max(200, Math.round(box.width)), H = Math.max(150, Math.round(box.height));
  svg.setAttribute("viewBox", `0 0 ${W} ${H}`);
  const pts = pnpParams.map((p) => p.TargetPosition);
  const axis = sideAxis(), alongY = axis === "Y";          // the side view of every page (robotview.js)
  const other = alongY ? "X" : "Y";
  const across = Math.abs(pts[3][axis] - pts[0][axis]) < 20 && Math.abs(pts[3][other] - pts[0][other]) >= 20;
  const note = document.getElementById("pnp-note");
  note.textContent = across ? `Pick and place lie one behind the other in this side view (the travel runs along ` +
    `${other}): press ${other}–Z view.` : "Side view. Tap a segment's name to edit it. Orange: segment in progress; green: TCP trail.";
  const toggle = document.getElementById("pnp-side");
  toggle.textContent = `${alongY ? "X" : "Y"}–Z view`;
  toggle.title = toggle.ariaLabel = `Show the side view ${alongY ? "X" : "Y"}–Z (on every page)`;
  const horiz = (p) => (alongY ? p.Y : p.X);
  let h0 = Math.min(...pts.map(horiz)), h1 = Math.max(...pts.map(horiz));
  let v0 = Math.min(...pts.map((p) => p.Z)), v1 = Math.max(...pts.map((p) => p.Z));
  const [mx0, my0] = [150, 60];                         // room for the labels beside and above the path
  const s = Math.min((W - 2 * mx0) / Math.max(h1 - h0, 50), (H - 2 * my0 - 20) / Math.max(v1 - v0, 50));
  const X = (p) => W / 2 + (horiz(p) - (h0 + h1) / 2) * s;
  const Y = (p) => (H - 20) / 2 + my0 / 2 - (p.Z - (v0 + v1) / 2) * s;
  pnpGeometry = { X, Y, horiz };
  let out = `<defs><marker id="arrow" viewBox="0 0 10 10" refX="8" refY="5" markerUnits="userSpaceOnUse" markerWidth="10" markerHeight="10" orient="auto-start-reverse">
    <path d="M0,0 L10,5 L0,10 z" fill="#2368a8"/></marker></defs>`;
  const step = niceStep(Math.max(h1 - h0, v1 - v0, 100));           // grid in mm, as in the robot view
  for (let g = Math.ceil((h0 - W / s) / step) * step; g <= h1 + W / s; g += step) {
    const x = X(alongY ? { Y: g } : { X: g });
    if (x >= 0 && x <= W) out += `<line class="gridline" x1="${x}" y1="0" x2="${x}" y2="${H - 20}"/>`;
  }
  for (let g = Math.ceil((v0 - H / s) / step) * step; g <= v1 + H / s; g += step) {
    const y = Y({ Z: g });
    if (y >= 0 && y <= H - 20) out += `<line class="gridline" x1="0" y1="${y}" x2="${W}" y2="${y}"/>`;
  }
  const labels = [];
  for (let i = 0; i < 6; i++) {
    const a = pts[(i + 5) % 6], b = pts[i];
    const [x1, y1, x2, y2] = [X(a), Y(a), X(b), Y(b)];
    let lx = (x1 + x2) / 2, ly = (y1 + y2) / 2, d;
    const vertical = Math.abs(x1 - x2) < 8;
    const down = y2 > y1;
    const shift = vertical ? (down ? -6 : 6) : 0;     // down and up side by side, not on top of each other
    if (vertical) {               // both labels of a column on its outer side, the down one higher
      d = `M${x1 + shift},${y1} L${x2 + shift},${y2}`;
      const top = Math.min(y1, y2), bottom = Math.max(y1, y2);
      lx = x1 < W / 2 ? x1 - 78 : x1 + 78;
      ly = top + (down ? 0.28 : 0.78) * (bottom - top);
    }
    else if (i === 0) {            // return travel: an arc above the approach so the two do not overlap
      const cy = Math.min(y1, y2) - 60;
      d = `M${x1},${y1} Q${lx},${cy} ${x2},${y2}`; ly = (y1 + y2) / 4 + cy / 2 - 14;
    } else { d = `M${x1},${y1} L${x2},${y2}`; ly += 18; }
    out += `<path class="seg" id="seg-${i}" d="${d}"/>`;
    const side = vertical ? ` data-side="${x1 < W / 2 ? -1 : 1}" data-col="${x1}"` : "";
    labels.push(`<g class="edit" id="edit-${i}" data-seg="${i}"${side}><rect x="${lx - 86}" y="${ly - 17}" width="172" height="34"/>
      <text x="${lx}" y="${ly + 5}" text-anchor="middle">${i + 1} ${PNP_SEGMENTS[i]} ✎</text></g>`);
  }
  pts.forEach((p) => { out += `<circle class="pt" cx="${X(p)}" cy="${Y(p)}" r="3.5"/>`; });
  out += `<polyline class="trail" id="pnp-trail" points=""/><circle class="tcp" id="pnp-tcp" r="5" cx="-20" cy="-20"/>`;
  out += labels.join("");
  const bar = step, bx = W - 12 - bar * s, by = H - 6;              // scale bar and axes, bottom
  out += `<path class="scale" d="M${bx},${by - 5} V${by} H${W - 12} V${by - 5}"/>
    <text class="axis" x="${W - 12}" y="${by - 8}" text-anchor="end">${bar} mm</text>
    <text class="axis" x="6" y="${by}">Side ${axis}→ Z↑ (mm, base frame) · grid ${step} mm</text>`;
  svg.innerHTML = out;
  /* each name's box as wide as its text; a column's names beside the column, clear of its two paths (a 172 px box
     centred 78 px out covered them), and every box inside the drawing (at 800x480 "2 Pick" was cut at its edge) */
  for (const g of svg.querySelectorAll(".edit")) {
    const text = g.querySelector("text"), rect = g.querySelector("rect");
    const w = Math.ceil(text.getComputedTextLength()) + 24;
    let cx = g.dataset.side ? Number(g.dataset.col) + Number(g.dataset.side) * (w / 2 + 14) : Number(text.getAttribute("x"));
    cx = Math.min(W - w / 2 - 2, Math.max(w / 2 + 2, cx));
    text.setAttribute("x", String(cx));
    rect.setAttribute("x", String(cx - w / 2));
    rect.setAttribute("width", String(w));
  }
  svg.dataset.axes = `${axis}-Z`;
  for (const g of svg.querySelectorAll(".edit")) g.onclick = () => openSegment(Number(g.dataset.seg));
  updatePnP();
}

/* dynamic part: segment in progress and the TCP trail, updated in place at every poll */
function updatePnP() {
  if (!pnpGeometry) return;
  const { X, Y } = pnpGeometry;
  const state = pnpState();
  const active = state === "Running" || state === "Stopping" ? live.values.PnP_Segment : -1;
  for (let i = 0; i < 6; i++) {
    document.getElementById(`seg-${i}`).classList.toggle("active", i === active);
    document.getElementById(`edit-${i}`).classList.toggle("active", i === active);
  }
  /* the trail's points are worked out again only when the server sent new ones (robotview.js, VIEW.trailSeq) */
  const trail = document.getElementById("pnp-trail");
  if (pnpTrailShown.el !== trail || pnpTrailShown.seq !== VIEW.trailSeq) {     // drawPnP makes a new polyline
    const pts = VIEW.trail.map(([x, y, z]) => ({ X: x, Y: y, Z: z }));
    setAttr(trail, "points", pts.map((p) => `${X(p)},${Y(p)}`).join(" "));
    pnpTrailShown = { el: trail, seq: VIEW.trailSeq };
  }
  const tcp = live.values.ReadPos_Valid && live.values.ReadPos_Position ? live.values.ReadPos_Position.TCP : null;
  if (tcp) {
    const dot = document.getElementById("pnp-tcp");
    setAttr(dot, "cx", X(tcp)); setAttr(dot, "cy", Y(tcp));
  }
}

function openSegment(i) {
  const dialog = document.getElementById("seg-dialog"), body = document.getElementById("seg-body");
  const root = `PnP_MoveParameters[${i}]`;
  body.innerHTML = "";
  buildStruct(body, root, MAP.variables.PnP_MoveParameters.type, "Motion Settings");
  fillFrom(body, root, pnpParams[i]);
  watchLimits(body, root);
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
  uncutLabels(body);                  // laid out only now that the dialog is open
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
  /* Start and Reset are rising edges (/api/execute); the message says what the PLC made of them */
  const edge = async (variable, what, expect) => {
    message(`${what} …`);
    try {
      await api("/api/execute", { execute: variable });
      if (live.kick) live.kick();
      const firstPoll = live.polls + 2;
      const check = () => {
        if (live.polls < firstPoll) { setTimeout(check, POLL_MS); return; }
        const { state, text } = pnpOptions();
        if (expect.includes(state))
          message(`${what}: the cycle is ${state}. ${state === "Running" ? "" : text}`.trim());
        else message(`${what} not taken: ${text}`, "error");
      };
      setTimeout(check, POLL_MS);
    } catch (e) { message(`${what}: ${e.message}`, "error"); }
  };
  document.getElementById("btn-execute").onclick = () => edge("PnP_Example_Execute", "Start", ["Running"]);
  document.getElementById("btn-reset").onclick = () => edge("PnP_Reset", "Reset", ["Idle"]);
  document.getElementById("btn-stop").onclick = async () => {
    try {
      await api("/api/write", { values: { PnP_Example_Execute: false } });
      message("End Cycle: the robot finishes the current segment, then the cycle is Idle.");
    } catch (e) { message("End Cycle: " + e.message, "error"); }
  };
  const control = (cmd, what) => executeCommand("ProgramControl_Execute", { "ProgramControl_Param.Command": cmd }, what)
    .then((sent) => sent && watchResult("ProgramControl", what, what === "Pause" ? "the robot holds its path." : "the robot continues."));
  for (const [id, variable] of [["btn-preset", "PnP_MoveParameters[0].Speed"], ["btn-pause", "ProgramControl_Execute"],
    ["btn-resume", "ProgramControl_Execute"]]) document.getElementById(id).disabled = !mayWrite(variable);
  document.getElementById("btn-pause").onclick = () => control(MAP.types.eCBT_PrgControlCmd.enum.Pause, "Pause");
  document.getElementById("btn-resume").onclick = () => control(MAP.types.eCBT_PrgControlCmd.enum.Resume, "Resume");
  live.listeners.push(updatePnP, showPnPState, fetchTrail);
  window.addEventListener("resize", drawPnP);
  document.getElementById("pnp-side").onclick = () => { toggleSideAxis(); drawPnP(); };
  try { await loadPnP(); } catch (e) { message("Cannot read the PnP parameters: " + e.message, "error"); }
  startPolling(["PnP_Example_Execute", "PnP_State", "PnP_OutcomeUnknown", "PnP_Segment", "PnP_Waiting", "PnP_GripperClosed", "PnP_CycleCount", "PnP_MoveBusy",
    "PnP_MoveActive", "PnP_MoveError", "PnP_MoveErrorID", "PnP_MoveErrorDescrip", "PnP_Move_CmdID_Ack",
    "ProgramControl_Busy", "ProgramControl_Done", "ProgramControl_Error", "ProgramControl_ErrorID",
    "ProgramControl_CommandAborted", "ProgramControl_ErrorDescrip", "Connect_Execute", "Connect_Connected", "ReadPos_Valid",
    "ReadPos_Position", ...ROBOT_STATUS]);
}
