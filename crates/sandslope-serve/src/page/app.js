"use strict";
// The explorer page of `sandslope serve` (docs/serve.md). Every number comes from the server:
// /api/<command> answers exactly what `sandslope <command> --json` prints for the same flags,
// /data/... gives what the charts need beyond that. The charts are drawn here, on SVG and
// canvas, in the colours of the command line's figures: the server writes the palette
// (crates/sandslope-render/src/figures/palette.rs) into style.css as custom properties on
// :root (--sinkage, --route-time, --figure-ink, ...), read here as #rrggbb; no colour is
// written in this file (a test in page.rs holds it so). Nothing is loaded from anywhere but
// this server.

const palette = (name) => getComputedStyle(document.documentElement).getPropertyValue(`--${name}`).trim();
const CODES = ["sinkage", "slippage", "metastable", "success"];
const COLOURS = Object.fromEntries(CODES.map((c) => [c, palette(c)]));
const ROUTE_ORDER = ["time", "risk", "distance"];
const ROUTE_COLOURS = Object.fromEntries(ROUTE_ORDER.map((r) => [r, palette(`route-${r}`)]));
const SIM_COLOURS = Object.fromEntries(
  ["sand", "sand-surface", "data", "closed-form", "tripod-a", "tripod-b", "not-success", "model"].map((r) => [r, palette(r)]),
);
// The charts' own marks, by the figures' roles: black axes and markers (--figure-ink) on white
// (--paper), the light grid lines, the page's rules and ink, the terrain's star, nodata.
const INK = palette("figure-ink");
const PAPER = palette("paper");
const GRID = palette("grid");
const RULE = palette("page-rule");
const STAR = palette("star");
const rgbOf = (hex) => [1, 3, 5].map((i) => parseInt(hex.slice(i, i + 2), 16));
const hexOf = (rgb) => `#${rgb.map((v) => Math.round(v).toString(16).padStart(2, "0")).join("")}`;
const NODATA = rgbOf(palette("nodata"));
// The risk map's colour map (`risk --map`, plotters' viridis), by its stops --p-fail-0, ...
const P_FAIL_STOPS = [];
for (let k = 0; palette(`p-fail-${k}`); k++) P_FAIL_STOPS.push(rgbOf(palette(`p-fail-${k}`)));
// The robot quantities a request may set (parameter -> robot-file key), from the library's
// table of robot keys as /data/served lists it; filled by start().
const ROBOT_FLAGS = [];
const SPEC_KEYS = {};
const SVGNS = "http://www.w3.org/2000/svg";
const $ = (id) => document.getElementById(id);
const pageUrl = new URLSearchParams(location.search);

// ---- the page log: errors, and every URL the page loaded (read by the browser tests) ----
const errors = [];
function logError(message) {
  errors.push(String(message));
  $("log-errors").textContent = errors.join("\n");
}
window.addEventListener("error", (e) => logError(`error: ${e.message}`));
window.addEventListener("unhandledrejection", (e) => logError(`unhandled: ${e.reason && (e.reason.stack || e.reason)}`));
document.addEventListener("securitypolicyviolation", (e) => logError(`blocked: ${e.blockedURI}`));
function logResources() {
  $("log-resources").textContent = performance.getEntriesByType("resource").map((r) => r.name).join("\n");
}

