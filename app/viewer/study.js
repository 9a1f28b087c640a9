// coldroute plan viewer — the electrification study: which routes can go electric, with which
// battery. A study request (pasted, or the API's own example) runs as a job; its days are shown
// as a route × day heat map of the margin above the reserve and as the battery–coverage curve.
// Uses the page's api(), el() and $() (viewer.js).
"use strict";

const study = { answer: null, plot: null, job: null };

async function loadStudyExample() {
  const doc = await api("GET", "/openapi.json");
  const examples = doc.ok ? doc.data.paths["/v1/studies/electrification"].post.requestBody
    .content["application/json"].examples : {};
  const first = Object.values(examples)[0];
  if (first) $("study-json").value = JSON.stringify(first.value, null, 1);
}

function studyStatus(text) { $("study-status").textContent = text; }

async function readExport() {
  // A telematics export (one row per stop) made into the study's days by the service; the
  // study's other fields from the request above (its routes: id, depot, product).
  const file = $("study-csv").files[0];
  if (!file) return;
  let study;
  try { study = JSON.parse($("study-json").value); } catch (error) {
    studyStatus(`The study request is not JSON: ${error.message}`);
    return;
  }
  for (const route of study.routes || []) {
    delete route.stops; delete route.start_time; delete route.days;
  }
  const form = new FormData();
  form.append("study", JSON.stringify(study));
  form.append("history", file);
  const headers = { Accept: "application/json" };
  if ($("api-key").value) headers["X-API-Key"] = $("api-key").value;
  const response = await fetch("/v1/studies/electrification/from-csv", { method: "POST", headers, body: form });
  const data = await response.json().catch(() => null);
  if (!response.ok) { studyStatus(problemText({ status: response.status, data })); return; }
  $("study-json").value = JSON.stringify(data, null, 1);
  const days = data.routes.reduce((n, r) => n + r.days.length, 0);
  studyStatus(`${file.name}: ${days} route-days read. Run the study.`);
}

async function runStudy() {
  let request;
  try { request = JSON.parse($("study-json").value); } catch (error) {
    studyStatus(`The study request is not JSON: ${error.message}`);
    return;
  }
  $("study-run").disabled = true;
  try {
    const submitted = await api("POST", "/v1/jobs", {
      type: "electrification", request: { ...request, include_days: true },
    });
    if (!submitted.ok) { studyStatus(problemText(submitted)); return; }
    study.job = submitted.data.id;
    $("study-cancel").hidden = false;
    const done = await waitForJob(submitted.data.id);
    if (done.status !== "succeeded") {
      studyStatus(`Study job ${done.id}: ${done.status}${done.error ? `, ${done.error.detail}` : ""}`);
      return;
    }
    study.answer = done.result;
    studyStatus(`${done.result.route_days} route-days studied.`);
    drawStudy();
  } finally {
    $("study-run").disabled = false;
    $("study-cancel").hidden = true;
    study.job = null;
  }
}

async function cancelStudy() {
  // The job's parts stop on every worker; waitForJob then sees it cancelled.
  if (study.job) await api("DELETE", `/v1/jobs/${encodeURIComponent(study.job)}`);
}

function progressText(job) {
  const p = job.progress;
  if (!p || !p.total) return `${job.status}…`;
  const share = Math.floor((100 * p.done) / p.total);
  return `${job.status}: ${p.done.toLocaleString("en")} of ${p.total.toLocaleString("en")} ` +
    `route-days × candidates (${share} %, ${p.parts_done} of ${p.parts_total} parts)…`;
}

function problemText(answer) {
  const problem = answer.data || {};
  const fields = (problem.errors || []).map((e) => `${e.field}: ${e.message}`).join("; ");
  return fields || problem.detail || `The service answered ${answer.status}.`;
}

async function waitForJob(jobId) {
  for (;;) {
    const answer = await api("GET", `/v1/jobs/${encodeURIComponent(jobId)}`);
    if (!answer.ok) return { id: jobId, status: "failed", error: { detail: problemText(answer) } };
    const job = answer.data;
    if (["succeeded", "failed", "cancelled"].includes(job.status)) return job;
    studyStatus(`Study job ${job.id}: ${progressText(job)}`);
    await new Promise((resolve) => setTimeout(resolve, 1000));
  }
}

