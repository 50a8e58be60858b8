/* CBT HMI: the Jog/Teach page (examples/JogTeach_Example.st). Hold-to-run buttons jog one joint or one axis of
   the base or tool frame with CBT_Jog; Teach stores the robot's position with CBT_Teach into an entry of the
   PLC's TeachTable. The page holds Jog_Forward / Jog_Backward only while a button is pressed and counts Jog_Beat
   up every JOG_BEAT_MS meanwhile: the PLC releases the jog by itself when the beat stops (a browser or a network
   that dies with the button held), so the page's timing is never what stops the robot. */
"use strict";

const JOG_BEAT_MS = 50;                                   // the PLC's watchdog: 300 ms without a beat
const JOG_FRAMES = ["JogJoint", "JogBase", "JogTool"];     // eCBT_JogFrame, in its order
const JOG_AXES = { JogJoint: ["J1", "J2", "J3", "J4", "J5", "J6"], JogBase: ["X", "Y", "Z", "RX", "RY", "RZ"],
  JogTool: ["X", "Y", "Z", "RX", "RY", "RZ"] };
const JOG_UNITS = { JogJoint: "°", JogBase: "mm, °", JogTool: "mm, °" };
const JOG_VARS = ["Jog_Forward", "Jog_Backward", "Jog_Frame", "Jog_Axis", "Jog_Velocity", "Jog_Busy", "Jog_Active",
  "Jog_Done", "Jog_Error", "Jog_ErrorID", "Jog_ErrorDescrip", "Jog_Dropped", "Teach_Execute", "Teach_Index",
  "Teach_Name", "Teach_Busy", "Teach_Done", "Teach_Error", "Teach_ErrorID", "Teach_ErrorDescrip", "TeachTable"];
const JOG_STYLE = `
.jog { display: grid; grid-template-columns: 380px 1fr; gap: 10px; flex: 1; align-content: start; }
.jog fieldset { border: 1px solid #8895a3; border-radius: 4px; padding: 4px 8px; margin: 0 0 6px 0; }
.jog .frames button { min-width: 70px; height: 36px; }
.jog .frames button[aria-pressed="true"] { background: #3c4650; color: #fff; font-weight: bold; }
.jog .axes { display: grid; grid-template-columns: 60px 90px 90px 1fr; gap: 4px 8px; align-items: center; }
.jog .axes button { height: 36px; font-size: 18px; touch-action: none; user-select: none; }
.jog .axes button.held { background: #3c4650; color: #fff; }
.jog .indicators { grid-template-columns: repeat(4, minmax(0, 1fr)); }
.jog .teach-row { display: flex; gap: 6px; align-items: center; margin-bottom: 4px; }
.jog .teach-row input, .jog .teach-row select { height: 34px; font-size: 14px; }
.jog input:disabled { background: #e3e7eb; color: #44505c; border: 1px dashed #8a96a2; cursor: not-allowed; }
.jog .points-box { max-height: 276px; overflow-y: auto; }
.jog table.points { border-collapse: collapse; font-size: 14px; width: 100%; }
.jog table.points td { border-bottom: 1px solid #d5dbe1; padding: 1px 4px; }
.jog table.points tr.sel { outline: 2px solid #2368a8; }`;

const jog = { frame: "JogBase", held: null, beat: 0, timer: null };

async function jogWrite(values) {
  await api("/api/write", { values });
  if (live.kick) live.kick();
}

/* pressed: hold the direction (with the frame, axis and speed the PLC latches at the press) and keep beating */
async function jogPress(button) {
  if (jog.held) return;
  const velocity = Number(document.getElementById("jog-velocity").value);
  if (!Number.isInteger(velocity) || velocity < 1 || velocity > 100) {
    message("Jog speed: enter 1..100 %.", "error");
    return;
  }
  jog.held = button;
  button.classList.add("held");
  const input = button.dataset.dir === "+" ? "Jog_Forward" : "Jog_Backward";
  jog.timer = setInterval(() => { jog.beat = (jog.beat + 1) % 4294967296;
    api("/api/write", { values: { Jog_Beat: jog.beat } }).catch(() => {}); }, JOG_BEAT_MS);
  try {
    await jogWrite({ Jog_Frame: JOG_FRAMES.indexOf(jog.frame), Jog_Axis: Number(button.dataset.axis),
      Jog_Velocity: velocity, Jog_Beat: jog.beat, [input]: true });
    message(`Jogging ${JOG_AXES[jog.frame][button.dataset.axis - 1]}${button.dataset.dir} while the button is held …`);
  } catch (e) {
    message(`Jog: ${e.message}`, "error");
    jogRelease();
  }
}

