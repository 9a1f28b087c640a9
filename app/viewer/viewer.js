// coldroute plan viewer: the stops from a CSV (or a pasted request), planned by the service,
// drawn with Leaflet (the map, its markers clustered) and uPlot (the charts), both vendored
// into the service: nothing from another host but the optional map tiles.
/* global L, uPlot */
"use strict";

const CONSUMERS = ["traction", "auxiliaries", "cabin", "refrigeration"];
const CONSUMER_COLOURS = {
  traction: "#4c78a8", auxiliaries: "#c4570a", cabin: "#3b7d32", refrigeration: "#c03a3a",
};
const ROUTE_COLOURS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b",
  "#e377c2", "#17becf", "#bcbd22", "#7f7f7f"];
// The columns the CSV reads; any other column is kept as it is and shown (address, notes…).
const CSV_COLUMNS = ["id", "lat", "lon", "service_min", "door_min", "kg", "window_start",
  "window_end", "product"];
// Larger requests go as a job: polled, with progress, and reopened by /viewer?job=<id>.
const SYNC_MAX_STOPS = 60;
const SYNC_MAX_TIME_LIMIT_S = 10;
// A stop farther than this from the depot is flagged before planning (the service warns too).
const FAR_STOP_KM = 300;
// Stop markers nearer each other than this on screen are clustered [px] (a marker is 22 px).
const CLUSTER_RADIUS_PX = 26;
// Shaded spans in the charts: what the van does then, and its colour.
const SPANS = {
  charge: ["charging", "rgba(60, 160, 60, 0.22)"],
  break: ["driver's break", "rgba(123, 97, 196, 0.2)"],
  reload: ["reloading at the depot", "rgba(230, 140, 30, 0.22)"],
  door: ["door open at a stop", "rgba(120, 120, 120, 0.2)"],
};

const state = {
  request: null, endpoint: null, answer: null, routes: [], places: {}, extras: {},
  columns: [], charts: [], jobId: null,
  // The plans shown in this page, to compare; and the stops' order per van as edited.
  history: [], order: {}, changed: new Set(),
  // Stops pinned to a van for the next re-plan of the fleet: stop id → van id.
  pins: {},
};
let polling = null;
let map = null;
let planLayer = null;
let tiles = null;

function $(id) { return document.getElementById(id); }

function el(tag, attributes = {}, text = null) {
  const node = document.createElement(tag);
  for (const [key, value] of Object.entries(attributes)) node.setAttribute(key, value);
  if (text !== null) node.textContent = text;
  return node;
}

// ---------------------------------------------------------------- numbers and times

function fixed(x, digits) {
  // No negative zero: "-0.00" reads as a loss where there is none.
  const text = x.toFixed(digits);
  return Number(text) === 0 ? (0).toFixed(digits) : text;
}
function percent(x) { return `${fixed(100 * x, 0)} %`; }
function kwh(x) { return `${fixed(x, 1)} kWh`; }
function km(m) { return `${fixed(m / 1000, 1)} km`; }
function celsius(x) { return x === null || x === undefined ? "" : `${fixed(x, 1)} °C`; }
function minutes(s) { return `${fixed(s / 60, 0)} min`; }
function localTime(iso) { return iso ? iso.slice(11, 16) : ""; }

function offsetSeconds(iso) {
  // The UTC offset an ISO time carries (the plan's own zone), in seconds.
  const match = /([+-])(\d\d):?(\d\d)$/.exec(iso);
  if (!match) return 0;
  return (match[1] === "-" ? -1 : 1) * (Number(match[2]) * 3600 + Number(match[3]) * 60);
}

function wallClock(iso) {
  // The plan's local wall-clock time as seconds of a UTC clock: the charts read it in UTC, so
  // they show the plan's local time whatever the browser's zone.
  return Date.parse(iso) / 1000 + offsetSeconds(iso);
}

function distanceKm(a, b) {
  const rad = Math.PI / 180;
  const h = Math.sin(((b.lat - a.lat) * rad) / 2) ** 2 +
    Math.cos(a.lat * rad) * Math.cos(b.lat * rad) * Math.sin(((b.lon - a.lon) * rad) / 2) ** 2;
  return 2 * 6371.0088 * Math.asin(Math.min(1, Math.sqrt(h)));
}

// ---------------------------------------------------------------- messages

function showError(message) {
  $("errors").appendChild(el("li", { class: "error", "data-testid": "error" }, message));
  $("messages").scrollIntoView({ block: "nearest" });
}

function flag(message) {
  $("flags").appendChild(el("li", { class: "warning", "data-testid": "flag" }, message));
}

function clearMessages() {
  $("errors").replaceChildren();
  $("flags").replaceChildren();
  $("status").textContent = "";
}

function showProblem(problem, status) {
  clearPlan();
  if (problem && Array.isArray(problem.errors) && problem.errors.length) {
    for (const entry of problem.errors) showError(`${entry.field}: ${entry.message}`);
  } else if (problem && problem.detail) {
    showError(`${problem.title || "Error"} (${status}): ${problem.detail}`);
  } else {
    showError(`The service answered ${status}.`);
  }
}

class CsvError extends Error {}

// ---------------------------------------------------------------- the API

async function api(method, path, body) {
  const headers = { Accept: "application/json" };
  const key = $("api-key").value;
  if (key) headers["X-API-Key"] = key;
  if (body !== undefined) headers["Content-Type"] = "application/json";
  const response = await fetch(path, {
    method, headers, body: body === undefined ? undefined : JSON.stringify(body),
  });
  let data = null;
  try { data = await response.json(); } catch (_) { data = null; }
  return { ok: response.ok, status: response.status, data };
}

const vans = { options: [] };

async function loadVans() {
  const presets = await api("GET", "/v1/presets");
  const profiles = await api("GET", "/v1/vehicle-profiles");
  if (!presets.ok) {
    vans.options = [["Presets", [["preset:paper-generic", "paper-generic"]]]];
    if (presets.status === 401) $("status").textContent = "Enter the API key to list the vans.";
  } else {
    // A preset that carries no payload (a reference car) cannot make deliveries.
    const carriers = presets.data.presets.filter((p) => p.payload_kg > 0);
    vans.options = [["Presets", carriers.map((p) => [`preset:${p.name}`,
      `${p.name} (${fixed(p.battery.usable_capacity_kwh, 0)} kWh, ${fixed(p.payload_kg, 0)} kg)`])]];
    if (profiles.ok && profiles.data.profiles.length) {
      vans.options.push(["Vehicle profiles", profiles.data.profiles.map((p) => [`profile:${p.name}`, p.name])]);
    }
  }
  for (const select of document.querySelectorAll("select.van-kind")) fillVanKinds(select);
}

function fillVanKinds(select) {
  const chosen = select.value;
  select.replaceChildren();
  for (const [label, options] of vans.options) {
    const group = el("optgroup", { label });
    for (const [value, text] of options) group.appendChild(el("option", { value }, text));
    select.appendChild(group);
  }
  const values = [...select.options].map((o) => o.value);
  if (select.dataset.chosen && values.includes(chosen)) select.value = chosen;
  else if (values.includes("preset:ev-van-3.5t-reefer")) select.value = "preset:ev-van-3.5t-reefer";
}

function addVanRow(first = false) {
  // One kind of van: its model, how many, its battery and payload, its driver's shift.
  const row = el("div", { class: "van-row", "data-testid": "van-row" });
  const field = (label, input) => {
    const wrap = el("label");
    wrap.append(el("span", {}, label), input);
    return wrap;
  };
  const kind = el("select", { class: "van-kind" });
  kind.addEventListener("change", () => { kind.dataset.chosen = "yes"; });
  const count = el("input", { type: "number", class: "van-count", min: "1", max: "100", value: "2" });
  const battery = el("input", { type: "number", class: "battery-kwh", min: "1", step: "any", placeholder: "the van's" });
  const payload = el("input", { type: "number", class: "payload-kg", min: "0", step: "any", placeholder: "the van's" });
  const start = el("input", { type: "time", class: "shift-start", value: "06:30", "aria-label": "Shift start" });
  const end = el("input", { type: "time", class: "shift-end", value: "16:30", "aria-label": "Shift end" });
  if (first) {
    kind.id = "van-kind";
    count.id = "van-count";
    count.dataset.testid = "van-count";
    battery.id = "battery-kwh";
    payload.id = "payload-kg";
    start.id = "shift-start";
    end.id = "shift-end";
  }
  const shift = el("label");
  shift.append(el("span", {}, "Shift"), start, " – ", end);
  row.append(field("Van", kind), field("How many", count), field("Battery [kWh]", battery),
    field("Payload [kg]", payload), shift);
  if (!first) {
    const remove = el("button", { type: "button", class: "secondary" }, "Remove");
    remove.addEventListener("click", () => row.remove());
    row.appendChild(remove);
  }
  $("van-rows").appendChild(row);
  fillVanKinds(kind);
  return row;
}

// ---------------------------------------------------------------- CSV of stops

function splitCsvLine(line, delimiter) {
  const cells = [];
  let cell = "";
  let quoted = false;
  for (let i = 0; i < line.length; i += 1) {
    const c = line[i];
    if (quoted) {
      if (c === '"' && line[i + 1] === '"') { cell += '"'; i += 1; }
      else if (c === '"') quoted = false;
      else cell += c;
    } else if (c === '"') quoted = true;
    else if (c === delimiter) { cells.push(cell); cell = ""; }
    else cell += c;
  }
  cells.push(cell);
  return cells.map((x) => x.trim());
}

