/* CBT HMI: limits and hints that follow the selected data format. The ranges are the library's own (hmi/ranges.json,
   generated from docs/library/ranges.tsv; the server merges them into the variable table it serves), so a value
   the page accepts is one the FB accepts, and a data format the FB refuses for the motion command is refused
   here with the same ErrorID. */
"use strict";

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
}

function watchLimits(root, prefix) {
  root.addEventListener("change", (e) => { if (e.target.tagName === "SELECT" || e.target.type === "checkbox") refreshLimits(root, prefix); });
  refreshLimits(root, prefix);
}
