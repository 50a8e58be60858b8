/* CBT HMI: limits and hints that follow the selected data format. The ranges are the library's own (src/cbt_hmi/pages/ranges.json,
   generated from docs/library/ranges.tsv; the server merges them into the variable table it serves), so a value
   the page accepts is one the FB accepts, and a data format the FB refuses for the motion command is refused
   here with the same ErrorID. */
"use strict";

/* The address of a data file the page shell preloads (errors.json, tm5_700.json): the server names it with its
   version (cbt_hmi/web/assets.py), so the browser keeps it until the file changes; the plain name without one. Every
   script of the shell uses it; this one is the shell's first. */
function dataFileAddress(name) {
  const link = document.querySelector(`link[rel="preload"][href^="${name}?"]`);
  return link ? link.href : name;
}

/* {DataFormat: "CAP_Abs", MovementCommand: "Line", BlendingEnable: "TRUE", Module: "EndModule"} of a form */
function formContext(root, prefix) {
  const context = {};
  for (const el of inputsUnder(root, prefix)) {
    const key = el.dataset.path.split(".").pop();
    if (el.tagName === "SELECT") context[key] = el.options[el.selectedIndex] ? el.options[el.selectedIndex].text : "";
    else if (el.type === "checkbox") context[key] = el.checked ? "TRUE" : "FALSE";
  }
  return context;
}

const holds = (when, context) => Object.entries(when || {}).every(([k, vs]) => vs.includes(context[k]));

/* the range that applies now: {min, max, unit, error}; null when the FB does not check the value in this
   situation (e.g. Blending with blending off); the plain min/max for values without conditions */
function applicableRange(spec, context) {
  if (!spec.ranges) return spec.min === undefined ? null : { min: spec.min, max: spec.max, unit: spec.unit || "" };
  const hit = spec.ranges.find((r) => holds(r.when, context));
  if (!hit) return null;
  return { ...hit, unit: hit.unit === "—" ? "" : hit.unit };
}

function rangeHint(spec, context) {
  if (spec.allowed) return "";
  const r = applicableRange(spec, context);
  if (r) return `${r.min === -r.max ? "±" + r.max : r.min + ".." + r.max}${r.unit ? " " + r.unit : ""}`;
  if (spec.ranges) {
    const off = Object.keys(spec.ranges[0].when).find((k) => context[k] === "FALSE");
    return off ? `${off.replace(/Enable$/, "").toLowerCase()} off` : "";      // the FB does not check it
  }
  return spec.unit || "";
}

/* a format the FB refuses for this motion command: the error text, else null */
function refusedCombination(spec, value, context, name) {
  if (!spec.allowed) return null;
  const rule = spec.allowed.find((r) => holds(r.when, context));
  if (!rule || rule.allowed.includes(value)) return null;
  const [key, vals] = Object.entries(rule.when)[0];
  return `${name}: ${value} cannot be used with ${LABELS[key] || key} ${vals.join("/")} — ` +
    `${vals.join("/")} takes ${rule.allowed.join(", ")} (the FB would refuse it with ${rule.error})`;
}

/* hints and the refused-combination mark of every field of a form, after any change of a selection */
function refreshLimits(root, prefix) {
  const context = formContext(root, prefix);
  for (const el of inputsUnder(root, prefix)) {
    const spec = leafSpec(el.dataset.path);
    if (!spec || spec.type === "BOOL") continue;
    const hint = el.parentElement.querySelector(".hint");
    if (hint) hint.textContent = rangeHint(spec, context);
    if (spec.allowed) {
      const value = el.options[el.selectedIndex].text;
      const bad = refusedCombination(spec, value, context, LABELS.DataFormat);
      el.classList.toggle("invalid", Boolean(bad));
      el.title = bad || "";
      const rule = spec.allowed.find((r) => holds(r.when, context));
      if (hint) hint.textContent = bad ? `not for ${Object.values(rule.when)[0]}` : "";     // ErrorID in the title
    }
  }
  refreshPoseLimits(root, prefix);
}

function watchLimits(root, prefix) {
  root.addEventListener("change", (e) => { if (e.target.tagName === "SELECT" || e.target.type === "checkbox") refreshLimits(root, prefix); });
  refreshLimits(root, prefix);
  armReady.then(() => refreshLimits(root, prefix));          // the joint ranges come with the arm data
}