function clockOf(raw) {
  // H:MM, HH:MM or HH:MM:SS as the service's HH:MM (seconds must be 00), or null.
  const match = /^(\d{1,2}):([0-5]\d)(?::([0-5]\d))?$/.exec(raw);
  if (!match || Number(match[1]) > 23 || (match[3] && match[3] !== "00")) return null;
  return `${match[1].padStart(2, "0")}:${match[2]}`;
}

function parseStopsCsv(text, depot) {
  const lines = text.replace(/^\ufeff/, "").split(/\r\n|\n|\r/);
  while (lines.length && !lines[lines.length - 1].trim()) lines.pop();
  if (!lines.length || !lines[0].trim()) throw new CsvError("The CSV is empty: it needs a header row.");
  const delimiter = (lines[0].match(/;/g) || []).length > (lines[0].match(/,/g) || []).length ? ";" : ",";
  const names = splitCsvLine(lines[0], delimiter);
  const header = names.map((h) => h.toLowerCase());
  for (const needed of ["id", "lat", "lon"]) {
    if (!header.includes(needed)) throw new CsvError(`Header row: the column “${needed}” is missing.`);
  }
  header.forEach((name, k) => {
    if (!name) throw new CsvError(`Header row, column ${k + 1}: it has no name.`);
    if (header.indexOf(name) !== k) throw new CsvError(`Header row: the column “${names[k]}” appears twice.`);
  });
  const kept = names.filter((_, k) => !CSV_COLUMNS.includes(header[k]));
  const stops = [];
  const extras = {};
  const seen = new Set();
  const products = new Set();
  for (let i = 1; i < lines.length; i += 1) {
    if (!lines[i].trim()) continue;
    const row = stops.length + 1;
    const where = (column) => `Row ${row} (line ${i + 1}), column “${column}”`;
    const cells = splitCsvLine(lines[i], delimiter);
    if (cells.length !== header.length) {
      throw new CsvError(`Row ${row} (line ${i + 1}): ${cells.length} cells, the header has ${header.length}.`);
    }
    const value = Object.fromEntries(header.map((h, k) => [h, cells[k]]));
    const number = (column, low, high, fallback) => {
      const raw = value[column];
      if (raw === undefined || raw === "") {
        if (fallback === undefined) throw new CsvError(`${where(column)}: empty, a number is needed.`);
        return fallback;
      }
      const text = delimiter === ";" ? raw.replace(",", ".") : raw;
      if (!/^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$/.test(text)) {
        throw new CsvError(`${where(column)}: “${raw}” is not a number.`);
      }
      const x = Number(text);
      if (x < low || x > high) throw new CsvError(`${where(column)}: ${raw} is outside ${low}…${high}.`);
      return x;
    };
    const clock = (column) => {
      const raw = value[column] || "";
      if (!raw) return null;
      const time = clockOf(raw);
      if (time === null) {
        throw new CsvError(`${where(column)}: “${raw}” is not a time of day (H:MM, HH:MM or HH:MM:SS).`);
      }
      return time;
    };
    const id = value.id;
    if (!id) throw new CsvError(`${where("id")}: empty; every stop needs an id.`);
    if (seen.has(id)) throw new CsvError(`${where("id")}: “${id}” is used by an earlier row.`);
    seen.add(id);
    const stop = {
      id,
      lat: number("lat", -90, 90),
      lon: number("lon", -180, 180),
      service_time_s: 60 * number("service_min", 0, 1440, 5),
      door_open_s: 60 * number("door_min", 0, 1440, 2),
      delivery_kg: number("kg", 0, 40000, 0),
    };
    if (depot) {
      const away = distanceKm(depot, stop);
      const swapped = distanceKm(depot, { lat: stop.lon, lon: stop.lat });
      if (away > FAR_STOP_KM && swapped <= FAR_STOP_KM && Math.abs(stop.lon) <= 90) {
        throw new CsvError(`Row ${row} (line ${i + 1}), “${id}”: lat ${stop.lat} and lon ${stop.lon} look swapped ` +
          `— ${fixed(away, 0)} km from the depot as given, ${fixed(swapped, 0)} km swapped.`);
      }
      if (away > FAR_STOP_KM) {
        flag(`Row ${row} (line ${i + 1}), “${id}”: ${fixed(away, 0)} km from the depot — check its coordinates.`);
      }
    }
    const start = clock("window_start");
    const end = clock("window_end");
    if ((start === null) !== (end === null)) {
      throw new CsvError(`${where(start === null ? "window_start" : "window_end")}: a window needs both its start and its end.`);
    }
    if (start !== null) {
      if (end <= start) throw new CsvError(`${where("window_end")}: ${end} is not after ${start}.`);
      stop.time_windows = [{ start, end }];
    }
    if (value.product) products.add(value.product);
    extras[id] = Object.fromEntries(names.map((n, k) => [n, cells[k]]).filter(([n]) => kept.includes(n)));
    stops.push(stop);
  }
  if (!stops.length) throw new CsvError("The CSV has a header row but no stop.");
  if (products.size > 1) {
    throw new CsvError(`Column “product”: one box carries one product; the rows name ${[...products].join(", ")}.`);
  }
  return { stops, extras, columns: kept, product: [...products][0] || null };
}

function depotOf() {
  const depot = $("depot").value.split(/[,;\s]+/).filter(Boolean).map(Number);
  if (depot.length !== 2 || depot.some((x) => !Number.isFinite(x)) || Math.abs(depot[0]) > 90 || Math.abs(depot[1]) > 180) {
    throw new CsvError("Depot: give its latitude and longitude, e.g. 48.1703, 16.4207.");
  }
  return { lat: depot[0], lon: depot[1] };
}

async function readStopsFile(depot) {
  const file = $("stops-csv").files[0];
  if (!file) throw new CsvError("Choose a CSV file of stops, or paste a request.");
  return parseStopsCsv(await file.text(), depot);
}

function formVehicles(cargoBox, refrigeration) {
  const vehicles = [];
  let n = 0;
  for (const row of document.querySelectorAll(".van-row")) {
    const count = Number(row.querySelector(".van-count").value);
    if (!Number.isInteger(count) || count < 1 || count > 100) {
      throw new CsvError("How many vans: a whole number from 1 to 100 in each row.");
    }
    const [kind, name] = row.querySelector(".van-kind").value.split(/:(.*)/s);
    const battery = row.querySelector(".battery-kwh").value;
    const payload = row.querySelector(".payload-kg").value;
    for (let k = 0; k < count; k += 1) {
      n += 1;
      const van = {
        id: `van-${n}`,
        vehicle: kind === "profile" ? { profile: name } : { preset: name || "paper-generic" },
        shift_start: row.querySelector(".shift-start").value,
        shift_end: row.querySelector(".shift-end").value,
      };
      if (battery) van.battery = { usable_capacity_kwh: Number(battery) };
      if (payload) van.payload_kg = Number(payload);
      if (cargoBox) van.cargo_box = cargoBox;
      if (refrigeration) van.refrigeration = refrigeration;
      vehicles.push(van);
    }
  }
  if (vehicles.length > 100) throw new CsvError(`Vans: at most 100 in all, the rows ask for ${vehicles.length}.`);
  return vehicles;
}

function formRequest(parsed, depot) {
  if (!$("date").value) throw new CsvError("Date: choose the day to plan.");
  const product = $("product").value || parsed.product;
  const strategy = $("strategy").value;
  if (strategy === "optimal" && !product) {
    throw new CsvError("Unit: the optimal schedule keeps a product in its band — choose the product.");
  }
  // The optimal strategy plans a unit of finite capacity: the dynamic box.
  const cargoBox = product ? { product, mode: "dynamic" } : null;
  const body = {
    date: $("date").value,
    timezone: $("timezone").value || null,
    depot: { id: "depot", lat: depot.lat, lon: depot.lon },
    stops: parsed.stops,
    vehicles: formVehicles(cargoBox, strategy === "optimal" ? { strategy } : null),
    time_limit_s: Number($("time-limit").value) || 3,
  };
  const low = $("t-min").value;
  const high = $("t-max").value;
  if ((low === "") !== (high === "")) throw new CsvError("Weather: give both the low and the high, or neither.");
  if (low !== "") body.weather = { t_min_c: Number(low), t_max_c: Number(high) };
  return body;
}

// ---------------------------------------------------------------- planning

async function plan(event) {
  event.preventDefault();
  clearMessages();
  stopPolling();
  let body;
  const pasted = $("request-json").value.trim();
  state.extras = {};
  state.columns = [];
  try {
    if (pasted) {
      try { body = JSON.parse(pasted); } catch (error) {
        throw new CsvError(`The pasted request is not JSON: ${error.message}`);
      }
      if (!body || typeof body !== "object" || !Array.isArray(body.stops)) {
        throw new CsvError("The pasted request needs its stops[] (the body of /v1/plans or /v1/fleet-plans).");
      }
    } else {
      const depot = depotOf();
      const parsed = await readStopsFile(depot);
      body = formRequest(parsed, depot);
      state.extras = parsed.extras;
      state.columns = parsed.columns;
    }
  } catch (error) {
    if (error instanceof CsvError) { clearPlan(); showError(error.message); return; }
    throw error;
  }
  await submit(body);
}

