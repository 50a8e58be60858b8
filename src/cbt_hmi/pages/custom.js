/* Pages for the user's own program, built from their page description files (cbt_hmi/web/pagedesc.py; docs/hmi.md,
   "Pages for your own program"): the inputs as fields with label, unit and limits, the command key, the status
   values. No page-specific JavaScript: everything comes from MAP.custom_pages in the variable table. */
"use strict";

function customLabel(item) { return item.unit ? `${item.label} (${item.unit})` : item.label; }

/* the described inputs of a page as one fieldset of fields with label, unit and limits (a user's page and a
   shipped command page without a parameter structure alike) */
function inputsFieldset(inputs, legend) {
  const fs = document.createElement("fieldset");
  fs.innerHTML = `<legend>${esc(legend)}</legend>`;
  const grid = document.createElement("div");
  grid.className = "grid wide";
  for (const item of inputs) {
    LABELS[item.variable] = item.label;          // error texts name the field as the page does
    grid.append(makeField(item.variable, MAP.variables[item.variable], customLabel(item)));
  }
  fs.append(grid);
  return fs;
}

/* the main page of a table generated from a user program (no CBT example variables): one tile per page */
function customIndexPage() {
  const main = frame("Main", true);
  main.classList.add("custom");
  const area = document.createElement("div");
  area.className = "area custom-index";
  area.innerHTML = "<h2>Pages</h2>";
  const tiles = document.createElement("div");
  tiles.className = "tiles";
  for (const [key, page] of Object.entries(MAP.custom_pages || {})) {
    const a = document.createElement("a");
    a.href = `${key}.html`; a.id = `nav-${key}`; a.textContent = page.title;
    tiles.append(a);
  }
  if (!tiles.children.length) tiles.innerHTML = "<span>No page descriptions were loaded.</span>";
  area.append(tiles);
  main.append(area);
  hideRobotPill();
  startPolling(Object.keys(MAP.variables).slice(0, 1));   // the header's PLC state needs answers to show
}

function hideRobotPill() {                      // a program without the CBT connection has no robot to show
  if (!MAP.variables.Connect_Connected) document.getElementById("pill-robot").hidden = true;
}

async function customPage(key) {
  const page = MAP.custom_pages[key];
  const main = frame(page.title, false);
  main.classList.add("custom");
  hideRobotPill();
  const params = document.createElement("div");
  params.className = "params full";
  if (page.inputs.length) params.append(inputsFieldset(page.inputs, "Settings"));
  const side = document.createElement("div");
  side.className = "side";
  const buttons = document.createElement("div");
  buttons.className = "buttons";
  const names = page.inputs.map((i) => i.variable);
  const send = document.createElement("button");
  send.className = "primary wide";
  if (page.command) {
    send.id = "btn-execute"; send.textContent = page.command.label;
    send.disabled = !mayWrite(page.command.variable);
  } else {
    send.id = "btn-write"; send.textContent = "Write";
    send.disabled = !names.some((n) => mayWrite(n));
  }
  send.onclick = async () => {
    const result = collect(params, "");
    if (result.error) { message(result.error + " — nothing was sent.", "error"); return; }
    try {
      if (page.command) {
        await api("/api/execute", { execute: page.command.variable, values: result.values });
        message(`${page.command.label}: the PLC took the command${names.length ? " with the values shown" : ""}.`);
      } else {
        await api("/api/write", { values: result.values });
        message("Write: the PLC holds the values shown.");
      }
      if (live.kick) live.kick();
    } catch (e) { message(`${send.textContent}: ${e.message}`, "error"); }
  };
  buttons.append(send);
  side.append(buttons);
  if (page.status.length) {
    const table = statusTable("Status", page.status.map((i) => [customLabel(i), i.variable]));
    page.status.forEach((item, i) => {          // an abnormal state's lamp turns red when it is on
      const led = table.querySelectorAll("tr")[i].querySelector(".led");
      if (led && item.abnormal) led.classList.add("bad");
    });
    side.append(table);
  }
  const left = document.createElement("div");
  left.className = "left";
  left.append(params);
  main.append(left, side);
  uncutLabels(params);
  if (names.length) {
    try {
      const data = await readVars(names);
      for (const n of names) setInput(params.querySelector(`[data-path="${n}"]`), data.values[n]);
    } catch (e) { message("Cannot read the current values: " + e.message, "error"); }
  }
  startPolling(page.status.map((i) => i.variable));
}
