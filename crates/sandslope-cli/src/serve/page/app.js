"use strict";
const $ = (id) => document.getElementById(id);
async function api(command, params) {
  const q = new URLSearchParams(params).toString();
  const r = await fetch(`/api/${command}?${q}`);
  return r.json();
}
async function update() {
  const slope = $("slope").value;
  $("slope-out").textContent = slope;
  const e = await api("predict", { slope });
  $("speed").textContent = e.speed_m_s == null ? "-" : (e.speed_m_s * 100).toFixed(2);
}
$("slope").addEventListener("input", update);
update();
