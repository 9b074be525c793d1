// The explorer page's Routes and Simulate tabs and the wiring of every control (docs/serve.md),
// loaded after app.js, whose helpers, palette and state it uses (the two scripts share the
// page's global scope; the wiring runs last, when both are loaded). No colour is written in
// this file either (a test in page.rs holds it so).

// ---- Routes ----
function planFlags() {
  const objectives = ["time", "risk"].filter((o) => $(`obj-${o}`).checked);
  return {
    ...robotFlags(), ...uncertaintyFlags(), "max-roll": $("max-roll").value,
    objective: objectives.length ? objectives.join(",") : "distance",
  };
}
async function loadMap() {
  if (!state.served.dem) {
    $("routes-hint").textContent = "No elevation model: start the server with --dem FILE to plan routes.";
    return;
  }
  await fresh("dem", () => get("/data/dem"), (dem) => {
    state.dem = dem;
    const canvas = $("map");
    const w = Math.ceil(dem.cols / dem.stride);
    const h = Math.ceil(dem.rows / dem.stride);
    const scale = Math.max(1, Math.floor(600 / Math.max(w, h)));
    Object.assign(state.dem, { w, h, scale });
    canvas.width = w * scale;
    canvas.height = h * scale;
    state.hillshade = hillshade(dem, w, h);
    drawMap();
  });
  updateOverlay();
}
function hillshade(dem, w, h) {
  const info = state.served.dem;
  const dx = info.cell_x_m * dem.stride;
  const dy = info.cell_y_m * dem.stride;
  const z = (c, r) => {
    const cc = Math.min(w - 1, Math.max(0, c));
    const rr = Math.min(h - 1, Math.max(0, r));
    return dem.values[rr * w + cc];
  };
  const shade = new Float32Array(w * h);
  const az = (315 * Math.PI) / 180;
  const alt = (45 * Math.PI) / 180;
  for (let r = 0; r < h; r++) {
    for (let c = 0; c < w; c++) {
      const here = z(c, r);
      if (here === null) {
        shade[r * w + c] = NaN;
        continue;
      }
      const e = z(c + 1, r) ?? here;
      const wv = z(c - 1, r) ?? here;
      const n = z(c, r - 1) ?? here;
      const s = z(c, r + 1) ?? here;
      // relief exaggerated 3 x, so low dunes show
      const gx = (3 * (e - wv)) / (2 * dx);
      const gy = (3 * (n - s)) / (2 * dy);
      const slopeAngle = Math.atan(Math.hypot(gx, gy));
      const aspect = Math.atan2(gx, gy);
      shade[r * w + c] = Math.max(0, Math.sin(alt) * Math.cos(slopeAngle) + Math.cos(alt) * Math.sin(slopeAngle) * Math.cos(az - aspect + Math.PI));
    }
  }
  return shade;
}
// The overlay's colour and weight for a p_fail: invisible below 1e-6, then the risk map's colour
// map (dark purple to yellow, linear between its stops) on a log scale up to 1 (most of a dune
// is safe; what matters is where it is not).
function rampRisk(p) {
  const t = Math.min(1, Math.max(0, (Math.log10(Math.max(p, 1e-12)) + 6) / 6));
  const x = t * (P_FAIL_STOPS.length - 1);
  const k = Math.min(P_FAIL_STOPS.length - 2, Math.floor(x));
  const [a, b] = [P_FAIL_STOPS[k], P_FAIL_STOPS[k + 1]];
  return { rgb: a.map((v, i) => v + (x - k) * (b[i] - v)), alpha: t === 0 ? 0 : 0.25 + 0.6 * t };
}
function drawMap() {
  const dem = state.dem;
  if (!dem) return;
  const canvas = $("map");
  const ctx = canvas.getContext("2d");
  const { w, h, scale } = dem;
  const img = ctx.createImageData(w, h);
  const overlay = $("rule").value === "none" ? null : state.overlay;
  for (let i = 0; i < w * h; i++) {
    const s = state.hillshade[i];
    let rgb = Number.isNaN(s) ? NODATA : [40 + 200 * s, 40 + 200 * s, 40 + 200 * s];
    if (overlay && overlay.values[i] !== null && !Number.isNaN(s)) {
      const { rgb: c, alpha } = rampRisk(overlay.values[i]);
      rgb = rgb.map((v, k) => (1 - alpha) * v + alpha * c[k]);
    }
    img.data.set([rgb[0], rgb[1], rgb[2], 255], i * 4);
  }
  const off = document.createElement("canvas");
  off.width = w;
  off.height = h;
  off.getContext("2d").putImageData(img, 0, 0);
  ctx.imageSmoothingEnabled = false;
  ctx.drawImage(off, 0, 0, w * scale, h * scale);
  drawRoutes(ctx);
}
function cellToPixel(col, row) {
  const { stride, scale } = state.dem;
  return [(col / stride) * scale + scale / 2, (row / stride) * scale + scale / 2];
}
function drawRoutes(ctx) {
  const info = state.served.dem;
  if (state.routes) {
    const order = (f) => ROUTE_ORDER.indexOf(f.properties.objective);
    for (const feature of [...state.routes.features].sort((a, b) => order(a) - order(b))) {
      const name = feature.properties.objective;
      ctx.strokeStyle = ROUTE_COLOURS[name] || INK;
      // time under risk under distance, so coinciding routes all show
      ctx.lineWidth = { time: 7, risk: 3, distance: 2 }[name] || 3;
      ctx.setLineDash(name === "distance" ? [6, 4] : []);
      ctx.beginPath();
      feature.geometry.coordinates.forEach(([x, y], i) => {
        const [px, py] = cellToPixel((x - info.west) / info.cell_x - 0.5, (info.north - y) / info.cell_y - 0.5);
        if (i === 0) ctx.moveTo(px, py);
        else ctx.lineTo(px, py);
      });
      ctx.stroke();
    }
    ctx.setLineDash([]);
  }
  // As the plan figure marks them: the start white outlined black, the goal black on white.
  for (const [cell, colour, other, label] of [[state.start, PAPER, INK, "S"], [state.goal, INK, PAPER, "G"]]) {
    if (!cell) continue;
    const [px, py] = cellToPixel(cell[0], cell[1]);
    ctx.fillStyle = colour;
    ctx.strokeStyle = other;
    ctx.lineWidth = 2;
    ctx.beginPath();
    ctx.arc(px, py, 7, 0, 2 * Math.PI);
    ctx.fill();
    ctx.stroke();
    ctx.fillStyle = other;
    ctx.font = "bold 10px sans-serif";
    ctx.textAlign = "center";
    ctx.fillText(label, px, py + 3.5);
  }
}
function updateOverlay() {
  if (!state.dem || $("rule").value === "none") {
    drawMap();
    return;
  }
  const q = { ...planFlags(), rule: $("rule").value };
  delete q.objective;
  fresh("overlay", () => get("/data/risk-map", q), (grid) => {
    state.overlay = grid;
    drawMap();
  });
}
function onMapClick(event) {
  if (!state.dem) return;
  const rect = $("map").getBoundingClientRect();
  const { stride, scale, cols, rows } = state.dem;
  const col = Math.min(cols - 1, Math.floor((event.clientX - rect.left) / scale) * stride);
  const row = Math.min(rows - 1, Math.floor((event.clientY - rect.top) / scale) * stride);
  if (!state.start || state.goal) {
    state.start = [col, row];
    state.goal = null;
    state.routes = null;
    $("routes-table").tBodies[0].replaceChildren();
    $("downloads").replaceChildren();
    $("routes-hint").textContent = `start: column ${col}, row ${row}. Click the goal.`;
  } else {
    state.goal = [col, row];
    $("routes-hint").textContent = `start: column ${state.start[0]}, row ${state.start[1]}; goal: column ${col}, row ${row}.`;
    updatePlan();
  }
  drawMap();
}
function updatePlan() {
  if (!state.start || !state.goal) return;
  const q = { ...planFlags(), "start-px": state.start.join(","), "goal-px": state.goal.join(",") };
  fresh("plan", async () => {
    const [json, geojson] = await Promise.all([get("/api/plan", q), get("/download/plan.geojson", q)]);
    return { json, geojson };
  }, ({ json, geojson }) => {
    state.routes = geojson;
    drawTable(json);
    drawMap();
    const links = $("downloads");
    links.replaceChildren();
    for (const [file, label] of [["plan.geojson", "routes (GeoJSON)"], ["risk-map.tif", "risk map (GeoTIFF: p_fail, climb azimuth)"]]) {
      const a = document.createElement("a");
      a.href = `/download/${file}?${query(q)}`;
      a.download = file;
      a.textContent = `download ${label}`;
      links.append(a, " ");
    }
  });
}
// The routes table as `plan` prints it.
function drawTable(json) {
  const body = $("routes-table").tBodies[0];
  body.replaceChildren();
  for (const name of ROUTE_ORDER) {
    const r = json.routes[name];
    if (!r) continue;
    const tr = document.createElement("tr");
    tr.dataset.objective = name;
    let cells;
    if (r.found) {
      tr.dataset.lengthM = String(r.length_m);
      const regimes = CODES.filter((c) => r.regimes[c] > 0).map((c) => `${c} ${r.regimes[c]}`);
      if (r.edges_over_roll_limit > 0) regimes.push(`over roll limit ${r.edges_over_roll_limit}`);
      cells = [name, "yes", fmt(r.length_m, 1), fmt(r.time_s, 1), fmt(r.survival, 4), fmt(r.max_pitch_deg, 1), fmt(r.max_roll_deg, 1), regimes.join(", ")];
    } else {
      cells = [name, "no", "-", "-", "-", "-", "-", r.message];
    }
    cells.forEach((c, i) => {
      const td = document.createElement("td");
      td.textContent = c;
      if (i === 0) {
        const swatch = document.createElement("span");
        swatch.style.cssText = `display:inline-block;width:1.2em;height:0.25em;margin-right:0.4em;vertical-align:middle;background:${ROUTE_COLOURS[name]}`;
        td.prepend(swatch);
      }
      tr.appendChild(td);
    });
    body.appendChild(tr);
  }
}