// ---- requests ----
class RequestError extends Error {
  constructor(message, field) {
    super(message);
    this.field = field;
  }
}
let inFlight = 0;
function busy(delta) {
  inFlight += delta;
  document.body.dataset.busy = String(inFlight);
}
function query(params) {
  return new URLSearchParams(params).toString();
}
async function get(path, params) {
  const q = params ? query(params) : "";
  busy(1);
  try {
    const response = await fetch(q ? `${path}?${q}` : path);
    const body = await response.json();
    if (!response.ok) throw new RequestError(body.error || response.statusText, body.field);
    return body;
  } finally {
    busy(-1);
  }
}
// Draws the answer to the latest request of `key` only; a bad input is shown in the status
// line (it is the user's to fix), anything else is a page error.
const tickets = {};
const statuses = {};
// One bad input refuses every request that carries it (predict, sweep and phase for ?mass=1200):
// the banner shows each distinct message once, one per line. #tabs' data-rows counts the rows the
// tab buttons take (read by the browser tests: 1, however long the message).
function setStatus(key, text) {
  statuses[key] = text;
  $("status").textContent = [...new Set(Object.values(statuses).filter(Boolean))].join("\n");
  countTabRows();
}
function countTabRows() {
  const tops = [...document.querySelectorAll("#tabs button")].filter((b) => !b.hidden).map((b) => b.offsetTop);
  $("tabs").dataset.rows = String(new Set(tops).size);
}
window.addEventListener("resize", countTabRows);
async function fresh(key, fetcher, draw) {
  const ticket = (tickets[key] = (tickets[key] || 0) + 1);
  try {
    const data = await fetcher();
    if (ticket !== tickets[key]) return;
    setStatus(key, "");
    draw(data);
  } catch (e) {
    if (ticket !== tickets[key]) return;
    if (e instanceof RequestError) setStatus(key, e.message);
    else logError(`${key}: ${e.stack || e}`);
  } finally {
    logResources();
  }
}
const timers = {};
function soon(key, fn, ms = 80) {
  clearTimeout(timers[key]);
  timers[key] = setTimeout(fn, ms);
}

// ---- state ----
const state = {
  served: null,
  causes: {},
  outcomes: {},
  defaults: {},
  level: null, // the served terrain at 0 deg: fixes the phase diagram's axes
  sweep: null,
  phase: null,
  point: null,
  visited: { explore: true, risk: false, routes: false, simulate: false },
  dem: null,
  overlay: null,
  start: null,
  goal: null,
  routes: null,
};

// ---- flags from the controls ----
function robotFlags() {
  const q = {};
  if ($("robot").value) q.robot = $("robot").value;
  if ($("terrain").value) q.terrain = $("terrain").value;
  for (const flag of ROBOT_FLAGS) {
    const v = $(flag).value.trim();
    if (v !== "" && v !== state.defaults[flag]) q[flag] = v;
  }
  return q;
}
function ksValue() {
  return Number(10 ** Number($("k-s-slider").value)).toPrecision(4);
}
function exploreFlags() {
  const q = robotFlags();
  if ($("k-s-on").checked) q["k-s"] = ksValue();
  return q;
}
function uncertaintyFlags() {
  if ($("cv-auto").checked) return {};
  return { "cv-n": $("cv-n").value, "cv-s": $("cv-s").value };
}
function slope() {
  return $("slope").value;
}

