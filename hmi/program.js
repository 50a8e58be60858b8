/* CBT HMI – Program page: the running ladder, coloured live like Sysmac Studio's online monitoring.
   The server draws the rungs once (GET /api/program); every poll (GET /api/program/state) names the
   energised elements and wires (class "on") and the current value of every variable drawn. Read only. */
"use strict";

async function programPage() {
  const main = frame("Program – Ladder Monitor", false);
  main.classList.add("program");
  main.innerHTML = `<div class="ladder" id="ladder" tabindex="0"></div>`;
  const holder = document.getElementById("ladder");
  let programs;
  try {
    programs = (await api("/api/program")).programs;
  } catch (e) {
    message("Cannot load the ladder program: " + e.message, "error");
    return;
  }
  if (!programs.length) {
    holder.textContent = "The PLC runs no ladder (LD) program.";
    return;
  }
  for (const p of programs) {
    const section = document.createElement("section");
    section.dataset.pou = p.pou;
    section.innerHTML = `<h2>${p.pou} <span>(${p.instance})</span></h2>` + p.svg;
    holder.append(section);
  }
  message(`${programs.map((p) => p.pou).join(", ")}: monitoring. Green = energised.`);
  startPolling(["Connect_Connected"]);
  async function refresh() {
    for (const section of holder.querySelectorAll("section")) {
      try {
        const state = await api("/api/program/state?pou=" + encodeURIComponent(section.dataset.pou));
        const on = new Set(state.on);
        for (const el of section.querySelectorAll("[data-id]")) el.classList.toggle("on", on.has(el.dataset.id));
        for (const t of section.querySelectorAll("text.val")) {
          const v = state.values[t.dataset.var];
          t.textContent = v === undefined ? "" : v;
        }
        section.dataset.polls = String(Number(section.dataset.polls || 0) + 1);
      } catch (e) {
        message("Monitoring stopped: " + e.message, "error");
      }
    }
    setTimeout(refresh, POLL_MS);
  }
  refresh();
}