// ---- Simulate ----
// The walk comes whole from /data/simulation (the library's Simulation: the summary
// `simulate --json` prints, the trajectory sampled at SIM_RATE_HZ, the legs' outline and hips);
// the page only places the body and legs where the trajectory says, as the GIF of
// `simulate --animate` does (crates/sandslope-render/src/figures/simulate.rs draw_frame).
const SIM_RATE_HZ = 30;
const sim = { walk: null, pos: 0, playing: true, timer: null };
function simFlags() {
  return { ...exploreFlags(), slope: $("sim-slope").value, duration: $("sim-duration").value, rate: String(SIM_RATE_HZ) };
}
function updateSimulation() {
  // A check of the walk before is dropped with its answer (it was for other inputs).
  tickets.convergence = (tickets.convergence || 0) + 1;
  $("sim-convergence").textContent = "";
  delete $("sim-convergence").dataset.converged;
  fresh("simulate", () => get("/data/simulation", simFlags()), showSimulation);
}
// The walk again at a quarter of its step and a tenth of its creep speed (`simulate
// --check-convergence`, docs/simulate.md "Checking convergence"), on the user's click: six
// walks' time, so not on every change of the inputs.
function checkConvergence() {
  const { rate, ...flags } = simFlags();
  $("sim-convergence").textContent = "checking: the walk again at a quarter of its step and a tenth of its creep speed ...";
  fresh("convergence", () => get("/api/simulate", { ...flags, "check-convergence": "" }), showConvergence);
}
function showConvergence(c) {
  const out = $("sim-convergence");
  // A change that rounds to zero is "+0.00", not "-0.00".
  const signed = (v, digits) => {
    const s = fmt(v, digits);
    return /^-?[0.]+$/.test(s) ? s.replace("-", "+").replace(/^(?!\+)/, "+") : (v >= 0 ? "+" : "") + s;
  };
  const parts = c.refinements.map((r) => {
    const pct = c.walk.speed_m_s !== 0 ? ` (${signed((100 * r.speed_change_m_s) / Math.abs(c.walk.speed_m_s), 1)}%)` : "";
    const t1 = r.t1_change_s === null ? "-" : signed(r.t1_change_s * 1e3, 2);
    const failed = [["speed", r.speed_within], ["spread", r.spread_within], ["t1", r.t1_within], ["regime", r.same_regime]].filter((f) => !f[1]).map((f) => f[0]);
    const verdict = failed.length ? `outside the tolerance in ${failed.join(", ")}` : "within";
    const label = r.refinement === "quarter_step" ? "a quarter of the step" : "a tenth of the creep speed";
    return `${label}: speed ${signed(r.speed_change_m_s * 100, 2)} cm/s${pct}, steps' spread ${signed(r.step_speed_sd_change_m_s * 100, 2)} cm/s, t1 ${t1} ms, ${r.answer.regime} (${verdict})`;
  });
  out.textContent = `${c.converged ? "Converged" : "Not converged"} at ${c.slope_deg} deg: ${parts.join("; ")}. Tolerances: speed and the steps' spread ${fmt(c.speed_tolerance * 100, 0)}% or ${fmt(c.speed_tolerance_m_s * 100, 1)} cm/s, t1 ${fmt(c.t1_tolerance_s * 1e3, 0)} ms, the same regime.`;
  out.dataset.converged = String(c.converged);
}
function both(a, b, scale, digits) {
  const f = (v) => (v === null || v === undefined ? "-" : fmt(v * scale, digits));
  return `${f(a)} | ${f(b)}`;
}
function showSimulation(walk) {
  sim.walk = walk;
  sim.pos = 0;
  const m = walk.summary;
  const cf = m.closed_form;
  $("sim-regime").textContent = `${m.regime} | ${cf.regime}`;
  const speed = $("sim-speed");
  speed.textContent = `${fmt(m.speed_m_s * 100, 2)} ± ${fmt(m.speed_sd_m_s * 100, 2)}`;
  speed.dataset.speedMS = String(m.speed_m_s);
  speed.dataset.slopeDeg = String(m.slope_deg);
  const cfSpeed = $("sim-cf-speed");
  if (cf.speed_m_s !== null) cfSpeed.textContent = fmt(cf.speed_m_s * 100, 2);
  else if (cf.model_speed_m_s !== null) cfSpeed.textContent = `(${fmt(cf.model_speed_m_s * 100, 2)})`;
  else cfSpeed.textContent = "-";
  cfSpeed.dataset.speedMS = String(cf.speed_m_s);
  $("sim-t1").textContent = both(m.t1_s, cf.t1_s, 1e3, 1);
  $("sim-slip").textContent = both(m.slip_m, cf.slip_m, 1e3, 2);
  $("sim-step").textContent = both(m.step_m, cf.step_m, 1e3, 1);
  $("sim-depth").textContent = `${fmt(m.max_depth_m * 1e3, 1)} (${fmt(m.d_max_m * 1e3, 1)})`;
  // The contact scaling as model uncertainty (docs/simulate.md, "The scaling as model uncertainty").
  const sp = walk.scaling_spread;
  const spread = $("sim-spread");
  spread.textContent = sp ? `${fmt(sp.min_speed_m_s * 100, 1)} to ${fmt(sp.max_speed_m_s * 100, 1)}, regimes ${sp.regimes_agree ? "agree" : "DISAGREE"}` : "-";
  spread.title = sp ? sp.walks.map((w) => `${w.rft_scaling}: ${fmt(w.speed_m_s * 100, 2)} cm/s, ${w.regime}`).join("; ") + (sp.regimes_agree ? "" : ". The verdict here is the contact scaling's choice, not the sand's, until a plate dragged along the surface is measured.") : "";
  spread.dataset.regimesAgree = sp ? String(sp.regimes_agree) : "";
  let cause = `simulated: ${m.cause.replaceAll("_", " ")}, over ${m.steps_measured} measured steps of ${m.duration_s} s at dt = ${m.dt_s.toExponential(2)} s`;
  if (m.unanchored_steps > 0) cause += ` (${m.unanchored_steps} never anchored)`;
  if (m.stalled_legs.length) cause += `; servo stalled on legs ${m.stalled_legs.join(", ")}`;
  cause += `. Closed form: ${cf.cause.replaceAll("_", " ")}: ${state.causes[cf.cause] || ""}`;
  $("sim-cause").textContent = cause;
  const n = walk.trajectory.time_s.length;
  const slider = $("sim-time");
  slider.max = String(Math.max(0, n - 1));
  $("sim-canvas").dataset.frames = String(n);
  drawSimFrame();
}
function legColour(tripod, rank, n) {
  const base = rgbOf(SIM_COLOURS[tripod === 0 ? "tripod-a" : "tripod-b"]);
  const f = n > 1 ? (0.45 * rank) / (n - 1) : 0;
  return hexOf(base.map((c) => Math.floor(c + (255 - c) * f)));
}
function drawSimFrame() {
  const walk = sim.walk;
  if (!walk) return;
  const tr = walk.trajectory;
  const g = walk.geometry;
  const n = tr.time_s.length;
  if (n === 0) return;
  const i = Math.min(n - 1, Math.floor(sim.pos) % n);
  const canvas = $("sim-canvas");
  canvas.dataset.frame = String(i);
  $("sim-time").value = String(i);
  $("sim-time-out").textContent = `t = ${tr.time_s[i].toFixed(2)} s`;
  const ctx = canvas.getContext("2d");
  const W = canvas.width;
  const H = canvas.height;
  const theta = (walk.summary.slope_deg * Math.PI) / 180;
  const s = Math.sin(theta);
  const c = Math.cos(theta);
  const world = (p) => [p[0] * c - p[1] * s, p[0] * s + p[1] * c];
  const x = tr.x_m[i];
  const z = tr.z_m[i];
  const phi = tr.pitch_rad[i];
  const centre = world([x, z]);
  const halfW = 0.25;
  const halfH = (halfW * H) / W;
  const px = (p) => [((p[0] - centre[0] + halfW) / (2 * halfW)) * W, H - ((p[1] - centre[1] + halfH) / (2 * halfH)) * H];
  const path = (points, close) => {
    ctx.beginPath();
    points.forEach((p, k) => {
      const [u, v] = px(p);
      if (k === 0) ctx.moveTo(u, v);
      else ctx.lineTo(u, v);
    });
    if (close) ctx.closePath();
  };
  ctx.fillStyle = PAPER;
  ctx.fillRect(0, 0, W, H);
  // Sand: the slope frame below its surface, turned into the world.
  const far = 2;
  path([world([x - far, 0]), world([x + far, 0]), world([x + far, -far]), world([x - far, -far])], true);
  ctx.fillStyle = SIM_COLOURS.sand;
  ctx.fill();
  path([world([x - far, 0]), world([x + far, 0])], false);
  ctx.strokeStyle = SIM_COLOURS["sand-surface"];
  ctx.lineWidth = 2;
  ctx.stroke();
  // Marks on the sand every 5 cm along the slope, so the walk shows against the ground.
  ctx.lineWidth = 1;
  for (let k = Math.floor((x - 0.4) / 0.05); k <= Math.ceil((x + 0.4) / 0.05); k++) {
    path([world([k * 0.05, 0]), world([k * 0.05, -0.012])], false);
    ctx.stroke();
  }
  // Body: a box from the belly (h below the axle) to 0.3 h above it, pitched.
  const sp = Math.sin(phi);
  const cp = Math.cos(phi);
  const body = (p) => world([x + cp * p[0] - sp * p[1], z + sp * p[0] + cp * p[1]]);
  const l = g.body_length_m;
  const h = g.hip_height_m;
  path([[-l / 2, -h], [l / 2, -h], [l / 2, 0.3 * h], [-l / 2, 0.3 * h]].map(body), true);
  ctx.fillStyle = SIM_COLOURS.data;
  ctx.globalAlpha = 0.8;
  ctx.fill();
  ctx.globalAlpha = 1;
  const legs = g.hip_x_m.length;
  const half = Math.max(1, Math.floor(legs / 2));
  const scale = 0.02; // m of arrow per N
  for (let j = 0; j < legs; j++) {
    const a = phi - tr.leg_angle_rad[j][i];
    const sa = Math.sin(a);
    const ca = Math.cos(a);
    const hp = [cp * g.hip_x_m[j], sp * g.hip_x_m[j]];
    const pts = g.leg_nodes_m.map((p) => world([x + hp[0] + ca * p[0] - sa * p[1], z + hp[1] + sa * p[0] + ca * p[1]]));
    path(pts, false);
    ctx.strokeStyle = legColour(g.tripod[j], j % half, half);
    ctx.lineWidth = g.tripod[j] === 0 ? 4 : 3;
    ctx.stroke();
    const fx = tr.leg_force_x_n[j][i];
    const fz = tr.leg_force_z_n[j][i];
    if (Math.hypot(fx, fz) > 0.05) {
      let lowest = pts[0];
      for (const p of pts) if (-p[0] * s + p[1] * c < -lowest[0] * s + lowest[1] * c) lowest = p;
      const tip = [lowest[0] + scale * (fx * c - fz * s), lowest[1] + scale * (fx * s + fz * c)];
      path([lowest, tip], false);
      ctx.strokeStyle = SIM_COLOURS["closed-form"];
      ctx.lineWidth = 2;
      ctx.stroke();
      const [u, v] = px(tip);
      ctx.fillStyle = SIM_COLOURS["closed-form"];
      ctx.beginPath();
      ctx.arc(u, v, 3, 0, 2 * Math.PI);
      ctx.fill();
    }
  }
  const [u, v] = px(centre);
  ctx.fillStyle = INK;
  ctx.beginPath();
  ctx.arc(u, v, 4, 0, 2 * Math.PI);
  ctx.fill();
  ctx.font = "14px system-ui, sans-serif";
  ctx.fillText(`t = ${tr.time_s[i].toFixed(2)} s, ${walk.summary.slope_deg} deg, x = ${(x * 100).toFixed(1)} cm, speed ${fmt(walk.summary.speed_m_s * 100, 2)} cm/s (simulated)`, 10, 20);
}
// Plays the walk at its sample rate (times the chosen speed) while the tab is shown.
function simTick() {
  sim.timer = setTimeout(simTick, 1000 / SIM_RATE_HZ);
  if (!sim.walk || !sim.playing || !$("simulate").classList.contains("active")) return;
  sim.pos = (sim.pos + Number($("sim-rate").value)) % sim.walk.trajectory.time_s.length;
  drawSimFrame();
}
function setSimSlope(value) {
  $("sim-slope").value = value;
  $("sim-slope-num").value = value;
  soon("sim", updateSimulation, 150);
}