// ---- SVG helpers ----
function el(name, attrs, parent) {
  const e = document.createElementNS(SVGNS, name);
  for (const [k, v] of Object.entries(attrs || {})) e.setAttribute(k, v);
  if (parent) parent.appendChild(e);
  return e;
}
function text(parent, x, y, s, attrs) {
  const t = el("text", { x, y, ...(attrs || {}) }, parent);
  t.textContent = s;
  return t;
}
function linear(d0, d1, r0, r1) {
  const f = (v) => r0 + ((v - d0) / (d1 - d0 || 1)) * (r1 - r0);
  f.domain = [d0, d1];
  return f;
}
function niceTicks(lo, hi, n) {
  const span = hi - lo || 1;
  const step0 = span / n;
  const mag = 10 ** Math.floor(Math.log10(step0));
  const step = [1, 2, 5, 10].map((m) => m * mag).find((s) => span / s <= n) || 10 * mag;
  const ticks = [];
  for (let v = Math.ceil(lo / step) * step; v <= hi + 1e-9 * span; v += step) ticks.push(Number(v.toPrecision(12)));
  return ticks;
}
// A frame with axes: returns the plot area and scales.
function frame(svg, xDomain, yDomain, xLabel, yLabel, margin) {
  svg.replaceChildren();
  const m = margin || { l: 58, r: 14, t: 10, b: 42 };
  const w = Number(svg.getAttribute("width"));
  const h = Number(svg.getAttribute("height"));
  const x = linear(xDomain[0], xDomain[1], m.l, w - m.r);
  const y = linear(yDomain[0], yDomain[1], h - m.b, m.t);
  el("rect", { x: m.l, y: m.t, width: w - m.l - m.r, height: h - m.t - m.b, fill: PAPER, stroke: RULE }, svg);
  for (const t of niceTicks(xDomain[0], xDomain[1], 8)) {
    el("line", { x1: x(t), x2: x(t), y1: h - m.b, y2: h - m.b + 4, stroke: INK }, svg);
    el("line", { x1: x(t), x2: x(t), y1: m.t, y2: h - m.b, stroke: GRID }, svg);
    text(svg, x(t), h - m.b + 16, String(t), { "text-anchor": "middle" });
  }
  for (const t of niceTicks(yDomain[0], yDomain[1], 6)) {
    el("line", { x1: m.l - 4, x2: m.l, y1: y(t), y2: y(t), stroke: INK }, svg);
    el("line", { x1: m.l, x2: w - m.r, y1: y(t), y2: y(t), stroke: GRID }, svg);
    text(svg, m.l - 7, y(t) + 4, String(t), { "text-anchor": "end" });
  }
  text(svg, (m.l + w - m.r) / 2, h - 8, xLabel, { "text-anchor": "middle" });
  text(svg, 14, (m.t + h - m.b) / 2, yLabel, { "text-anchor": "middle", transform: `rotate(-90 14 ${(m.t + h - m.b) / 2})` });
  return { x, y, m, w, h };
}
function fmt(v, digits) {
  return v === null || v === undefined ? "-" : Number(v).toFixed(digits);
}