async function submit(request, label = null) {
  // Planned at once when small and quick, else as a job followed to its end.
  const endpoint = Array.isArray(request.vehicles) ? "fleet-plans" : "plans";
  // What the viewer draws: the roads (where a router gives them) and the day minute by minute.
  const body = { ...request, include_geometry: true, include_profile: true };
  const limit = body.time_limit_s ?? 1;
  if (body.stops.length > SYNC_MAX_STOPS || limit > SYNC_MAX_TIME_LIMIT_S) {
    const submitted = await api("POST", "/v1/jobs", {
      type: endpoint === "plans" ? "plan" : "fleet-plan", request: body,
    });
    if (!submitted.ok) { showProblem(submitted.data, submitted.status); return; }
    history.replaceState(null, "", `/viewer?job=${encodeURIComponent(submitted.data.id)}`);
    follow(submitted.data.id, body, endpoint);
    return;
  }
  $("plan").disabled = true;
  $("status").textContent = `Planning ${body.stops.length} stops…`;
  try {
    const answer = await api("POST", `/v1/${endpoint}`, body);
    if (!answer.ok) { $("status").textContent = ""; showProblem(answer.data, answer.status); return; }
    $("status").textContent = "Planned.";
    show(body, endpoint, answer.data, null, label);
  } finally {
    $("plan").disabled = false;
  }
}

function stopPolling() {
  if (polling !== null) clearTimeout(polling);
  polling = null;
  $("cancel").hidden = true;
  $("progress").hidden = true;
}

function follow(jobId, request, endpoint) {
  const began = Date.now();
  $("cancel").hidden = false;
  $("cancel").onclick = async () => {
    const answer = await api("DELETE", `/v1/jobs/${encodeURIComponent(jobId)}`);
    if (!answer.ok) showProblem(answer.data, answer.status);
  };
  const progress = $("progress");
  progress.hidden = false;
  const tick = async () => {
    const answer = await api("GET", `/v1/jobs/${encodeURIComponent(jobId)}?include_request=true`);
    if (!answer.ok) {
      stopPolling();
      showProblem(answer.data, answer.status);
      if (answer.status === 401) showError("Enter the API key above to open this job.");
      return;
    }
    const job = answer.data;
    const asked = job.request || request;
    const budget = (asked && asked.time_limit_s) || 1;
    const running = job.started_at ? (Date.now() - Date.parse(job.started_at)) / 1000 : 0;
    progress.value = job.status === "running" ? Math.min(running / (budget + 2), 0.95) : 0;
    $("status").textContent = `Job ${job.id}: ${job.status}` +
      (job.status === "running" ? ` (${Math.round(running)} s of about ${Math.ceil(budget)} s)` :
        job.status === "queued" ? ` (${Math.round((Date.now() - began) / 1000)} s waiting)` : "");
    if (job.status === "succeeded") {
      stopPolling();
      show(asked, job.type === "plan" ? "plans" : "fleet-plans", job.result, job.id);
    } else if (job.status === "failed") {
      stopPolling();
      showProblem(job.error, job.error && job.error.status);
    } else if (job.status === "cancelled") {
      stopPolling();
      showError(`Job ${job.id} was cancelled.`);
    } else {
      polling = setTimeout(tick, 1000);
    }
  };
  tick();
}

// ---------------------------------------------------------------- the answer

function routesOf(endpoint, answer) {
  if (endpoint === "plans") return [{ ...answer, vehicle_id: "van" }];
  return answer.routes;
}

function vanOf(request, vehicleId) {
  if (request && Array.isArray(request.vehicles)) {
    return request.vehicles.find((v) => v.id === vehicleId) || {};
  }
  return request || {};
}

function clearPlan() {
  // A failed request leaves no earlier plan on screen to be taken for its answer.
  state.request = null;
  state.answer = null;
  state.routes = [];
  for (const chart of state.charts) chart.destroy();
  state.charts = [];
  if (planLayer) planLayer.clearLayers();
  $("routes").replaceChildren();
  $("fleet-card").hidden = true;
  $("assumptions-card").hidden = true;
  $("work-card").hidden = true;
  state.changed.clear();
  $("export-csv").disabled = true;
  $("export-geojson").disabled = true;
  if (map) map.legend.update();
}

function show(request, endpoint, answer, jobId = null, label = null) {
  clearPlan();
  state.request = request;
  state.endpoint = endpoint;
  state.answer = answer;
  state.jobId = jobId;
  state.routes = routesOf(endpoint, answer);
  state.order = Object.fromEntries(state.routes.map((r) => [r.vehicle_id, r.stops.map((x) => x.id)]));
  state.pins = {};
  for (const van of (request && request.vehicles) || []) {
    for (const stopId of van.pinned_stops || []) state.pins[stopId] = van.id;
  }
  remember(request, endpoint, answer, jobId, label);
  state.places = {};
  if (request) {
    if (request.depot) state.places[request.depot.id] = request.depot;
    for (const stop of request.stops || []) state.places[stop.id] = stop;
    for (const charger of request.chargers || []) state.places[charger.id] = charger;
  }
  for (const route of state.routes) {
    for (const leg of route.legs) {
      const line = leg.geometry && leg.geometry.coordinates;
      if (line && line.length) {
        if (!state.places[leg.from_id]) state.places[leg.from_id] = { lon: line[0][0], lat: line[0][1] };
        const last = line[line.length - 1];
        if (!state.places[leg.to_id]) state.places[leg.to_id] = { lon: last[0], lat: last[1] };
      }
    }
  }
  drawMap();
  drawFleet();
  drawAssumptions();
  drawRoutes();
  drawWork();
  $("export-csv").disabled = false;
  $("export-geojson").disabled = false;
}

function unassignedOf() {
  return state.endpoint === "plans" || !state.answer ? [] : (state.answer.unassigned || []);
}

function colourOf(index) { return ROUTE_COLOURS[index % ROUTE_COLOURS.length]; }

// ---------------------------------------------------------------- the map

function createMap() {
  map = L.map("map", { zoomSnap: 0.25, keyboard: true, maxZoom: 19 });
  map.setView([48.2, 16.37], 11);
  const url = document.body.dataset.tileUrl;
  if (url) {
    tiles = L.tileLayer(url, {
      attribution: document.body.dataset.tileAttribution || "", subdomains: "abc", maxZoom: 19,
    });
    // A tile that fails (offline, server down) takes the layer away: the plan's own legs on
    // the plain background, and a note — never a field of broken images.
    tiles.on("tileerror", () => {
      if (!map.hasLayer(tiles)) return;
      map.removeLayer(tiles);
      mapNote(`The map tiles could not be loaded from ${new URL(url.replace("{s}", "a")).host}: ` +
        "the plan's own legs on a plain background.");
    });
    tiles.addTo(map);
  } else {
    mapNote("No map tiles are configured (COLDROUTE_TILE_URL): the plan's own legs on a plain background.");
  }
  const scale = L.control.scale({ imperial: false, maxWidth: 160 }).addTo(map);
  scale.getContainer().dataset.testid = "scale-bar";
  planLayer = L.featureGroup().addTo(map);
  map.legend = legendControl().addTo(map);
}

function mapNote(text) {
  const note = $("map-note");
  note.textContent = text;
  note.hidden = false;
  $("map").classList.add("no-tiles");
}

function legendControl() {
  const control = L.control({ position: "topright" });
  control.onAdd = () => {
    const box = el("div", { class: "map-legend", "data-testid": "map-legend" });
    box.hidden = true;
    control.box = box;
    return box;
  };
  control.update = () => {
    const box = control.box;
    box.replaceChildren();
    if (!state.routes.length) { box.hidden = true; return; }
    box.hidden = false;
    box.appendChild(el("b", {}, "Legend"));
    state.routes.forEach((route, r) => {
      const item = el("button", { type: "button", class: "legend-route", "data-vehicle": route.vehicle_id });
      const swatch = el("span", { class: "swatch" });
      swatch.style.background = colourOf(r);
      item.append(swatch, `${route.vehicle_id}: ${route.stops.length} stops`);
      item.addEventListener("mouseenter", () => highlight(route.vehicle_id));
      item.addEventListener("focus", () => highlight(route.vehicle_id));
      item.addEventListener("mouseleave", () => highlight(null));
      item.addEventListener("blur", () => highlight(null));
      box.appendChild(item);
    });
    const symbols = [["depot-icon", "", "depot"], ["charge-icon", "⚡", "charge"],
      ["break-icon", "☕", "driver's break"], ["reload-icon", "↺", "reload at the depot"],
      ["unassigned-icon", "✕", "not served"]];
    for (const [cls, text, label] of symbols) {
      const row = el("div");
      row.append(el("span", { class: `legend-symbol ${cls}` }, text), ` ${label}`);
      box.appendChild(row);
    }
    if (state.routes.some((route) => route.legs.some((leg) => !(leg.geometry && leg.geometry.coordinates)))) {
      const row = el("div");
      row.append(el("span", { class: "legend-dash" }), " straight line: no road geometry");
      box.appendChild(row);
    }
  };
  return control;
}

function routeLine(route) {
  // The route's road geometry where the router gave it; else straight between its places.
  const points = [];
  let straight = false;
  for (const leg of route.legs) {
    const line = leg.geometry && leg.geometry.coordinates;
    if (line && line.length > 1) {
      for (const [lon, lat] of line) points.push([lat, lon]);
    } else {
      straight = true;
      for (const id of [leg.from_id, leg.to_id]) {
        const place = state.places[id];
        if (place) points.push([place.lat, place.lon]);
      }
    }
  }
  return { points, straight };
}

