/* CBT HMI – Program page: the running ladder, coloured live like Sysmac Studio's online monitoring.
   The server draws the rungs once (GET /api/program); every poll (GET /api/program/state) names the
   energised elements and wires (class "on") and the current value of every variable drawn. Read only.
   The page adds what a panel needs: a rung list to jump to a rung, zoom, the rung comments whole (wrapped
   over as many lines as they need, where the drawing cuts them), and values that never cover another text
   (a value without room is shortened with "…"; tapping it shows it whole on the message line). */
"use strict";

/* 100 % is the panel's reading size: the drawing is scaled so that its smallest text (pin names and values, 11 px in
   the drawing's own units) reads at 14 px, the body text of the 9-inch panel; 60 % and 80 % are an overview */
const LADDER_ZOOMS = [0.6, 0.8, 1, 1.3, 1.6];
const READING_PX = 14;
const LADDER = { zoom: Number(sessionStorage.getItem("hmi.ladderZoom")) || 1 };
const SVG_NS = "http://www.w3.org/2000/svg";
const COMMENT_LINE = 16;                       // px between two lines of a wrapped rung comment (12 px text)

/* the rung comment `text.cmt` of each rung replaced by the whole comment, wrapped to the drawing's width; the
   rung's contents and every rung below move down by the lines added */
function wrapComments(svg, rungs) {
  const width = Number(svg.getAttribute("width"));
  let added = 0;
  for (const g of svg.querySelectorAll("g.rung")) {
    const top = Number((g.getAttribute("transform").match(/translate\(0 ([-\d.]+)\)/) || [0, 0])[1]);
    if (added) g.setAttribute("transform", `translate(0 ${top + added})`);
    const rung = rungs.find((r) => String(r.number) === g.dataset.rung), cmt = g.querySelector("text.cmt");
    if (!rung || !cmt || !rung.comment) continue;
    const x = Number(cmt.getAttribute("x")), room = width - x - 20;
    const words = rung.comment.replace(/\s+/g, " ").trim().split(" "), lines = [""];
    cmt.textContent = "";
    const probe = document.createElementNS(SVG_NS, "tspan");
    cmt.append(probe);
    for (const w of words) {
      const next = lines[lines.length - 1] ? `${lines[lines.length - 1]} ${w}` : w;
      probe.textContent = next;
      if (probe.getComputedTextLength() > room && lines[lines.length - 1]) lines.push(w);
      else lines[lines.length - 1] = next;
    }
    cmt.textContent = "";
    lines.forEach((line, i) => {
      const t = document.createElementNS(SVG_NS, "tspan");
      t.setAttribute("x", x); t.setAttribute("dy", i ? COMMENT_LINE : 0); t.textContent = line;
      cmt.append(t);
    });
    const extra = (lines.length - 1) * COMMENT_LINE;
    if (!extra) continue;
    const body = document.createElementNS(SVG_NS, "g");         // everything under the header moves down
    body.setAttribute("transform", `translate(0 ${extra})`);
    for (const child of [...g.childNodes]) {
      if (child === cmt || child.classList.contains("num") || child.classList.contains("band") ||
          (child.classList.contains("type") && Number(child.getAttribute("y")) < 20)) continue;
      body.append(child);
    }
    g.append(body);
    const band = g.querySelector("rect.band");
    if (band) band.setAttribute("height", Number(band.getAttribute("height")) + extra);
    added += extra;
  }
  const height = Number(svg.getAttribute("height")) + added;
  svg.setAttribute("height", height);
  svg.setAttribute("viewBox", `0 0 ${width} ${height}`);
  svg.querySelector(":scope > rect").setAttribute("height", height);
  svg.dataset.width = String(width); svg.dataset.height = String(height);
  const sizes = [...svg.querySelectorAll("text")].filter((t) => t.textContent.trim())
    .map((t) => parseFloat(getComputedStyle(t).fontSize)).filter((px) => px > 0);
  svg.dataset.base = String(sizes.length ? READING_PX / Math.min(...sizes) : 1);
}

function applyZoom(holder) {
  for (const svg of holder.querySelectorAll("svg.ld")) {
    const scale = Number(svg.dataset.base) * LADDER.zoom;
    svg.setAttribute("width", (Number(svg.dataset.width) * scale).toFixed(2));
    svg.setAttribute("height", (Number(svg.dataset.height) * scale).toFixed(2));
  }
  document.getElementById("ladder-zoom").textContent = `${Math.round(LADDER.zoom * 100)} %`;
  document.getElementById("ladder-out").disabled = LADDER.zoom === LADDER_ZOOMS[0];
  document.getElementById("ladder-in").disabled = LADDER.zoom === LADDER_ZOOMS[LADDER_ZOOMS.length - 1];
}

const overlaps = (a, b) => a.left < b.right - 0.5 && b.left < a.right - 0.5 && a.top < b.bottom - 0.5 && b.top < a.bottom - 0.5;