// ---- Explore ----
function showPrediction(e) {
  const badge = $("regime");
  // What the robot does, the paper's regime name beside it (docs/model.md §6, "Outcomes").
  badge.textContent = `${state.outcomes[e.regime] || e.regime} (${e.regime})`;
  badge.dataset.regime = e.regime;
  badge.style.background = COLOURS[e.regime];
  const speed = $("speed");
  if (e.speed_m_s !== null) speed.textContent = fmt(e.speed_m_s * 100, 2);
  else if (e.model_speed_m_s !== null) speed.textContent = `(${fmt(e.model_speed_m_s * 100, 2)})`;
  else speed.textContent = "-";
  speed.dataset.speedMS = String(e.speed_m_s);
  speed.dataset.slopeDeg = String(e.slope_deg);
  $("t1").textContent = e.t1_s === null ? "-" : fmt(e.t1_s * 1e3, 1);
  $("slip").textContent = e.slip_m === null ? "-" : fmt(e.slip_m * 1e3, 2);
  $("step").textContent = e.step_m === null ? "-" : fmt(e.step_m * 1e3, 2);
  $("margin").textContent = fmt(e.k_s_margin, 2);
  let cause = `${e.cause.replaceAll("_", " ")}: ${state.causes[e.cause] || ""}`;
  if (e.speed_m_s === null && e.model_speed_m_s !== null) {
    cause += ". The speed in parentheses is the stance model's, which this regime rules out.";
  }
  if (e.extrapolated) cause += " (k_n and k_s extrapolated beyond the terrain's last measured slope)";
  $("cause").textContent = cause;
  state.point = e;
  drawSweep();
  drawPhaseMarker();
}
function updatePredict() {
  const q = { ...exploreFlags(), slope: slope() };
  return fresh("predict", () => get("/api/predict", q), showPrediction);
}
function updateSweep() {
  // Over the slope slider's span, as the server wrote it (page.rs), at its step.
  const q = { ...exploreFlags(), from: $("slope").min, to: $("slope").max, step: $("slope").step };
  return fresh("sweep", () => get("/api/sweep", q), (rows) => {
    state.sweep = rows;
    drawSweep();
  });
}
function drawSweep() {
  const rows = state.sweep;
  if (!rows) return;
  const svg = $("sweep-chart");
  const speeds = rows.map((r) => (r.speed_m_s === null ? null : r.speed_m_s * 100));
  const finite = speeds.filter((v) => v !== null);
  const top = Math.max(1, ...finite);
  const bottom = Math.min(0, ...finite);
  const f = frame(svg, [Number($("slope").min), Number($("slope").max)], [bottom, top * 1.08], "slope (deg)", "speed (cm/s)");
  el("line", { x1: f.x(-30), x2: f.x(40), y1: f.y(0), y2: f.y(0), stroke: INK }, svg);
  for (let i = 1; i < rows.length; i++) {
    if (speeds[i - 1] === null || speeds[i] === null) continue;
    el("line", {
      x1: f.x(rows[i - 1].slope_deg), y1: f.y(speeds[i - 1]), x2: f.x(rows[i].slope_deg), y2: f.y(speeds[i]),
      stroke: COLOURS[rows[i].regime], "stroke-width": 3,
    }, svg);
  }
  const p = state.point;
  if (p) {
    el("line", { x1: f.x(p.slope_deg), x2: f.x(p.slope_deg), y1: f.m.t, y2: f.h - f.m.b, stroke: INK, "stroke-dasharray": "4 3" }, svg);
    if (p.speed_m_s !== null) {
      el("circle", { cx: f.x(p.slope_deg), cy: f.y(p.speed_m_s * 100), r: 6, fill: COLOURS[p.regime], stroke: INK, "stroke-width": 2, id: "sweep-marker" }, svg);
    }
  }
}
function phaseAxes() {
  const { k_n, k_s } = state.level;
  return { kn: [k_n / 100, k_n * 100], ks: [k_s / 1000, k_s * 100], n: 160 };
}
function updatePhase() {
  if (!state.level) return undefined;
  const a = phaseAxes();
  const q = { ...robotFlags(), slope: slope(), "k-n": `${a.kn[0]}:${a.kn[1]}:${a.n}`, "k-s": `${a.ks[0]}:${a.ks[1]}:${a.n}` };
  return fresh("phase", () => get("/data/phase-map", q), (map) => {
    state.phase = map;
    drawPhase();
  });
}
function drawPhase() {
  const map = state.phase;
  if (!map) return;
  const canvas = $("phase-canvas");
  const nx = map.k_n.length;
  const ny = map.k_s.length;
  canvas.width = nx;
  canvas.height = ny;
  const ctx = canvas.getContext("2d");
  const img = ctx.createImageData(nx, ny);
  const rgb = CODES.map((c) => rgbOf(COLOURS[c]));
  for (let j = 0; j < ny; j++) {
    for (let i = 0; i < nx; i++) {
      const c = rgb[map.regimes.charCodeAt(j * nx + i) - 48];
      const o = ((ny - 1 - j) * nx + i) * 4;
      img.data.set([c[0], c[1], c[2], 255], o);
    }
  }
  ctx.putImageData(img, 0, 0);
  drawPhaseMarker();
}
function drawPhaseMarker() {
  const map = state.phase;
  if (!map) return;
  const svg = $("phase-axes");
  const lx = [Math.log10(map.k_n[0]), Math.log10(map.k_n[map.k_n.length - 1])];
  const ly = [Math.log10(map.k_s[0]), Math.log10(map.k_s[map.k_s.length - 1])];
  svg.replaceChildren();
  const x = linear(lx[0], lx[1], 60, 400);
  const y = linear(ly[0], ly[1], 270, 10);
  el("rect", { x: 60, y: 10, width: 340, height: 260, fill: "none", stroke: INK }, svg);
  for (let d = Math.ceil(lx[0]); d <= lx[1]; d++) {
    el("line", { x1: x(d), x2: x(d), y1: 270, y2: 275, stroke: INK }, svg);
    text(svg, x(d), 288, `1e${d}`, { "text-anchor": "middle" });
  }
  for (let d = Math.ceil(ly[0]); d <= ly[1]; d++) {
    el("line", { x1: 55, x2: 60, y1: y(d), y2: y(d), stroke: INK }, svg);
    text(svg, 52, y(d) + 4, `1e${d}`, { "text-anchor": "end" });
  }
  text(svg, 230, 312, "normal resistance k_n (N/m³)", { "text-anchor": "middle" });
  text(svg, 12, 140, "shear strength k_s (N/m³)", { "text-anchor": "middle", transform: "rotate(-90 12 140)" });
  const p = state.point;
  if (p && p.k_n > 0 && p.k_s > 0) {
    const cx = x(Math.log10(p.k_n));
    const cy = y(Math.log10(p.k_s));
    // The terrain's (k_n, k_s) in the colours of the figures' star: green, outlined black.
    el("circle", { cx, cy, r: 7, fill: STAR, stroke: INK, "stroke-width": 2.5, id: "phase-marker" }, svg);
    el("circle", { cx, cy, r: 2, fill: INK }, svg);
  }
}
function updateExplore() {
  updatePredict();
  updatePhase();
}