function icon(cls, text, attributes, colour) {
  const node = el("span", { class: `map-icon ${cls}`, ...attributes }, text);
  if (colour) node.style.borderColor = colour;
  return L.divIcon({ className: "map-icon-holder", html: node, iconSize: null });
}

function marker(lat, lon, divIcon, tooltip, vehicleId) {
  // tooltip: HTML with the client's texts escaped, lines split by newlines.
  const m = L.marker([lat, lon], { icon: divIcon, keyboard: true });
  m.bindTooltip(tooltip.replace(/\n/g, "<br>"), { direction: "top" });
  const label = new DOMParser().parseFromString(tooltip, "text/html").body.textContent.replace(/\n/g, "; ");
  m.on("add", () => {
    m.getElement().setAttribute("aria-label", label);
    m.getElement().setAttribute("role", "button");
  });
  if (vehicleId) {
    m.on("mouseover focus", () => highlight(vehicleId));
    m.on("mouseout blur", () => highlight(null));
  }
  return m;
}

function escapeHtml(text) {
  return String(text).replace(/&/g, "&amp;").replace(/</g, "&lt;").replace(/>/g, "&gt;");
}

function drawMap() {
  planLayer.clearLayers();
  state.lines = {};
  // Stops closer on screen than a marker's width are clustered (the cluster says how many;
  // a click zooms in): numbers never overlap, at 7 stops or 700.
  const stopsLayer = L.markerClusterGroup({
    maxClusterRadius: CLUSTER_RADIUS_PX, disableClusteringAtZoom: 18, showCoverageOnHover: false,
    iconCreateFunction: (cluster) => L.divIcon({
      html: el("span", { "aria-label": `${cluster.getChildCount()} stops here: zoom in` }, String(cluster.getChildCount())),
      className: "marker-cluster stop-cluster", iconSize: L.point(24, 24),
    }),
  });
  stopsLayer.addTo(planLayer);
  state.stopsLayer = stopsLayer;
  state.routes.forEach((route, r) => {
    const colour = colourOf(r);
    const { points, straight } = routeLine(route);
    const line = L.polyline(points, {
      color: colour, weight: 4, opacity: 0.85, dashArray: straight ? "8 6" : null,
    }).addTo(planLayer);
    line.bindTooltip(`${escapeHtml(route.vehicle_id)}: ${km(route.totals.distance_m)}, ${kwh(route.totals.energy_kwh.total)}`, { sticky: true });
    const path = line.getElement();
    path.setAttribute("data-testid", "route-line");
    path.setAttribute("data-vehicle", route.vehicle_id);
    path.setAttribute("data-points", String(points.length));
    line.on("mouseover", () => highlight(route.vehicle_id));
    line.on("mouseout", () => highlight(null));
    state.lines[route.vehicle_id] = line;
    route.stops.forEach((stop, k) => {
      const place = state.places[stop.id];
      if (!place) return;
      const windows = (place.time_windows || []).map((w) => `${w.start}–${w.end}`).join(", ") || "none";
      const extra = Object.entries(state.extras[stop.id] || {}).filter(([, v]) => v)
        .map(([name, v]) => `\n${escapeHtml(name)}: ${escapeHtml(v)}`).join("");
      const tooltip = `${escapeHtml(route.vehicle_id)} · ${k + 1}. ${escapeHtml(stop.id)}${extra}\n` +
        `arrive ${localTime(stop.arrival)}, window ${windows}, leave ${localTime(stop.departure)}\n` +
        `SoC ${percent(stop.soc_arrival)} → ${percent(stop.soc_departure)}`;
      stopsLayer.addLayer(marker(place.lat, place.lon, icon("stop-icon", String(k + 1), {
        "data-testid": "stop-marker", "data-stop": stop.id, "data-vehicle": route.vehicle_id,
      }, colour), tooltip, route.vehicle_id));
    });
    for (const charge of route.charges || []) {
      marker(charge.lat, charge.lon, icon("charge-icon", "⚡", { "data-testid": "charge-marker" }),
        `${escapeHtml(route.vehicle_id)} charges at ${escapeHtml(charge.charger_id)} ${localTime(charge.arrive)}–` +
        `${localTime(charge.depart)}: ${percent(charge.soc_before)} → ${percent(charge.soc_after)}`,
        route.vehicle_id).addTo(planLayer);
    }
    const depot = state.request && state.request.depot;
    for (const reload of route.reloads || []) {
      if (!depot) break;
      marker(depot.lat, depot.lon, icon("reload-icon", "↺", { "data-testid": "reload-marker" }),
        `${escapeHtml(route.vehicle_id)} reloads ${localTime(reload.arrive)}–${localTime(reload.depart)}`,
        route.vehicle_id).addTo(planLayer);
    }
    for (const pause of route.breaks || []) {
      // A break where the van stands when it begins.
      const begins = Date.parse(pause.start);
      const before = route.legs.filter((leg) => Date.parse(leg.arrive) <= begins + 1000).pop();
      const place = state.places[before ? before.to_id : route.legs[0].from_id];
      if (!place) continue;
      marker(place.lat, place.lon, icon("break-icon", "☕", { "data-testid": "break-marker" }),
        `${escapeHtml(route.vehicle_id)} break (${escapeHtml(pause.kind)}) ${localTime(pause.start)}–${localTime(pause.end)}`,
        route.vehicle_id).addTo(planLayer);
    }
  });
  const depot = state.request && state.request.depot;
  if (depot) {
    marker(depot.lat, depot.lon, icon("depot-icon", "", { "data-testid": "depot-marker" }),
      `Depot ${escapeHtml(depot.id)}`).addTo(planLayer);
  }
  for (const item of unassignedOf()) {
    const place = state.places[item.id];
    if (!place) continue;
    marker(place.lat, place.lon, icon("unassigned-icon", "✕", { "data-testid": "unassigned-marker" }),
      `${escapeHtml(item.id)} not served: ${escapeHtml(item.reason)} — ${escapeHtml(item.detail)}`).addTo(planLayer);
  }
  const credit = state.answer && state.answer.attribution;
  if (map.planCredit) map.attributionControl.removeAttribution(map.planCredit);
  map.planCredit = credit ? escapeHtml(credit) : null;
  if (map.planCredit) map.attributionControl.addAttribution(map.planCredit);
  map.legend.update();
  const bounds = planLayer.getBounds();
  if (bounds.isValid()) map.fitBounds(bounds, { padding: [30, 30], maxZoom: 16 });
}

function highlight(vehicleId) {
  // One route's line, markers, legend entry and card together; the others fade.
  for (const [id, line] of Object.entries(state.lines || {})) {
    const on = vehicleId === null || id === vehicleId;
    line.setStyle({ opacity: on ? 0.85 : 0.15, weight: vehicleId !== null && on ? 6 : 4 });
    if (vehicleId !== null && on) line.bringToFront();
  }
  for (const node of document.querySelectorAll("[data-vehicle]")) {
    node.classList.toggle("active", vehicleId !== null && node.dataset.vehicle === vehicleId);
    node.classList.toggle("faded", vehicleId !== null && node.dataset.vehicle !== vehicleId &&
      node.matches(".map-icon, .legend-route"));
  }
}

// ---------------------------------------------------------------- totals and assumptions

function facts(box, items) {
  box.replaceChildren();
  for (const [name, value, cls] of items) {
    const span = el("span", cls ? { class: cls } : {});
    span.append(`${name}: `, el("b", {}, value));
    box.appendChild(span);
  }
}

function gridKwh(route) {
  // Pre-conditioning before departure, and each charge's draw on the way.
  return route.totals.grid_kwh + (route.charges || []).reduce((n, c) => n + c.grid_kwh, 0);
}

function drawFleet() {
  $("fleet-card").hidden = false;
  const sum = (f) => state.routes.reduce((n, r) => n + f(r), 0);
  const breaks = state.routes.filter((r) => r.cold_chain && r.cold_chain.verdict === "breaks");
  const chains = state.routes.filter((r) => r.cold_chain);
  facts($("fleet-totals"), [
    ["Vans", String(state.routes.length)], ["Stops served", String(sum((r) => r.stops.length))],
    ["Not served", String(unassignedOf().length)], ["Distance", km(sum((r) => r.totals.distance_m))],
    ["Energy", kwh(sum((r) => r.totals.energy_kwh.total))],
    ["From the grid", kwh(sum(gridKwh))],
    ...(chains.length ? [["Cold chain", breaks.length ? `breaks on ${breaks.length} of ${chains.length}` : "holds",
      breaks.length ? "bad" : "ok"]] : []),
  ]);
  const warnings = $("warnings");
  warnings.replaceChildren();
  const all = [...((state.endpoint === "fleet-plans" && state.answer.warnings) || [])];
  for (const route of state.routes) {
    for (const warning of route.warnings || []) all.push(`${route.vehicle_id}: ${warning}`);
  }
  for (const warning of all) warnings.appendChild(el("div", { class: "warning", "data-testid": "warning" }, warning));
  const list = $("unassigned-list");
  list.replaceChildren();
  const left = unassignedOf();
  if (left.length) list.appendChild(el("h3", {}, `Not served (${left.length})`));
  for (const item of left) {
    const row = el("div", { class: "unassigned", "data-testid": "unassigned", "data-stop": item.id });
    row.append(el("b", {}, item.id), ` — ${item.reason}: ${item.detail}`);
    list.appendChild(row);
  }
}