// ---- wiring ----
function showTab(name) {
  for (const b of document.querySelectorAll("#tabs button")) b.classList.toggle("active", b.dataset.tab === name);
  for (const s of document.querySelectorAll(".tab")) s.classList.toggle("active", s.id === name);
  if (!state.visited[name]) {
    state.visited[name] = true;
    if (name === "risk") updateRisk();
    if (name === "routes") state.mapReady = loadMap();
    if (name === "simulate") {
      updateSimulation();
      simTick();
    }
  }
}
function onRobotChange() {
  soon("robot", () => {
    updateSweep();
    updateExplore();
    if (state.visited.risk) updateRisk();
    if (state.visited.routes) {
      updateOverlay();
      updatePlan();
    }
    if (state.visited.simulate) updateSimulation();
  });
}
function syncMassSlider() {
  const m = Number($("mass").value);
  if (m > 0) $("mass-slider").value = String(Math.log10(m));
}
function setSlope(value) {
  $("slope").value = value;
  $("slope-num").value = value;
  $("slope").dispatchEvent(new Event("input"));
}

async function start() {
  const served = await get("/data/served");
  state.served = served;
  state.causes = Object.fromEntries(served.causes);
  state.outcomes = Object.fromEntries(served.outcomes);
  for (const { field, key } of served.robot_keys) {
    if (!$(field)) {
      logError(`the page has no control for the robot quantity ${field} (${key})`);
      continue;
    }
    ROBOT_FLAGS.push(field);
    SPEC_KEYS[field] = key;
  }
  for (const [id, list, current] of [["robot", served.robots, served.robot_name], ["terrain", served.terrains, served.terrain_name]]) {
    const select = $(id);
    select.append(new Option(`${current} (served)`, ""));
    for (const name of list) if (name !== current) select.append(new Option(name, name));
  }
  for (const flag of ROBOT_FLAGS) {
    // Shown to 6 significant digits (2 pi rad/s as 6.28319, not 6.283185307179586 cut to
    // "6.28318530" by the box); an unchanged box sends no flag, so the served robot's exact
    // value is what the server uses.
    state.defaults[flag] = String(Number(Number(served.robot[SPEC_KEYS[flag]]).toPrecision(6)));
    $(flag).defaultValue = state.defaults[flag];
    $(flag).value = state.defaults[flag];
  }
  syncMassSlider();
  for (const c of CODES) {
    const swatch = document.createElement("span");
    swatch.style.background = COLOURS[c];
    $("legend").append(swatch, c);
  }
  // The phase diagram's axes: the served terrain's level (k_n, k_s) / 100 (/ 1000) to x 100, as `phase`'s defaults.
  state.level = await get("/api/predict", { slope: "0" });
  $("k-s-slider").value = String(Math.log10(state.level.k_s));
  $("k-s-out").textContent = ksValue();

  for (const b of document.querySelectorAll("#tabs button")) b.addEventListener("click", () => showTab(b.dataset.tab));
  $("slope").addEventListener("input", () => {
    $("slope-num").value = $("slope").value;
    soon("explore", updateExplore, 30);
  });
  $("slope-num").addEventListener("change", () => setSlope($("slope-num").value));
  $("mass-slider").addEventListener("input", () => {
    $("mass").value = Number(10 ** Number($("mass-slider").value)).toPrecision(3);
    onRobotChange();
  });
  $("mass").addEventListener("change", () => {
    syncMassSlider();
    onRobotChange();
  });
  for (const id of [...ROBOT_FLAGS.filter((f) => f !== "mass"), "robot", "terrain"]) $(id).addEventListener("change", onRobotChange);
  $("k-s-on").addEventListener("change", () => {
    $("k-s-slider").disabled = !$("k-s-on").checked;
    onRobotChange();
  });
  $("k-s-slider").addEventListener("input", () => {
    $("k-s-out").textContent = ksValue();
    soon("ks", () => {
      updateSweep();
      updatePredict();
    });
  });
  $("cv-auto").addEventListener("change", () => {
    $("cv-n").disabled = $("cv-s").disabled = $("cv-auto").checked;
    onRobotChange();
  });
  $("cv-n").disabled = $("cv-s").disabled = true;
  for (const id of ["cv-n", "cv-s"]) {
    $(id).addEventListener("input", () => {
      $(`${id}-out`).textContent = $(id).value;
      soon("cv", onRobotChange);
    });
  }
  $("max-risk").addEventListener("change", onRobotChange);
  $("rule").addEventListener("change", updateOverlay);
  for (const id of ["obj-time", "obj-risk"]) $(id).addEventListener("change", updatePlan);
  $("max-roll").addEventListener("change", () => {
    updateOverlay();
    updatePlan();
  });
  $("map").addEventListener("click", onMapClick);
  $("sim-slope").addEventListener("input", () => setSimSlope($("sim-slope").value));
  $("sim-slope-num").addEventListener("change", () => setSimSlope($("sim-slope-num").value));
  $("sim-duration").addEventListener("change", updateSimulation);
  $("sim-play").addEventListener("click", () => {
    sim.playing = !sim.playing;
    $("sim-play").textContent = sim.playing ? "pause" : "play";
  });
  $("sim-check").addEventListener("click", checkConvergence);
  $("sim-time").addEventListener("input", () => {
    sim.pos = Number($("sim-time").value);
    drawSimFrame();
  });

  // The page's URL can set what a user would: ?slope=20, ?tab=risk, ?mass=1.2, ?tab=simulate,
  // ?tab=routes&start-px=COL,ROW&goal-px=COL,ROW (clicked on the map once it is drawn).
  for (const flag of ROBOT_FLAGS) if (pageUrl.has(flag)) $(flag).value = pageUrl.get(flag);
  syncMassSlider();
  updateSweep();
  await updateExplore();
  // ?slope= moves the slider as a user would (an input event), after the first answer is shown.
  if (pageUrl.has("slope")) setSlope(pageUrl.get("slope"));
  // ?tab=simulate&sim-slope=DEG&sim-duration=S: the Simulate tab's walk.
  for (const key of ["sim-slope", "sim-duration"]) if (pageUrl.has(key)) $(key).value = pageUrl.get(key);
  $("sim-slope-num").value = $("sim-slope").value;
  const tab = pageUrl.get("tab");
  if (["risk", "routes", "simulate"].includes(tab)) showTab(tab);
  // ?tab=simulate&sim-check: the convergence check, clicked as a user would.
  if (tab === "simulate" && pageUrl.has("sim-check")) $("sim-check").click();
  if (tab === "routes" && pageUrl.has("start-px") && pageUrl.has("goal-px")) {
    await state.mapReady;
    for (const key of ["start-px", "goal-px"]) {
      const [col, row] = pageUrl.get(key).split(",").map(Number);
      const rect = $("map").getBoundingClientRect();
      const [px, py] = cellToPixel(col, row);
      $("map").dispatchEvent(new MouseEvent("click", { clientX: rect.left + px, clientY: rect.top + py, bubbles: true }));
    }
  }
}
start().catch((e) => logError(`start: ${e.stack || e}`));