function drawStudy() {
  const ids = study.answer.routes[0].candidates.map((c) => c.id);
  const select = $("study-candidate");
  select.replaceChildren(...ids.map((id) => el("option", { value: id }, id)));
  select.onchange = () => drawCandidate(select.value);
  $("study-output").hidden = false;
  drawCandidate(ids[0]);
}

function outcomeOf(route, candidateId) { return route.candidates.find((c) => c.id === candidateId); }

function drawCandidate(candidateId) {
  const routes = study.answer.routes;
  const fleet = study.answer.fleet.find((f) => f.id === candidateId);
  $("study-fleet").textContent = `${candidateId}: ${fleet.routes_all_year} of ${routes.length} ` +
    `route(s) all year on one charge, ${fleet.routes_p95} on 95 % of days` +
    (fleet.routes_all_year_with_charging === null ? "" : `, ${fleet.routes_all_year_with_charging} all year with the charges`) +
    `; the depot recharges at most ${fleet.depot_kwh_max_day.toFixed(1)} kWh a day. ` +
    `Weather: ${study.answer.weather_source}${study.answer.warnings.length ? ` (${study.answer.warnings.join("; ")})` : ""}.`;
  drawHeatMap(routes, candidateId);
  drawCoverage(routes, candidateId);
}

function cellClass(day) {
  if (day.margin_kwh >= 0) return "covered";
  return day.covered_with_charging ? "charged" : "short";
}

function drawHeatMap(routes, candidateId) {
  // One row per route, one cell per day driven: its margin above the reserve, in colour.
  const table = el("table", { class: "heat", "data-testid": "study-heatmap" });
  for (const route of routes) {
    const outcome = outcomeOf(route, candidateId);
    const row = el("tr", { "data-route": route.id });
    row.appendChild(el("th", { scope: "row" }, `${route.id} · ${outcome.days_feasible}/${outcome.days_total}`));
    const cells = el("td");
    for (const day of outcome.days) {
      const cell = el("span", {
        class: `day ${cellClass(day)}`,
        title: `${day.date}: ${day.margin_kwh >= 0 ? "+" : ""}${day.margin_kwh.toFixed(1)} kWh above the reserve, lowest ${Math.round(day.min_soc * 100)} %`,
      });
      cells.appendChild(cell);
    }
    row.appendChild(cells);
    table.appendChild(row);
  }
  $("study-heatmap").replaceChildren(table);
}

function coverageCurve(routes, candidateId) {
  // The share of route-days whose need a usable capacity covers, capacity by capacity.
  const needs = routes.flatMap((r) => outcomeOf(r, candidateId).days.map((d) => d.required_kwh)).sort((a, b) => a - b);
  const kwh = needs.map((n) => Math.round(n * 10) / 10);
  const share = needs.map((_, k) => (k + 1) / needs.length * 100);
  return [kwh, share];
}

function drawCoverage(routes, candidateId) {
  if (study.plot) study.plot.destroy();
  const holder = $("study-coverage");
  holder.replaceChildren();
  const font = "13px system-ui, sans-serif";
  study.plot = new uPlot({
    width: Math.max(holder.clientWidth - 14, 300), height: 260,
    scales: { x: { time: false }, y: { range: [0, 100] } },
    axes: [
      { font, label: "usable battery [kWh]", labelFont: font, stroke: "#1d2733", grid: { stroke: "#e3e8ee" } },
      { font, label: "route-days covered [%]", labelFont: font, size: 60, stroke: "#1d2733", grid: { stroke: "#e3e8ee" } },
    ],
    series: [{ label: "battery (kWh)" }, { label: "covered (%)", stroke: "#1f77b4", width: 2, paths: uPlot.paths.stepped({ align: 1 }) }],
  }, coverageCurve(routes, candidateId), holder);
}

document.addEventListener("DOMContentLoaded", () => {
  $("study-example").addEventListener("click", () => loadStudyExample().catch((error) => studyStatus(`Unexpected: ${error.message}`)));
  $("study-run").addEventListener("click", () => runStudy().catch((error) => studyStatus(`Unexpected: ${error.message}`)));
  $("study-cancel").addEventListener("click", () => cancelStudy().catch((error) => studyStatus(`Unexpected: ${error.message}`)));
  $("study-csv").addEventListener("change", () => readExport().catch((error) => studyStatus(`Unexpected: ${error.message}`)));
});

window.coldrouteStudy = { answer: () => study.answer, coverage: () => study.plot && study.plot.data };