function speedsAssumed() {
  // The mean speed of the legs of each street type: what straight-line distances assumed.
  const byType = {};
  for (const route of state.routes) {
    for (const leg of route.legs) {
      const t = leg.street_type || "legs";
      byType[t] = byType[t] || { m: 0, s: 0, n: 0 };
      byType[t].m += leg.distance_m;
      byType[t].s += leg.duration_s;
      byType[t].n += 1;
    }
  }
  return Object.entries(byType).map(([t, v]) =>
    `${t} ${fixed((v.m / Math.max(v.s, 1)) * 3.6, 0)} km/h (${v.n} leg${v.n === 1 ? "" : "s"})`).join(", ");
}

const DISTANCE_SOURCES = {
  osrm: "roads (the OSRM router)",
  client: "the request's own distance and duration matrix",
  estimate: "straight lines (great circle × a detour factor), not roads",
};

function describeVan(van) {
  const v = van.vehicle || {};
  const parts = [v.profile ? `profile ${v.profile}` : `preset ${v.preset || "paper-generic"}`];
  if (van.battery && van.battery.usable_capacity_kwh) parts.push(`${van.battery.usable_capacity_kwh} kWh`);
  if (van.payload_kg !== undefined) parts.push(`${van.payload_kg} kg payload`);
  if (van.shift_start) parts.push(`shift ${van.shift_start}–${van.shift_end || ""}`);
  if (van.start_time) parts.push(`leaves ${van.start_time}`);
  return parts.join(", ");
}

function drawAssumptions() {
  const answer = state.answer;
  const request = state.request || {};
  const list = $("assumptions");
  list.replaceChildren();
  const add = (term, text) => {
    list.appendChild(el("dt", {}, term));
    list.appendChild(el("dd", {}, text));
  };
  const first = state.routes[0] || {};
  const weather = first.weather || answer.weather;
  if (weather) {
    add("Weather", `${weather.source}: ${fixed(weather.t_min_c, 1)} to ${fixed(weather.t_max_c, 1)} °C`);
  }
  const source = answer.distance_source || first.distance_source;
  if (source) add("Distances", `${DISTANCE_SOURCES[source] || source}; speeds ${speedsAssumed()}`);
  add("Day", `${request.date || ""}, times in ${answer.timezone || request.timezone || "local time"}`);
  const vansAsked = Array.isArray(request.vehicles) ? request.vehicles : [request];
  const counted = {};
  for (const van of vansAsked) {
    const text = describeVan(van);
    counted[text] = (counted[text] || 0) + 1;
  }
  add("Vans", Object.entries(counted).map(([text, n]) => `${n} × ${text}`).join("; "));
  const strategies = new Set(state.routes.map((r) => (r.refrigeration ? r.refrigeration.strategy : "thermostat")));
  const product = (vansAsked[0] && vansAsked[0].cargo_box && vansAsked[0].cargo_box.product) || "none given";
  add("Refrigeration", `${[...strategies].join(", ")}; product ${typeof product === "string" ? product : "a band of its own"}`);
  $("assumptions-card").hidden = false;
}

// ---------------------------------------------------------------- routes

function drawRoutes() {
  const box = $("routes");
  state.routes.forEach((route, r) => {
    const card = el("div", { class: "card", "data-testid": "route", "data-vehicle": route.vehicle_id });
    card.addEventListener("mouseenter", () => highlight(route.vehicle_id));
    card.addEventListener("mouseleave", () => highlight(null));
    const title = el("h2");
    const swatch = el("span", { class: "swatch" });
    swatch.style.background = colourOf(r);
    title.append(swatch, `${route.vehicle_id} · ${route.stops.length} stops`);
    const sheet = el("button", { type: "button", class: "secondary", "data-testid": "run-sheet" }, "Run sheet");
    sheet.addEventListener("click", () => printRunSheet(route));
    title.appendChild(sheet);
    card.appendChild(title);
    const battery = route.battery;
    const totals = el("div", { class: "totals" });
    const chain = route.cold_chain;
    const unit = route.refrigeration;
    facts(totals, [
      ["Distance", km(route.totals.distance_m)],
      ["Time", `${fixed(route.totals.duration_s / 3600, 1)} h`],
      ["Energy", kwh(route.totals.energy_kwh.total)],
      ...CONSUMERS.map((c) => [c, kwh(route.totals.energy_kwh[c])]),
      ["From the grid", kwh(gridKwh(route))],
      ["Lowest SoC", percent(battery.min_soc)],
      ["Charges", String((route.charges || []).length)],
      ["Reloads", String((route.reloads || []).length)],
      ["Breaks", String((route.breaks || []).length)],
      ["Battery", battery.feasible ? "holds its reserve" : "runs short", battery.feasible ? "ok" : "bad"],
      ...(unit ? [["Unit", `${unit.strategy}, ${kwh(unit.battery_kwh)} from the battery (thermostat ${kwh(unit.thermostat_battery_kwh)})`]] : []),
      ...(chain ? [["Cold chain", chain.verdict === "holds"
        ? `holds (goods ${celsius(chain.product_min_c)} … ${celsius(chain.product_max_c)})`
        : `breaks at ${chain.first_break_stop || "the start"}: ${chain.reason}`, chain.verdict === "holds" ? "ok" : "bad"]] : []),
    ]);
    totals.lastChild.dataset.testid = chain ? "cold-chain" : "";
    card.appendChild(totals);
    const charts = el("div", { class: "charts" });
    card.appendChild(charts);
    card.appendChild(stopTable(route));
    box.appendChild(card);
    for (const make of [socChart, energyChart, boxChart]) make(route, charts);
  });
}

// ---------------------------------------------------------------- charts (uPlot)

function spansOf(route) {
  // What the van does when, as [kind, from, to] on the plan's local clock [s].
  const out = [];
  for (const c of route.charges || []) out.push(["charge", wallClock(c.arrive), wallClock(c.depart)]);
  for (const b of route.breaks || []) out.push(["break", wallClock(b.start), wallClock(b.end)]);
  for (const r of route.reloads || []) out.push(["reload", wallClock(r.arrive), wallClock(r.depart)]);
  return out;
}

function doorSpans(route) {
  // Each stop's door open from the start of its service for the planned door time.
  return route.stops.map((s) => {
    const open = Number((state.places[s.id] || {}).door_open_s || 0);
    const from = wallClock(s.service_start || s.arrival);
    return ["door", from, from + open];
  }).filter(([, a, b]) => b > a);
}

function spanPlugin(spans) {
  // The shaded spans behind the lines.
  return {
    hooks: {
      drawClear: [(u) => {
        const { ctx } = u;
        ctx.save();
        for (const [kind, from, to] of spans) {
          const x0 = u.valToPos(from, "x", true);
          const x1 = u.valToPos(to, "x", true);
          ctx.fillStyle = SPANS[kind][1];
          ctx.fillRect(x0, u.bbox.top, Math.max(x1 - x0, 2), u.bbox.height);
        }
        ctx.restore();
      }],
    },
  };
}

function chart(route, holder, testid, title, data, series, spans, yLabel, yRange) {
  const frame = el("figure", { class: "chart", "data-testid": testid, "data-vehicle": route.vehicle_id });
  frame.appendChild(el("figcaption", {}, title));
  holder.appendChild(frame);
  const width = Math.max(frame.clientWidth - 14, 300);
  const font = "13px system-ui, sans-serif";
  // The plan's local clock, 24 h, read in UTC (see wallClock).
  const clock = (u, splits) => splits.map((v) => new Date(v * 1000).toISOString().slice(11, 16));
  const plot = new uPlot({
    width, height: 260,
    tzDate: (ts) => uPlot.tzDate(new Date(ts * 1e3), "Etc/UTC"),
    cursor: { sync: { key: `route-${route.vehicle_id}` }, drag: { x: true, y: false } },
    scales: { x: { time: true }, y: yRange ? { range: yRange } : {} },
    axes: [
      { font, stroke: "#1d2733", grid: { stroke: "#e3e8ee" }, values: clock, space: 60 },
      { font, stroke: "#1d2733", label: yLabel, labelFont: font, size: 60, grid: { stroke: "#e3e8ee" } },
    ],
    series: [{ label: "time (local)", value: (u, v) => (v === null ? "" : new Date(v * 1000).toISOString().slice(11, 16)) }, ...series],
    plugins: [spanPlugin(spans)],
  }, data, frame);
  const legend = el("p", { class: "span-legend" });
  for (const kind of new Set(spans.map(([k]) => k))) {
    const swatch = el("span", { class: "swatch" });
    swatch.style.background = SPANS[kind][1];
    legend.append(swatch, ` ${SPANS[kind][0]}  `);
  }
  legend.append(el("span", { class: "hint" }, "Drag across a chart to zoom, double-click to zoom out."));
  frame.appendChild(legend);
  frame.plot = plot;
  state.charts.push(plot);
  return plot;
}

function profileTimes(route) {
  return route.profile.time.map(wallClock);
}

function reserveOf(route) {
  if (route.battery && typeof route.battery.reserve_soc === "number") return route.battery.reserve_soc;
  const van = vanOf(state.request, route.vehicle_id);
  if (van.battery && typeof van.battery.min_soc === "number") return van.battery.min_soc;
  return null;
}

