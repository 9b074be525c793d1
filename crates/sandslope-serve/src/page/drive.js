// The Drive tab (`serve --drive`, docs/drive.md): the run the server drives, polled from
// /api/drive/status while it runs (the same per-stance record `drive --json` lists under
// `live`), and a stop button that takes the CLI's Ctrl-C path (gait stopped, torque off).
// Loaded after app.js, whose `$`, `get`, `busy`, `logError` and `showTab` it uses.
const DRIVE_POLL_MS = 500;
const DRIVE_FINAL = ["completed", "interrupted", "halted", "failed"];

function sci(v) {
  return v === null || v === undefined ? "-" : Number(v).toExponential(2);
}
function prob(v) {
  if (v === null || v === undefined) return "-";
  return v < 0.001 ? "< 0.001" : v.toFixed(3);
}
function showDrive(st) {
  const tab = $("drive");
  tab.dataset.state = st.state;
  $("drive-state").textContent = st.state + (st.emulated ? " (emulated bus)" : "");
  $("drive-time").textContent = `${st.time_s.toFixed(2)} / ${st.duration_s}`;
  $("drive-speed").textContent = `${st.leg_speed_rad_s.toFixed(2)} (${st.commanded_leg_speed_rad_s.toFixed(2)})`;
  $("drive-slope").textContent = String(st.slope_deg);
  const live = st.live && st.live.inference;
  const ks = $("drive-k-s");
  ks.textContent = live ? `${sci(live.k_s)} [${sci(live.k_s_lo)} – ${sci(live.k_s_hi)}]` : "-";
  for (const [key, id] of [["k_s", "drive-k-s"], ["p_slippage", "drive-p-slippage"], ["p_fail", "drive-p-fail"]]) {
    if (live) $(id).dataset.value = String(live[key]);
  }
  if (live) ks.dataset.lo = String(live.k_s_lo), (ks.dataset.hi = String(live.k_s_hi));
  const cm = (v) => (100 * v).toFixed(1);
  $("drive-climb").textContent = live ? `${cm(live.speed_m_s)} [${cm(live.speed_lo_m_s)} – ${cm(live.speed_hi_m_s)}]` : "-";
  if (live) $("drive-climb").dataset.value = String(live.speed_m_s);
  $("drive-p-slippage").textContent = live ? prob(live.p_slippage) : "-";
  $("drive-p-fail").textContent = live ? prob(live.p_fail) : "-";
  showVerdicts(st.live && st.live.pooled);
  $("drive-estimates").textContent = live
    ? `${st.estimates} stances; the last, tripod ${st.live.tripod}, ended at t = ${st.live.time_s.toFixed(2)} s`
    : "no stance finished yet";
  // Said as what happened and what is watched, not as a comparison that reads as true.
  $("drive-halted").textContent = st.stop_on_risk === null
    ? "off (no --stop-on-risk)"
    : st.halted
      ? `HALTED: P(fail) passed ${st.stop_on_risk}`
      : `watching: halts if P(fail) passes ${st.stop_on_risk}`;
  $("drive-halted").dataset.halted = String(st.halted);
  const ended = DRIVE_FINAL.includes(st.state);
  $("drive-stop").disabled = ended;
  if (ended) $("drive-stop").textContent = "Stopped: torque off";
  const off = st.torque_off;
  let end = "";
  if (st.error) end += `${st.error}. `;
  if (off) end += `Torque off confirmed on servos ${off.confirmed.join(", ") || "none"}` +
    (off.unconfirmed.length ? `; NOT confirmed on ${off.unconfirmed.join(", ")} (their Bus Watchdog stops them)` : "") + ". ";
  if (st.emulator) end += st.emulator;
  $("drive-end").textContent = end;
  return ended;
}
// Both verdicts on the stances pooled so far (docs/drive.md, "The live estimate, pooled, and
// the decision"): the simulator's (the grid walks' regimes) and the closed form's at the
// pooled k_s; where one says the walk fails (P >= 0.5) and the other not, the page says so
// and which one the decision took.
function showVerdicts(pooled) {
  const v = $("drive-verdicts");
  const note = $("drive-disagree");
  if (!pooled) {
    v.textContent = "-";
    note.hidden = true;
    return;
  }
  const sim = pooled.p_fail_simulator;
  const cf = pooled.p_fail_closed_form;
  v.textContent = `${prob(sim)} / ${prob(cf)}`;
  v.dataset.simulator = String(sim);
  v.dataset.closedForm = String(cf);
  const disagree = (sim >= 0.5) !== (cf >= 0.5);
  v.dataset.disagree = String(disagree);
  note.hidden = !disagree;
  note.textContent = disagree
    ? `The verdicts disagree over ${pooled.stances} stances: the simulator says the walk ` +
      (sim >= 0.5 ? "fails" : "succeeds") + ` (P(fail) ${prob(sim)}), the closed form that it ` +
      (cf >= 0.5 ? "fails" : "succeeds") + ` (P(fail) ${prob(cf)}); the decision takes the more pessimistic, ${prob(pooled.p_fail)}.`
    : "";
}
async function pollDrive() {
  let ended = false;
  try {
    ended = showDrive(await get("/api/drive/status"));
  } catch (e) {
    logError(`drive: ${e.message || e}`);
    return;
  }
  if (!ended) setTimeout(pollDrive, DRIVE_POLL_MS);
}
async function stopDrive() {
  $("drive-stop").disabled = true;
  $("drive-stop").textContent = "Stopping…";
  busy(1);
  try {
    const r = await fetch("/api/drive/stop", { method: "POST" });
    if (!r.ok) logError(`drive stop: ${(await r.json()).error}`);
  } finally {
    busy(-1);
  }
}
async function startDrive() {
  // Only a server started with --drive has a run: the tab stays hidden otherwise ("off").
  const first = await get("/api/drive/status");
  if (first.state === "off") return;
  document.querySelector('#tabs button[data-tab="drive"]').hidden = false;
  $("drive-stop").addEventListener("click", stopDrive);
  if (new URLSearchParams(location.search).get("tab") === "drive") showTab("drive");
  if (!showDrive(first)) setTimeout(pollDrive, DRIVE_POLL_MS);
}
startDrive().catch((e) => logError(`drive: ${e.stack || e}`));