/* released (or the pointer left the button, the page was hidden): both directions FALSE at once */
async function jogRelease() {
  if (!jog.held) return;
  jog.held.classList.remove("held");
  jog.held = null;
  clearInterval(jog.timer);
  try { await jogWrite({ Jog_Forward: false, Jog_Backward: false }); }
  catch (e) { message(`Jog: ${e.message}; the PLC stops the jog by itself when the page's beat stops.`, "error"); }
}

function jogAxes() {
  const axes = document.getElementById("jog-axes");
  axes.innerHTML = "";
  JOG_AXES[jog.frame].forEach((name, i) => {
    const label = document.createElement("b");
    label.textContent = name;
    axes.append(label);
    for (const dir of ["-", "+"]) {
      const b = document.createElement("button");
      b.type = "button";
      b.id = `jog-${i + 1}${dir === "+" ? "p" : "m"}`;
      b.dataset.axis = String(i + 1);
      b.dataset.dir = dir;
      b.textContent = `${name} ${dir === "+" ? "+" : "−"}`;
      b.disabled = !mayWrite("Jog_Forward");
      b.addEventListener("pointerdown", (ev) => { ev.preventDefault(); b.setPointerCapture(ev.pointerId); jogPress(b); });
      for (const end of ["pointerup", "pointercancel", "lostpointercapture"]) b.addEventListener(end, jogRelease);
      axes.append(b);
    }
    const now = document.createElement("span");
    now.dataset.jogNow = String(i);
    axes.append(now);
  });
  document.getElementById("jog-unit").textContent = JOG_UNITS[jog.frame];
  for (const b of document.querySelectorAll(".frames button"))
    b.setAttribute("aria-pressed", String(b.dataset.frame === jog.frame));
}

function jogShow() {
  const v = live.values, pos = v.ReadPos_Position, valid = live.online && v.ReadPos_Valid === true;
  for (const cell of document.querySelectorAll("[data-jog-now]")) {
    const i = Number(cell.dataset.jogNow);
    let text = "####";
    if (valid && pos) text = jog.frame === "JogJoint" ? pos.Joints[i].toFixed(2) :
      pos.TCP[["X", "Y", "Z", "RX", "RY", "RZ"][i]].toFixed(2);
    setText(cell, text);                          // every write compares first (hmi.js, setText …)
  }
  const table = v.TeachTable, body = document.getElementById("teach-points");
  if (Array.isArray(table) && body) {
    const index = Number(document.getElementById("teach-index").value);
    table.forEach((p, i) => {
      const row = body.rows[i];
      const text = p.Taught ? `${p.Name}|${["X", "Y", "Z"].map((k) => p.Pose[k].toFixed(1)).join(", ")}` : "—|";
      if (row.dataset.text !== text) {
        row.dataset.text = text;
        const [name, xyz] = text.split("|");
        setText(row.cells[1], name);
        setText(row.cells[2], xyz);
      }
      row.classList.toggle("sel", i + 1 === index);
    });
  }
  if (v.Jog_Error === true && jog.shownError !== v.Jog_ErrorID) {
    jog.shownError = v.Jog_ErrorID;
    message(errorMessage("Jog", v, "Jog"), "error");
  } else if (v.Jog_Error !== true) jog.shownError = null;
  if (v.Jog_Dropped === true && !jog.dropShown) {
    jog.dropShown = true;
    message("Jog: the PLC stopped the jog because this page stopped answering; press the button again.", "error");
  } else if (v.Jog_Dropped !== true) jog.dropShown = false;
}

async function teachPress() {
  const index = Number(document.getElementById("teach-index").value);
  const name = document.getElementById("teach-name").value.trim();
  if (!name) { message("Teach: type a name for the point first.", "error"); return; }
  if (await executeCommand("Teach_Execute", { Teach_Index: index, Teach_Name: name }, "Teach"))
    releaseWhenFinished("Teach", "Teach", `point ${index} '${name}' holds the robot's position`);
}

/* A taught point becomes the target of Move Absolute or of a PnP segment: its TCP pose, or its joint angles when
   that target is in the joint format (JPP_Abs = 0); the move itself is started on its own page. */
const TEACH_TARGETS = [["MoveAbs_Param", "Move Absolute"],
  ...Array.from({ length: 6 }, (_, k) => [`PnP_MoveParameters[${k}]`, `PnP segment ${k + 1}`])];