function socChart(route, holder) {
  let times;
  let soc;
  if (route.profile) {
    times = profileTimes(route);
    soc = route.profile.soc.map((s) => 100 * s);
  } else {
    const points = [];
    for (const leg of route.legs) points.push([leg.depart, leg.soc_start], [leg.arrive, leg.soc_end]);
    for (const c of route.charges || []) points.push([c.arrive, c.soc_before], [c.depart, c.soc_after]);
    points.sort((a, b) => Date.parse(a[0]) - Date.parse(b[0]));
    times = points.map(([t]) => wallClock(t));
    soc = points.map(([, s]) => 100 * s);
  }
  const reserve = reserveOf(route);
  const series = [{ label: "state of charge", stroke: "#1d5c8a", width: 2, value: (u, v) => (v === null ? "" : `${fixed(v, 1)} %`) }];
  const data = [times, soc];
  if (reserve !== null) {
    series.push({ label: `reserve ${percent(reserve)}`, stroke: "#b3261e", dash: [6, 4], width: 1.5, points: { show: false } });
    data.push(times.map(() => 100 * reserve));
  }
  chart(route, holder, "soc-chart", "State of charge [%]", data, series, spansOf(route), "%", [0, 100]);
}

function energyChart(route, holder) {
  if (!route.profile) return;
  const times = profileTimes(route);
  const series = [...CONSUMERS, "total"].map((c) => ({
    label: c, stroke: c === "total" ? "#1d2733" : CONSUMER_COLOURS[c], width: c === "total" ? 2.5 : 2,
    value: (u, v) => (v === null ? "" : `${fixed(v, 2)} kWh`),
  }));
  const data = [times, ...[...CONSUMERS, "total"].map((c) => route.profile.energy_kwh[c])];
  chart(route, holder, "energy-chart", "Energy per consumer since departure [kWh]", data, series, spansOf(route), "kWh");
}

function boxChart(route, holder) {
  const profile = route.profile;
  const chain = route.cold_chain;
  const air = profile && profile.box_temperature_c;
  if (!profile || !air) {
    const note = el("figure", { class: "chart", "data-testid": "box-chart", "data-vehicle": route.vehicle_id });
    note.append(el("figcaption", {}, "Cargo box"), el("p", { class: "hint" },
      "Steady box: the unit holds the set-point (the dynamic mode, or a product, draws the temperatures)."));
    holder.appendChild(note);
    return;
  }
  const times = profileTimes(route);
  const value = (u, v) => (v === null || v === undefined ? "" : `${fixed(v, 1)} °C`);
  const series = [{ label: "air", stroke: "#0b7a75", width: 2, value }];
  const data = [times, air];
  if (profile.product_temperature_c) {
    series.push({ label: "goods", stroke: "#7a3b0b", width: 2.5, value });
    data.push(profile.product_temperature_c);
  }
  if (profile.air_setpoint_c) {
    series.push({ label: "air set-point (schedule)", stroke: "#5b6b7a", dash: [3, 3], width: 1.5, value, points: { show: false } });
    data.push(profile.air_setpoint_c);
  }
  const limits = [];
  if (chain) {
    limits.push([`band floor ${celsius(chain.min_c)}`, chain.min_c], [`band ceiling ${celsius(chain.max_c)}`, chain.max_c]);
    if (chain.excursion_c > 0) limits.push([`brief rises to ${celsius(chain.max_c + chain.excursion_c)}`, chain.max_c + chain.excursion_c]);
  } else if (route.box && typeof route.box.product_limit_c === "number") {
    limits.push([`product limit ${celsius(route.box.product_limit_c)}`, route.box.product_limit_c]);
  }
  for (const [label, level] of limits) {
    series.push({ label, stroke: "#b3261e", dash: [6, 4], width: 1.2, value, points: { show: false } });
    data.push(times.map(() => level));
  }
  const title = chain ? `Air and goods [°C] — cold chain ${chain.verdict}` : "Cargo-box air [°C]";
  chart(route, holder, "box-chart", title, data, series, [...spansOf(route), ...doorSpans(route)], "°C");
}

// ---------------------------------------------------------------- run sheet, exports

function visitsOf(route) {
  // The day in time order (the service's visits: stops, charges, reloads, breaks in place).
  if (route.visits && route.visits.length) return route.visits;
  const rows = route.stops.map((s) => ({ kind: "stop", id: s.id, arrive: s.arrival, start: s.service_start || s.arrival, depart: s.departure, soc_arrival: s.soc_arrival, soc_departure: s.soc_departure, payload_after_kg: s.payload_after_kg }));
  return rows;
}

const SHEET_HEAD = ["#", "Stop", "Address / notes", "Arrive", "Wait", "Service", "Leave", "Unload",
  "Payload after", "SoC", "Door", "Goods at delivery"];

function sheetRows(route) {
  const stops = Object.fromEntries(route.stops.map((s) => [s.id, s]));
  let n = 0;
  let payload = null;
  const rows = [];
  for (const visit of visitsOf(route)) {
    const wait = (Date.parse(visit.start) - Date.parse(visit.arrive)) / 1000;
    const soc = `${percent(visit.soc_arrival)} → ${percent(visit.soc_departure)}`;
    if (visit.kind === "stop") {
      n += 1;
      const stop = stops[visit.id] || {};
      const place = state.places[visit.id] || {};
      const before = payload === null ? visit.payload_after_kg + (place.delivery_kg || 0) : payload;
      const notes = Object.entries(state.extras[visit.id] || {}).filter(([, v]) => v).map(([, v]) => v).join(" · ");
      const windows = (place.time_windows || []).map((w) => `${w.start}–${w.end}`).join(", ");
      const goods = stop.product_temperature_c ? celsius(stop.product_temperature_c.arrival) : "";
      rows.push([String(n), visit.id + (windows ? ` (${windows})` : ""), notes, localTime(visit.arrive),
        wait > 30 ? minutes(wait) : "", localTime(visit.start), localTime(visit.depart),
        `${fixed(Math.max(before - visit.payload_after_kg, 0), 0)} kg`, `${fixed(visit.payload_after_kg, 0)} kg`, soc,
        place.door_open_s ? minutes(place.door_open_s) : "", goods]);
    } else {
      const what = { charge: `⚡ charge at ${visit.id}`, reload: "↺ reload at the depot", break: "☕ break" }[visit.kind] || visit.kind;
      rows.push(["", what, "", localTime(visit.arrive), wait > 30 ? minutes(wait) : "", localTime(visit.start),
        localTime(visit.depart), "", `${fixed(visit.payload_after_kg, 0)} kg`, soc, "", ""]);
    }
    payload = visit.payload_after_kg;
  }
  return rows;
}

function table(route, editable = false) {
  const t = el("table", { "data-testid": "run-table", "data-vehicle": route.vehicle_id });
  const head = el("tr");
  for (const name of [...SHEET_HEAD, ...(editable ? ["Move"] : [])]) head.appendChild(el("th", { scope: "col" }, name));
  t.appendChild(head);
  const visits = visitsOf(route);
  sheetRows(route).forEach((row, k) => {
    const tr = el("tr");
    for (const cell of row) tr.appendChild(el("td", {}, cell));
    if (editable && visits[k].kind === "stop") tr.appendChild(moveCell(route.vehicle_id, visits[k].id, tr));
    else if (editable) tr.appendChild(el("td"));
    t.appendChild(tr);
  });
  if (editable) dropTarget(t, route.vehicle_id, null);
  return t;
}

function stopTable(route) {
  const details = el("details", { "data-vehicle-table": route.vehicle_id });
  details.appendChild(el("summary", {}, "Stops, charges, reloads and breaks"));
  details.appendChild(table(route, true));
  return details;
}

// ---------------------------------------------------------------- editing: move, re-simulate

function moveCell(vehicleId, stopId, tr) {
  // ↑ ↓ within the route, a list of vans to move to; the row drags onto another row too.
  const cell = el("td", { class: "move" });
  const up = el("button", { type: "button", class: "secondary small", "aria-label": `Move ${stopId} earlier`, "data-testid": "move-up" }, "↑");
  const down = el("button", { type: "button", class: "secondary small", "aria-label": `Move ${stopId} later`, "data-testid": "move-down" }, "↓");
  up.addEventListener("click", () => moveStop(stopId, vehicleId, -1));
  down.addEventListener("click", () => moveStop(stopId, vehicleId, +1));
  const to = el("select", { "aria-label": `Van for ${stopId}`, "data-testid": "move-to" });
  for (const route of state.routes) to.appendChild(el("option", { value: route.vehicle_id }, route.vehicle_id));
  to.value = vehicleId;
  to.addEventListener("change", () => moveStop(stopId, to.value, null));
  cell.append(up, down, to);
  if (state.endpoint === "fleet-plans") cell.appendChild(pinButton(stopId, vehicleId));
  tr.draggable = true;
  tr.dataset.stop = stopId;
  tr.addEventListener("dragstart", (event) => event.dataTransfer.setData("text/plain", stopId));
  dropTarget(tr, vehicleId, stopId);
  return cell;
}