// ---- Risk ----
function riskFlags() {
  return { ...robotFlags(), ...uncertaintyFlags(), "max-risk": $("max-risk").value };
}
function updateRisk() {
  const q = riskFlags();
  fresh("risk", async () => {
    const [curve, limit] = await Promise.all([
      get("/api/risk", { ...q, slope: "0:30:31" }),
      get("/api/risk", { ...q, solve: "slope" }),
    ]);
    return { curve, limit };
  }, drawRisk);
  fresh("envelope", () => get("/api/risk", { ...q, solve: "mass", slope: "0:30:7" }), drawEnvelope);
}
function drawRisk({ curve, limit }) {
  const svg = $("risk-chart");
  const f = frame(svg, [0, 30], [0, 1], "slope (deg)", "p_fail");
  const pts = curve.map((r) => `${f.x(r.slope_deg)},${f.y(r.p_fail)}`).join(" ");
  el("polyline", { points: pts, fill: "none", stroke: COLOURS.slippage, "stroke-width": 2.5 }, svg);
  for (const r of curve) el("circle", { cx: f.x(r.slope_deg), cy: f.y(r.p_fail), r: 2.5, fill: COLOURS.slippage }, svg);
  const maxRisk = limit.max_risk;
  el("line", { x1: f.x(0), x2: f.x(30), y1: f.y(maxRisk), y2: f.y(maxRisk), stroke: SIM_COLOURS.data, "stroke-dasharray": "2 3" }, svg);
  text(svg, f.x(0.5), f.y(maxRisk) - 4, `max risk ${maxRisk}`);
  // Two limits, named apart (risk --solve slope): up to where the robot climbs (P(not success)
  // below the threshold) and up to where it does not fail (p_fail below it); a limit of kind
  // "repose" is the angle of repose itself, where the sand flows, not a risk threshold.
  const safe = limit.safe_slope_deg;
  const success = limit.success_slope_deg;
  // In the risk curve's colours: the success limit in P(not success)'s orange, the safe-slope
  // limit in the model's blue, the threshold in the reference lines' grey.
  const marks = [
    [success, "success-slope", SIM_COLOURS["not-success"], "climbs steadily to"],
    [safe, "safe-slope", SIM_COLOURS.model, limit.limit.kind === "repose" ? "repose" : "safe to"],
  ];
  let row = 0;
  for (const [deg, id, colour, label] of marks) {
    if (deg === null || deg > 30) continue;
    el("line", { x1: f.x(deg), x2: f.x(deg), y1: f.m.t, y2: f.h - f.m.b, stroke: colour, "stroke-width": 2, "stroke-dasharray": "6 4", id }, svg);
    text(svg, f.x(deg) + 4, f.m.t + 14 + 16 * row++, `${label} ${deg.toFixed(1)} deg`);
  }
  const describe = (l, p) => {
    if (l.kind === "limit") return `up to ${l.value.toFixed(1)} deg (${p} < ${maxRisk})`;
    if (l.kind === "repose") return `up to the angle of repose, ${l.repose_deg} deg (${p} < ${maxRisk} below it; beyond it the sand flows)`;
    if (l.kind === "none_safe") return `on no slope (${p} = ${l.p_fail.toFixed(4)} already on level ground)`;
    return `at every slope searched, up to ${l.up_to} deg (${p} < ${maxRisk})`;
  };
  // "Safe" as docs/model.md §9 defines it, the words of docs/model.md §6.
  let summary = `climbs steadily (success limit) ${describe(limit.success_limit, "P(not climbing steadily)")}; ` +
    `safe (safe-slope limit) ${describe(limit.limit, "P(sinks or slides back)")}`;
  if (success !== null && safe !== null && safe - success >= 0.05) {
    summary += `; between ${success.toFixed(1)} and ${safe.toFixed(1)} deg it likely climbs slowly and may stall (metastable: it can stall in its own trench)`;
  }
  const first = curve[0];
  summary += `; CVs used: k_n ${first.cv_n.toFixed(3)} (${first.cv_n_source}), k_s ${first.cv_s.toFixed(3)} (${first.cv_s_source}) at level`;
  $("risk-summary").textContent = summary;
  $("risk-summary").dataset.safeSlopeDeg = String(safe);
  $("risk-summary").dataset.successSlopeDeg = String(success);
  $("risk-summary").dataset.limitKind = limit.limit.kind;
  if ($("cv-auto").checked) {
    $("cv-n-out").textContent = first.cv_n.toFixed(3);
    $("cv-s-out").textContent = first.cv_s.toFixed(3);
  }
}
function drawEnvelope(env) {
  const svg = $("envelope-chart");
  const payloads = env.points.map((p) => p.max_payload_kg).filter((v) => v !== null);
  const top = Math.max(0.1, ...payloads);
  const f = frame(svg, [0, 30], [Math.min(0, ...payloads), top * 1.1], "slope (deg)", "heaviest safe payload (kg)");
  // The curve is broken where no mass is safe (`limit.kind` "none_safe": even the robot
  // empty fails more often than the risk allows); those slopes get a cross on the zero line.
  const segments = [[]];
  for (const p of env.points) {
    if (p.max_payload_kg === null) {
      if (segments[segments.length - 1].length) segments.push([]);
      const [cx, cy] = [f.x(p.slope_deg), f.y(0)];
      el("path", {
        d: `M${cx - 5},${cy - 5}L${cx + 5},${cy + 5}M${cx - 5},${cy + 5}L${cx + 5},${cy - 5}`,
        stroke: COLOURS.slippage, "stroke-width": 2.5, "data-slope-deg": String(p.slope_deg), "data-none-safe": "true",
      }, svg);
      continue;
    }
    segments[segments.length - 1].push(`${f.x(p.slope_deg)},${f.y(p.max_payload_kg)}`);
    el("circle", {
      cx: f.x(p.slope_deg), cy: f.y(p.max_payload_kg), r: 3.5, fill: COLOURS.sinkage,
      "data-slope-deg": String(p.slope_deg), "data-max-payload-kg": String(p.max_payload_kg),
    }, svg);
  }
  for (const seg of segments.filter((s) => s.length > 1)) {
    el("polyline", { points: seg.join(" "), fill: "none", stroke: COLOURS.sinkage, "stroke-width": 2.5 }, svg);
  }
  const none = env.points.filter((p) => p.max_payload_kg === null).map((p) => p.slope_deg);
  if (none.length) {
    text(svg, f.w - 20, f.m.t + 30, `× no safe load at ${none.join(", ")} deg`, { "text-anchor": "end", fill: COLOURS.slippage });
  }
  text(svg, f.w - 20, f.m.t + 14, `robot ${env.robot_mass_kg} kg, max risk ${env.max_risk}`, { "text-anchor": "end" });
}