/* ---- per-unit limits and the reach check: what the TM5-700 can do, beyond the FB's own ranges ----
   The FB checks every pose member against one range (±100000, docs/library/ranges.tsv) whatever its unit; the
   page also knows the unit: an angle (RX, RY, RZ) beyond one turn, ±360°, is a typing slip (our choice: TMflow
   shows orientations within ±180°); in a joint format the six values are J1..J6, each within its joint range
   from the arm data (src/cbt_hmi/pages/tm5_700.json, ±2 × the range for joint offsets); millimetres are judged by the reach
   check on the whole pose (robotview.js reachCheck). */
const POSE_KEYS = ["X", "Y", "Z", "RX", "RY", "RZ"];
const ANGLE_LIMIT = 360;
const poseLabel = (member) => (LABELS[member] || member).replace(/ \(.*\)$/, "");

/* {min, max, unit, what} for a pose member in the selected data format, null where only the FB's range holds */
function unitLimit(member, key, context) {
  if (!["TargetPosition", "ArcPoint", "EndPoint"].includes(member)) return null;
  const fmt = context.DataFormat || "";
  if (fmt.startsWith("J")) {
    if (!ARM.data) return null;
    const j = ARM.data.joints[POSE_KEYS.indexOf(key)], lim = fmt.endsWith("_Rel") ? 2 * j.limit : j.limit;
    return { min: -lim, max: lim, unit: "°", what: `${j.name}${fmt.endsWith("_Rel") ? " offset" : ""}` };
  }
  if (key.startsWith("R")) return { min: -ANGLE_LIMIT, max: ANGLE_LIMIT, unit: "°", what: key };
  return null;
}

/* the legend of each pose row says what its six values are and their limits in the selected format */
function refreshPoseLimits(root, prefix) {
  const context = formContext(root, prefix);
  for (const fs of root.querySelectorAll("fieldset.pose")) {
    const member = fs.dataset.member, span = fs.querySelector("legend .range");
    const joint = (context.DataFormat || "").startsWith("J");
    const limits = POSE_KEYS.map((k) => unitLimit(member, k, context));
    for (const [i, k] of POSE_KEYS.entries()) {
      const el = fs.querySelector(`[data-path$=".${member}.${k}"]`), box = el && el.parentElement;
      const label = box && box.querySelector("label");
      if (label) label.textContent = joint && limits[i] ? limits[i].what.split(" ")[0] : k;
      if (el) el.title = limits[i] ? `${limits[i].what}: ${limits[i].min}..${limits[i].max}${limits[i].unit}` : `${k}: mm, reach-checked`;
    }
    if (!span || !limits[0] && !limits[3]) continue;
    span.textContent = joint ? `joints, ° (${limits.map((l) => "±" + l.max).join(" ")})` :
      `mm (reach-checked) · RX RY RZ ±${ANGLE_LIMIT}°`;
  }
}

/* Everything the robot itself would refuse in a motion form that the FB's ranges let through: an angle or joint
   out of its range, a target the TM5-700 cannot reach. The text (null when all is well); marks the fields. */
function physicalRefusal(root, prefix) {
  if (typeof motionTargets !== "function" || !prefix) return null;
  const context = formContext(root, prefix);
  for (const el of inputsUnder(root, prefix)) {
    const parts = el.dataset.path.split("."), key = parts.pop(), member = parts.pop();
    if (!POSE_KEYS.includes(key)) continue;
    const lim = unitLimit(member, key, context), v = Number(el.value);
    if (lim && Number.isFinite(v) && (v < lim.min || v > lim.max)) {
      el.classList.add("invalid");
      return `${poseLabel(member)} ${lim.what}: ${v}${lim.unit} is out of range ` +
        `${lim.min}..${lim.max}${lim.unit} for the ${ARM.data ? ARM.data.model : "robot"}`;
    }
  }
  const refused = reachRefusal(motionTargets(root, prefix));
  if (!refused) return null;
  for (const k of ["X", "Y", "Z"]) {
    const el = root.querySelector(`[data-path="${prefix}.${refused.member}.${k}"]`);
    if (el) el.classList.add("invalid");
  }
  return `${poseLabel(refused.member)}: ${refused.reason}`;
}