function pinButton(stopId, vehicleId) {
  // Pinned: the fleet's re-plan gives the stop to this van (or leaves it out, saying why).
  const pinned = state.pins[stopId] === vehicleId;
  const pin = el("button", {
    type: "button", class: "secondary small", "data-testid": "pin", "aria-pressed": String(pinned),
    "aria-label": `Pin ${stopId} to ${vehicleId}`, title: `Pin ${stopId} to ${vehicleId} when the fleet is planned again`,
  }, pinned ? "📌 pinned" : "pin");
  pin.addEventListener("click", () => {
    if (state.pins[stopId] === vehicleId) delete state.pins[stopId];
    else state.pins[stopId] = vehicleId;
    pin.setAttribute("aria-pressed", String(state.pins[stopId] === vehicleId));
    pin.textContent = state.pins[stopId] === vehicleId ? "📌 pinned" : "pin";
    drawPins();
  });
  return pin;
}

function drawPins() {
  const count = Object.keys(state.pins).length;
  $("replan").hidden = state.endpoint !== "fleet-plans";
  $("replan").disabled = count === 0;
  $("pin-status").textContent = count ? `${count} stop(s) pinned: ${Object.entries(state.pins).map(([s, v]) => `${s} → ${v}`).join(", ")}.` : "";
}

async function replan() {
  // The fleet's request again, each van with the stops pinned to it: the search plans the
  // rest around them.
  const request = structuredClone(state.request);
  for (const van of request.vehicles) {
    van.pinned_stops = Object.keys(state.pins).filter((stopId) => state.pins[stopId] === van.id);
  }
  clearMessages();
  await submit(request, "pinned");
}

function dropTarget(node, vehicleId, beforeStopId) {
  node.addEventListener("dragover", (event) => event.preventDefault());
  node.addEventListener("drop", (event) => {
    event.preventDefault();
    event.stopPropagation();
    const moved = event.dataTransfer.getData("text/plain");
    if (moved && moved !== beforeStopId) moveStop(moved, vehicleId, null, beforeStopId);
  });
}

function moveStop(stopId, vehicleId, step, beforeStopId = null) {
  // The stop to another place in a van's order: step ±1 in its own, or before a stop (or at
  // the end) of another's.
  const from = Object.keys(state.order).find((v) => state.order[v].includes(stopId));
  const source = state.order[from];
  const at = source.indexOf(stopId);
  if (step !== null) {
    const to = at + step;
    if (to < 0 || to >= source.length) return;
    source.splice(at, 1);
    source.splice(to, 0, stopId);
  } else {
    source.splice(at, 1);
    const target = state.order[vehicleId];
    const before = beforeStopId === null ? -1 : target.indexOf(beforeStopId);
    target.splice(before < 0 ? target.length : before, 0, stopId);
    state.changed.add(vehicleId);
    if (state.pins[stopId]) state.pins[stopId] = vehicleId;  // a pin follows its stop
  }
  state.changed.add(from);
  drawOrders();
  drawPins();
}

function drawOrders() {
  // A changed route's table: the new order, its times not known until re-simulated.
  for (const vehicleId of state.changed) {
    const holder = document.querySelector(`[data-vehicle-table="${vehicleId}"]`);
    if (!holder) continue;
    const t = el("table", { "data-testid": "run-table", "data-vehicle": vehicleId, class: "changed" });
    const head = el("tr");
    for (const name of ["#", "Stop", "Move"]) head.appendChild(el("th", { scope: "col" }, name));
    t.appendChild(head);
    state.order[vehicleId].forEach((stopId, k) => {
      const tr = el("tr");
      tr.append(el("td", {}, String(k + 1)), el("td", {}, stopId), moveCell(vehicleId, stopId, tr));
      t.appendChild(tr);
    });
    dropTarget(t, vehicleId, null);
    holder.replaceChildren(el("summary", {}, `Changed: ${state.order[vehicleId].length} stops in a new order — re-simulate for the times`), t);
    holder.open = true;
  }
  $("resimulate").disabled = state.changed.size === 0;
  $("edit-status").textContent = state.changed.size ? `${state.changed.size} route(s) changed, not yet simulated.` : "";
}

const FLEET_ONLY = ["vehicles", "minimize_vehicles", "matrix"];
const VAN_SHIFT = ["id", "shift_start", "shift_end"];

function routeRequest(vehicleId) {
  // The plan request that re-simulates one van's stops in the order given.
  const request = state.request;
  const byId = Object.fromEntries(request.stops.map((x) => [x.id, x]));
  const stops = state.order[vehicleId].map((id) => byId[id]);
  if (state.endpoint === "plans") return { ...request, stops, keep_order: true };
  const body = Object.fromEntries(Object.entries(request).filter(([k]) => !FLEET_ONLY.includes(k)));
  const van = vanOf(request, vehicleId);
  for (const [k, v] of Object.entries(van)) if (!VAN_SHIFT.includes(k)) body[k] = v;
  if (van.shift_start) body.start_time = van.shift_start;
  return { ...body, stops, keep_order: true, include_geometry: true, include_profile: true };
}

async function resimulate() {
  $("resimulate").disabled = true;
  $("edit-status").textContent = "Re-simulating…";
  const changed = [...state.changed].filter((v) => state.order[v].length);
  const answers = {};
  for (const vehicleId of changed) {
    const answer = await api("POST", "/v1/plans", routeRequest(vehicleId));
    if (!answer.ok) {
      $("edit-status").textContent = "";
      $("resimulate").disabled = false;
      const problem = answer.data || {};
      const detail = (problem.errors || []).map((e) => `${e.field}: ${e.message}`).join("; ") || problem.detail;
      showError(`${vehicleId} in the new order: ${detail || `the service answered ${answer.status}`}`);
      return;
    }
    answers[vehicleId] = answer.data;
  }
  if (state.endpoint === "plans") {
    const request = routeRequest("van");
    show(request, "plans", answers.van, null, "edited");
    return;
  }
  const routes = state.routes
    .filter((r) => state.order[r.vehicle_id].length)
    .map((r) => (answers[r.vehicle_id] ? { ...answers[r.vehicle_id], vehicle_id: r.vehicle_id } : r));
  const edited = { ...state.answer, routes, edited: true };
  show(state.request, "fleet-plans", edited, null, "edited");
}

// ---------------------------------------------------------------- save and compare

function remember(request, endpoint, answer, jobId, label) {
  const routes = routesOf(endpoint, answer);
  const served = routes.reduce((n, r) => n + r.stops.length, 0);
  const name = `Plan ${state.history.length + 1}${label ? ` (${label})` : ""}${jobId ? ` · job ${jobId.slice(0, 8)}` : ""}: ` +
    `${served} stops, ${km(routes.reduce((n, r) => n + r.totals.distance_m, 0))}`;
  state.history.push({ name, request, endpoint, answer });
}

function drawWork() {
  $("work-card").hidden = false;
  const link = $("saved-link");
  // A fleet changed by hand is no longer one request: saved route by route, not as a whole.
  $("save").disabled = Boolean(state.answer.edited);
  if (state.jobId) showLink(state.jobId);
  else link.hidden = true;
  drawOrders();
  drawPins();
  for (const id of ["compare-a", "compare-b"]) {
    const select = $(id);
    select.replaceChildren(...state.history.map((h, k) => el("option", { value: String(k) }, h.name)));
  }
  $("compare-a").value = String(Math.max(state.history.length - 2, 0));
  $("compare-b").value = String(state.history.length - 1);
  drawCompare();
}

function showLink(jobId) {
  const link = $("saved-link");
  link.href = `/viewer?job=${encodeURIComponent(jobId)}`;
  link.textContent = `${window.location.origin}${link.getAttribute("href")}`;
  link.hidden = false;
}

async function save() {
  // Saved in the jobs' store: the same request planned again gives the same plan (seeded,
  // stopped by work), kept as long as jobs are (COLDROUTE_JOB_RETENTION_S).
  const submitted = await api("POST", "/v1/jobs", {
    type: state.endpoint === "plans" ? "plan" : "fleet-plan", request: state.request,
  });
  if (!submitted.ok) { showProblem(submitted.data, submitted.status); return; }
  state.jobId = submitted.data.id;
  showLink(submitted.data.id);
  $("edit-status").textContent = "Saved: the link reopens this plan.";
}

function lateMinutes(routes, places) {
  // Minutes served after the end of a stop's window, over the day.
  let late = 0;
  for (const route of routes) {
    for (const stop of route.stops) {
      const windows = (places[stop.id] || {}).time_windows || [];
      if (!windows.length) continue;
      const clock = stop.service_start ? stop.service_start.slice(11, 16) : stop.arrival.slice(11, 16);
      const toMin = (hhmm) => Number(hhmm.slice(0, 2)) * 60 + Number(hhmm.slice(3, 5));
      const over = Math.min(...windows.map((w) => Math.max(toMin(clock) - toMin(w.end), 0)));
      late += over;
    }
  }
  return late;
}

function figures(plan) {
  const routes = routesOf(plan.endpoint, plan.answer);
  const places = Object.fromEntries(((plan.request && plan.request.stops) || []).map((x) => [x.id, x]));
  const sum = (f) => routes.reduce((n, r) => n + f(r), 0);
  const chains = routes.filter((r) => r.cold_chain);
  const broken = chains.filter((r) => r.cold_chain.verdict === "breaks").length;
  return [
    ["Vans", String(routes.length)],
    ["Stops served", String(sum((r) => r.stops.length))],
    ["Not served", String(plan.endpoint === "plans" ? 0 : (plan.answer.unassigned || []).length)],
    ["Distance", km(sum((r) => r.totals.distance_m))],
    ["Energy", kwh(sum((r) => r.totals.energy_kwh.total))],
    ["From the grid", kwh(sum(gridKwh))],
    ["Lowest SoC", percent(Math.min(...routes.map((r) => r.battery.min_soc)))],
    ["Late (after the window)", `${fixed(lateMinutes(routes, places), 0)} min`],
    ["Cold chain", chains.length ? (broken ? `breaks on ${broken} of ${chains.length}` : "holds") : "no product"],
  ];
}