/* writes a value, shortened while it would cover a name, a pin, a comment or another value of its rung */
function showValue(t, text, fixed) {
  if (t.dataset.full === text) return;
  t.dataset.full = text;
  setText(t, text);                     // after a scroll or a zoom the value is worked out again, often the same
  if (!text) return;
  const others = fixed.get(t.closest("g.rung"));
  const vals = [...t.closest("g.rung").querySelectorAll("text.val")].filter((v) => v !== t && v.textContent);
  const clash = () => {
    const r = t.getBoundingClientRect();
    return others.some((o) => overlaps(r, o)) || vals.some((v) => overlaps(r, v.getBoundingClientRect()));
  };
  for (let n = text.length - 1; n >= 0 && clash(); n--) t.textContent = text.slice(0, n) + "…";
  if (clash()) t.textContent = "";               // no room at all: the value is on the message line when tapped
}

async function programPage() {
  const main = frame("Ladder Monitor", false);
  main.classList.add("program");
  main.innerHTML = `<div class="ladder-bar"><label for="rung-jump">Rung</label><select id="rung-jump"></select>
    <span class="ladder-zoomctl"><button type="button" id="ladder-out" aria-label="Zoom out" title="Zoom out">−</button>
    <span id="ladder-zoom"></span><button type="button" id="ladder-in" aria-label="Zoom in" title="Zoom in">+</button></span></div>
    <div class="ladder" id="ladder" tabindex="0"></div>`;
  const holder = document.getElementById("ladder"), jump = document.getElementById("rung-jump");
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
    section.innerHTML = `<h2>${esc(p.pou)} <span>(${esc(p.instance)})</span></h2>` + p.svg;
    holder.append(section);
    wrapComments(section.querySelector("svg"), p.rungs);
    for (const r of p.rungs) {
      const text = `${programs.length > 1 ? p.pou + " " : ""}${r.number}${r.label ? " " + r.label + ":" : ""}` +
        `${r.comment ? " – " + r.comment.replace(/\s+/g, " ") : ""}`;
      jump.add(new Option(text.length > 70 ? text.slice(0, 69) + "…" : text, `${p.pou}:${r.number}`));
    }
  }
  if (!ZOOM_OK()) LADDER.zoom = 1;
  applyZoom(holder);
  jump.onchange = () => {
    const [pou, n] = jump.value.split(":");
    const g = holder.querySelector(`section[data-pou="${pou}"] g.rung[data-rung="${n}"]`);
    // client rectangles are in screen pixels, scrollTop in the panel's: the panel is drawn larger from 1280x800
    const zoom = parseFloat(getComputedStyle(document.querySelector(".panel")).zoom) || 1;
    if (g) holder.scrollTop += (g.getBoundingClientRect().top - holder.getBoundingClientRect().top) / zoom - 30;
  };
  const zoomBy = (d) => {
    const g = holder.querySelector(`g.rung[data-rung="${jump.value.split(":")[1]}"]`);
    LADDER.zoom = LADDER_ZOOMS[Math.max(0, Math.min(LADDER_ZOOMS.length - 1, LADDER_ZOOMS.indexOf(LADDER.zoom) + d))];
    sessionStorage.setItem("hmi.ladderZoom", String(LADDER.zoom));
    applyZoom(holder);
    for (const t of holder.querySelectorAll("text.val")) delete t.dataset.full;    // room changes with the zoom
    fixed = fixedTexts();
    if (g) jump.onchange();
  };
  document.getElementById("ladder-out").onclick = () => zoomBy(-1);
  document.getElementById("ladder-in").onclick = () => zoomBy(1);
  holder.addEventListener("click", (e) => {                 // a shortened value, whole on the message line
    const t = e.target.closest && e.target.closest("text.val");
    if (t && t.dataset.full) message(`${t.dataset.var} = ${t.dataset.full}`);
  });
  /* the texts that do not change, per rung, for the values to keep clear of */
  const fixedTexts = () => new Map([...holder.querySelectorAll("g.rung")].map((g) => [g,
    [...g.querySelectorAll("text:not(.val)")].filter((t) => t.textContent).map((t) => t.getBoundingClientRect())]));
  let fixed = fixedTexts();
  message(`${programs.map((p) => p.pou).join(", ")}: monitoring. Green = energised.`);
  startPolling(["Connect_Connected"]);
  async function refresh() {
    for (const section of holder.querySelectorAll("section")) {
      try {
        const state = await api("/api/program/state?pou=" + encodeURIComponent(section.dataset.pou));
        const on = new Set(state.on);
        for (const el of section.querySelectorAll("[data-id]")) el.classList.toggle("on", on.has(el.dataset.id));
        if (section.dataset.scrolled !== String(holder.scrollTop)) {     // the boxes move with the scrolling
          fixed = fixedTexts(); section.dataset.scrolled = String(holder.scrollTop);
          for (const t of section.querySelectorAll("text.val")) delete t.dataset.full;
        }
        for (const t of section.querySelectorAll("text.val")) {
          const v = state.values[t.dataset.var];
          showValue(t, v === undefined ? "" : String(v), fixed);
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

const ZOOM_OK = () => LADDER_ZOOMS.includes(LADDER.zoom);