async function teachUse() {
  const index = Number(document.getElementById("teach-index").value);
  const select = document.getElementById("teach-use-target");
  const root = select.value, label = select.selectedOptions[0].textContent;
  const point = (live.values.TeachTable || [])[index - 1];
  if (!point || point.Taught !== true) {
    message(`Use point ${index}: the point is not taught yet; teach it first.`, "error");
    return;
  }
  const name = root.split("[")[0];
  try {
    const now = (await readVars([name])).values[name];
    const param = root.includes("[") ? now[Number(root.match(/\[(\d+)\]/)[1])] : now;
    const joints = param.DataFormat === 0 || param.DataFormat === "JPP_Abs";     // read as a number or a name
    const values = {};
    ["X", "Y", "Z", "RX", "RY", "RZ"].forEach((k) => {
      values[`${root}.TargetPosition.${k}`] = joints ? point.Joints[k] : point.Pose[k];
    });
    await api("/api/write", { values });
    message(`Use point ${index} '${point.Name}': now the target of ${label} (${joints ? "joint angles" : "TCP pose"}); ` +
            "start the move on its page.", "ok");
  } catch (e) { message(`Use point ${index}: ${e.message}`, "error"); }
}

function jogPage() {
  const main = frame("Jog / Teach", false);
  const style = document.createElement("style");
  style.textContent = JOG_STYLE;
  document.head.append(style);
  const options = Array.from({ length: 16 }, (_, i) => `<option value="${i + 1}">${i + 1}</option>`).join("");
  const rows = Array.from({ length: 16 }, (_, i) => `<tr><td>${i + 1}</td><td></td><td></td></tr>`).join("");
  main.innerHTML = `<div class="jog">
    <div><fieldset><legend>Frame</legend><div class="frames">
      ${JOG_FRAMES.map((f) => `<button type="button" id="jog-frame-${f}" data-frame="${f}">${f.slice(3)}</button>`).join("")}
      </div></fieldset>
      <fieldset><legend>Hold to jog (<span id="jog-unit"></span>) — speed
        <input id="jog-velocity" type="number" min="1" max="100" step="1" value="10" style="width:64px;height:34px;font:inherit"> %</legend>
        <div class="axes" id="jog-axes"></div></fieldset>
      <div class="indicators"><span data-status="Jog_Busy" class="lamp active">Busy</span>
        <span data-status="Jog_Active" class="lamp active">Moving</span>
        <span data-status="Jog_Error" class="lamp error">Error</span>
        <span data-status="Robot_Stopping" class="lamp stopping">Stopping</span></div></div>
    <div><fieldset><legend>Teach the robot's position</legend><div class="teach-row">
      Point <select id="teach-index">${options}</select>
      <input id="teach-name" maxlength="24" placeholder="Name" value="P1" style="width:120px">
      <button type="button" id="btn-teach">Teach</button></div>
      <div class="teach-row">Use it in <select id="teach-use-target">${TEACH_TARGETS.map(([v, t]) =>
        `<option value="${v}">${t}</option>`).join("")}</select>
      <button type="button" id="btn-teach-use">Use as target</button></div>
      <div class="points-box"><table class="points"><tbody id="teach-points">${rows}</tbody></table></div>
      </fieldset></div></div>`;
  for (const b of document.querySelectorAll(".frames button"))
    b.addEventListener("click", () => { if (!jog.held) { jog.frame = b.dataset.frame; jogAxes(); jogShow(); } });
  document.getElementById("btn-teach").addEventListener("click", teachPress);
  document.getElementById("btn-teach").disabled = !mayWrite("Teach_Execute");
  document.getElementById("teach-index").addEventListener("change", jogShow);
  document.getElementById("btn-teach-use").addEventListener("click", teachUse);
  document.getElementById("btn-teach-use").disabled = !mayWrite("MoveAbs_Param.TargetPosition.X");
  // jogging and teaching are commissioning (engineer): their fields are locked like the keys, and the line says why
  document.getElementById("jog-velocity").disabled = !mayWrite("Jog_Velocity");
  document.getElementById("teach-name").disabled = !mayWrite("Teach_Name");
  if (ACCESS.role === "operator")
    message("Jog and Teach are commissioning: they need the engineer address. Use as target works for the operator.");
  window.addEventListener("blur", jogRelease);
  document.addEventListener("visibilitychange", () => { if (document.hidden) jogRelease(); });
  jogAxes();
  live.listeners.push(jogShow);
  startPolling([...JOG_VARS, "ReadPos_Valid", "ReadPos_Position", "Connect_Connected", ...ROBOT_STATUS]);
}