function drawCompare() {
  const t = $("compare");
  t.replaceChildren();
  const a = state.history[Number($("compare-a").value)];
  const b = state.history[Number($("compare-b").value)];
  if (!a || !b) return;
  const head = el("tr");
  head.append(el("th", { scope: "col" }, ""), el("th", { scope: "col" }, a.name), el("th", { scope: "col" }, b.name));
  t.appendChild(head);
  const fa = figures(a);
  const fb = figures(b);
  fa.forEach(([name, va], k) => {
    const tr = el("tr", va === fb[k][1] ? {} : { class: "differs" });
    tr.append(el("th", { scope: "row" }, name), el("td", {}, va), el("td", {}, fb[k][1]));
    t.appendChild(tr);
  });
}

async function openToCompare() {
  // A saved plan (its link or job id) added to the plans to compare.
  const raw = $("compare-link").value.trim();
  const match = /job=([^&\s]+)/.exec(raw);
  const jobId = match ? decodeURIComponent(match[1]) : raw;
  if (!jobId) return;
  const answer = await api("GET", `/v1/jobs/${encodeURIComponent(jobId)}?include_request=true`);
  if (!answer.ok || answer.data.status !== "succeeded") {
    showError(`Compare: ${answer.ok ? `job ${jobId} is ${answer.data.status}` : `no saved plan ${jobId} (${answer.status})`}.`);
    return;
  }
  const job = answer.data;
  remember(job.request, job.type === "plan" ? "plans" : "fleet-plans", job.result, job.id, "saved");
  drawWork();
}

function printRunSheet(route) {
  const area = $("print-area");
  area.replaceChildren();
  area.appendChild(el("h1", {}, `Run sheet — ${route.vehicle_id} — ${state.request ? state.request.date : ""}`));
  const chain = route.cold_chain;
  area.appendChild(el("p", {}, `Leave ${localTime(route.legs[0].depart)}, back ${localTime(route.legs[route.legs.length - 1].arrive)}; ` +
    `${km(route.totals.distance_m)}, ${route.stops.length} stops, lowest state of charge ${percent(route.battery.min_soc)}` +
    (chain ? `; cold chain ${chain.verdict}.` : ".")));
  area.appendChild(table(route));
  window.print();
}

function download(name, type, text) {
  const link = el("a", { href: URL.createObjectURL(new Blob([text], { type })), download: name });
  document.body.appendChild(link);
  link.click();
  setTimeout(() => { URL.revokeObjectURL(link.href); link.remove(); }, 1000);
}

function csvCell(value) {
  // A text a spreadsheet would run as a formula (=, +, -, @, a tab or a return first) is
  // kept as text by a leading apostrophe (OWASP, "CSV Injection"); numbers stay numbers.
  let text = String(value);
  if (/^[=+\-@\t\r]/.test(text) && !/^[-+]?\d+(\.\d+)?$/.test(text)) text = `'${text}`;
  return /[",\n\r]/.test(text) ? `"${text.replace(/"/g, '""')}"` : text;
}

function exportCsv() {
  const rows = [["vehicle_id", "sequence", "stop_id", "arrival", "service_start", "departure",
    "soc_arrival", "soc_departure", "leg_energy_kwh", "stop_energy_kwh", "door_heat_kwh",
    "payload_after_kg", "product_temperature_c", ...state.columns]];
  for (const route of state.routes) {
    const into = Object.fromEntries(route.legs.map((l) => [l.to_id, l]));
    route.stops.forEach((s, k) => {
      const extra = state.extras[s.id] || {};
      rows.push([route.vehicle_id, k + 1, s.id, s.arrival, s.service_start || "", s.departure,
        fixed(s.soc_arrival, 4), fixed(s.soc_departure, 4), into[s.id] ? fixed(into[s.id].energy_kwh.total, 4) : "",
        fixed(s.energy_kwh.total, 4), fixed(s.door_heat_kwh, 4), fixed(s.payload_after_kg, 1),
        s.product_temperature_c ? fixed(s.product_temperature_c.arrival, 2) : "",
        ...state.columns.map((c) => extra[c] || "")]);
    });
  }
  download("plan.csv", "text/csv", `${rows.map((r) => r.map(csvCell).join(",")).join("\r\n")}\r\n`);
}

function exportGeojson() {
  // The service's GeoJSON of a plan (Accept: application/geo+json), a route after another.
  const features = [];
  for (const route of state.routes) {
    const depot = state.request && state.request.depot;
    if (depot) {
      features.push({ type: "Feature", geometry: { type: "Point", coordinates: [depot.lon, depot.lat] },
        properties: { kind: "depot", id: depot.id, vehicle_id: route.vehicle_id } });
    }
    route.stops.forEach((s, k) => {
      const place = state.places[s.id];
      if (!place) return;
      features.push({ type: "Feature", geometry: { type: "Point", coordinates: [place.lon, place.lat] },
        properties: { kind: "stop", id: s.id, vehicle_id: route.vehicle_id, sequence: k + 1,
          arrival: s.arrival, departure: s.departure, door_heat_kwh: s.door_heat_kwh,
          soc_arrival: s.soc_arrival, soc_departure: s.soc_departure, ...(state.extras[s.id] || {}) } });
    });
    for (const c of route.charges || []) {
      features.push({ type: "Feature", geometry: { type: "Point", coordinates: [c.lon, c.lat] },
        properties: { kind: "charge", vehicle_id: route.vehicle_id, ...c } });
    }
    route.legs.forEach((leg, index) => {
      const a = state.places[leg.from_id];
      const b = state.places[leg.to_id];
      const line = leg.geometry ? leg.geometry.coordinates : (a && b ? [[a.lon, a.lat], [b.lon, b.lat]] : []);
      features.push({ type: "Feature", geometry: { type: "LineString", coordinates: line },
        properties: { kind: "leg", vehicle_id: route.vehicle_id, index, from_id: leg.from_id,
          to_id: leg.to_id, depart: leg.depart, arrive: leg.arrive, distance_m: leg.distance_m,
          duration_s: leg.duration_s, street_type: leg.street_type, energy_kwh: leg.energy_kwh,
          soc_start: leg.soc_start, soc_end: leg.soc_end } });
    });
  }
  download("plan.geojson", "application/geo+json", JSON.stringify({ type: "FeatureCollection", features }, null, 1));
}

// ---------------------------------------------------------------- start

async function start() {
  const tomorrow = new Date(Date.now() + 86400e3);
  $("date").value = tomorrow.toISOString().slice(0, 10);
  addVanRow(true);
  $("add-vans").addEventListener("click", () => addVanRow(false));
  createMap();
  $("plan-form").addEventListener("submit", (event) => {
    plan(event).catch((error) => { $("plan").disabled = false; showError(`Unexpected: ${error.message}`); });
  });
  const job = new URLSearchParams(window.location.search).get("job");
  $("api-key").addEventListener("change", () => {
    loadVans();
    if (job && !state.answer && polling === null) { clearMessages(); follow(job, null, null); }
  });
  $("export-csv").addEventListener("click", exportCsv);
  $("export-geojson").addEventListener("click", exportGeojson);
  $("save").addEventListener("click", () => save().catch((error) => showError(`Unexpected: ${error.message}`)));
  $("resimulate").addEventListener("click", () => resimulate().catch((error) => showError(`Unexpected: ${error.message}`)));
  $("replan").addEventListener("click", () => replan().catch((error) => showError(`Unexpected: ${error.message}`)));
  $("compare-a").addEventListener("change", drawCompare);
  $("compare-b").addEventListener("change", drawCompare);
  $("compare-open").addEventListener("click", () => openToCompare().catch((error) => showError(`Unexpected: ${error.message}`)));
  await loadVans();
  if (job) follow(job, null, null);
}

// For scripts of dispatch teams (and the tests): the answer shown, as the service sent it,
// and what each chart draws.
window.coldroute = {
  answer: () => state.answer,
  request: () => state.request,
  markers: () => {
    const numbers = {};
    for (const m of state.stopsLayer ? state.stopsLayer.getLayers() : []) {
      const node = m.options.icon.options.html;
      (numbers[node.dataset.vehicle] = numbers[node.dataset.vehicle] || []).push(Number(node.textContent));
    }
    for (const list of Object.values(numbers)) list.sort((a, b) => a - b);
    return numbers;
  },
  charts: () => [...document.querySelectorAll("figure.chart")].filter((f) => f.plot).map((f) => ({
    testid: f.dataset.testid, vehicle: f.dataset.vehicle,
    series: f.plot.series.slice(1).map((s) => s.label), points: f.plot.data[0].length,
    start: f.plot.series[0].value(f.plot, f.plot.data[0][0]),
  })),
};

document.addEventListener("DOMContentLoaded", () => {
  start().catch((error) => showError(`Unexpected: ${error.message}`));
});
