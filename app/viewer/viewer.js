// coldroute plan viewer: the stops from a CSV (or a pasted request), planned by the service,
// drawn as hand-made SVG (no library, nothing from another host but the optional map tiles).
"use strict";

const SVG = "http://www.w3.org/2000/svg";
const CONSUMERS = ["traction", "auxiliaries", "cabin", "refrigeration"];
const CONSUMER_COLOURS = {
  traction: "#4c78a8", auxiliaries: "#f58518", cabin: "#54a24b", refrigeration: "#e45756",
};
const ROUTE_COLOURS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b",
  "#e377c2", "#17becf", "#bcbd22", "#7f7f7f"];
const CSV_COLUMNS = ["id", "lat", "lon", "service_min", "door_min", "kg", "window_start",
  "window_end"];
// Larger requests go as a job: polled, with progress, and reopened by /viewer?job=<id>.
const SYNC_MAX_STOPS = 60;
const SYNC_MAX_TIME_LIMIT_S = 10;

const state = { request: null, endpoint: null, answer: null, routes: [], places: {} };
let polling = null;

function $(id) { return document.getElementById(id); }

function el(tag, attributes = {}, text = null) {
  const node = document.createElement(tag);
  for (const [key, value] of Object.entries(attributes)) node.setAttribute(key, value);
  if (text !== null) node.textContent = text;
  return node;
}

function svg(tag, attributes = {}, text = null) {
  const node = document.createElementNS(SVG, tag);
  for (const [key, value] of Object.entries(attributes)) node.setAttribute(key, String(value));
  if (text !== null) node.textContent = text;
  return node;
}

function titled(node, text) {
  node.appendChild(svg("title", {}, text));
  return node;
}

// ---------------------------------------------------------------- messages

function showError(message) {
  $("errors").appendChild(el("li", { class: "error", "data-testid": "error" }, message));
}

function clearMessages() {
  $("errors").replaceChildren();
  $("status").textContent = "";
}

function showProblem(problem, status) {
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

async function loadVans() {
  const select = $("van-kind");
  const chosen = select.value;
  select.replaceChildren();
  const presets = await api("GET", "/v1/presets");
  const profiles = await api("GET", "/v1/vehicle-profiles");
  if (!presets.ok) {
    select.appendChild(el("option", { value: "preset:paper-generic" }, "paper-generic"));
    if (presets.status === 401) $("status").textContent = "Enter the API key to list the vans.";
    return;
  }
  const group = el("optgroup", { label: "Presets" });
  for (const preset of presets.data.presets) {
    group.appendChild(el("option", { value: `preset:${preset.name}` }, preset.name));
  }
  select.appendChild(group);
  if (profiles.ok && profiles.data.profiles.length) {
    const own = el("optgroup", { label: "Vehicle profiles" });
    for (const profile of profiles.data.profiles) {
      own.appendChild(el("option", { value: `profile:${profile.name}` }, profile.name));
    }
    select.appendChild(own);
  }
  if (chosen && [...select.options].some((o) => o.value === chosen)) select.value = chosen;
  else if ([...select.options].some((o) => o.value === "preset:ev-van-3.5t-reefer")) {
    select.value = "preset:ev-van-3.5t-reefer";
  }
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

function parseStopsCsv(text) {
  const lines = text.replace(/^\ufeff/, "").split(/\r\n|\n|\r/);
  while (lines.length && !lines[lines.length - 1].trim()) lines.pop();
  if (!lines.length || !lines[0].trim()) throw new CsvError("The CSV is empty: it needs a header row.");
  const delimiter = (lines[0].match(/;/g) || []).length > (lines[0].match(/,/g) || []).length ? ";" : ",";
  const header = splitCsvLine(lines[0], delimiter).map((h) => h.toLowerCase());
  for (const name of header) {
    if (!CSV_COLUMNS.includes(name)) {
      throw new CsvError(`Header row, column “${name}”: not a column of this CSV (${CSV_COLUMNS.join(",")}).`);
    }
  }
  for (const needed of ["id", "lat", "lon"]) {
    if (!header.includes(needed)) throw new CsvError(`Header row: the column “${needed}” is missing.`);
  }
  const stops = [];
  const seen = new Set();
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
      if (!/^([01]\d|2[0-3]):[0-5]\d$/.test(raw)) {
        throw new CsvError(`${where(column)}: “${raw}” is not a time of day HH:MM.`);
      }
      return raw;
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
    const start = clock("window_start");
    const end = clock("window_end");
    if ((start === null) !== (end === null)) {
      throw new CsvError(`${where(start === null ? "window_start" : "window_end")}: a window needs both its start and its end.`);
    }
    if (start !== null) {
      if (end <= start) throw new CsvError(`${where("window_end")}: ${end} is not after ${start}.`);
      stop.time_windows = [{ start, end }];
    }
    stops.push(stop);
  }
  if (!stops.length) throw new CsvError("The CSV has a header row but no stop.");
  return stops;
}

async function readStopsFile() {
  const file = $("stops-csv").files[0];
  if (!file) throw new CsvError("Choose a CSV file of stops, or paste a request.");
  return parseStopsCsv(await file.text());
}

function formRequest(stops) {
  const depot = $("depot").value.split(/[,;\s]+/).filter(Boolean).map(Number);
  if (depot.length !== 2 || depot.some((x) => !Number.isFinite(x))) {
    throw new CsvError("Depot: give its latitude and longitude, e.g. 48.1703, 16.4207.");
  }
  const count = Number($("van-count").value);
  if (!Number.isInteger(count) || count < 1 || count > 100) {
    throw new CsvError("How many vans: a whole number from 1 to 100.");
  }
  if (!$("date").value) throw new CsvError("Date: choose the day to plan.");
  const [kind, name] = $("van-kind").value.split(/:(.*)/s);
  const vehicles = [];
  for (let k = 1; k <= count; k += 1) {
    const van = {
      id: `van-${k}`,
      vehicle: kind === "profile" ? { profile: name } : { preset: name || "paper-generic" },
      shift_start: $("shift-start").value,
      shift_end: $("shift-end").value,
    };
    if ($("battery-kwh").value) van.battery = { usable_capacity_kwh: Number($("battery-kwh").value) };
    if ($("payload-kg").value) van.payload_kg = Number($("payload-kg").value);
    vehicles.push(van);
  }
  return {
    date: $("date").value,
    timezone: $("timezone").value || null,
    depot: { id: "depot", lat: depot[0], lon: depot[1] },
    stops,
    vehicles,
    time_limit_s: Number($("time-limit").value) || 3,
  };
}

// ---------------------------------------------------------------- planning

async function plan(event) {
  event.preventDefault();
  clearMessages();
  stopPolling();
  let body;
  const pasted = $("request-json").value.trim();
  try {
    if (pasted) {
      try { body = JSON.parse(pasted); } catch (error) {
        throw new CsvError(`The pasted request is not JSON: ${error.message}`);
      }
      if (!body || typeof body !== "object" || !Array.isArray(body.stops)) {
        throw new CsvError("The pasted request needs its stops[] (the body of /v1/plans or /v1/fleet-plans).");
      }
    } else {
      body = formRequest(await readStopsFile());
    }
  } catch (error) {
    if (error instanceof CsvError) { showError(error.message); return; }
    throw error;
  }
  const endpoint = Array.isArray(body.vehicles) ? "fleet-plans" : "plans";
  // What the viewer draws: the roads (where a router gives them) and the day minute by minute.
  body = { ...body, include_geometry: true, include_profile: true };
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
    show(body, endpoint, answer.data);
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
      show(asked, job.type === "plan" ? "plans" : "fleet-plans", job.result);
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

function localTime(iso) { return iso ? iso.slice(11, 16) : ""; }
function percent(x) { return `${(100 * x).toFixed(0)} %`; }
function kwh(x) { return `${x.toFixed(1)} kWh`; }
function km(m) { return `${(m / 1000).toFixed(1)} km`; }

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

function show(request, endpoint, answer) {
  state.request = request;
  state.endpoint = endpoint;
  state.answer = answer;
  state.routes = routesOf(endpoint, answer);
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
  drawRoutes();
  $("export-csv").disabled = false;
  $("export-geojson").disabled = false;
}

function unassignedOf() {
  return state.endpoint === "plans" ? [] : (state.answer.unassigned || []);
}

// ---------------------------------------------------------------- the map

function mercator(lat, lon) {
  const s = Math.sin((Math.max(Math.min(lat, 85), -85) * Math.PI) / 180);
  return [(lon + 180) / 360, 0.5 - Math.log((1 + s) / (1 - s)) / (4 * Math.PI)];
}

function routeLine(route) {
  const points = [];
  for (const leg of route.legs) {
    const line = leg.geometry && leg.geometry.coordinates;
    if (line && line.length > 1) {
      for (const [lon, lat] of line) points.push([lat, lon]);
    } else {
      for (const id of [leg.from_id, leg.to_id]) {
        const place = state.places[id];
        if (place) points.push([place.lat, place.lon]);
      }
    }
  }
  return points;
}

function niceLength(metres) {
  const power = 10 ** Math.floor(Math.log10(metres));
  for (const step of [5, 2, 1]) if (step * power <= metres) return step * power;
  return power;
}

function drawMap() {
  const map = $("map");
  map.replaceChildren();
  const width = map.clientWidth || 900;
  const height = map.clientHeight || 560;
  map.setAttribute("viewBox", `0 0 ${width} ${height}`);
  const lines = state.routes.map(routeLine);
  const points = lines.flat();
  for (const item of unassignedOf()) {
    const place = state.places[item.id];
    if (place) points.push([place.lat, place.lon]);
  }
  for (const route of state.routes) for (const c of route.charges || []) points.push([c.lat, c.lon]);
  if (!points.length) return;
  const projected = points.map(([lat, lon]) => mercator(lat, lon));
  const xs = projected.map((p) => p[0]);
  const ys = projected.map((p) => p[1]);
  const [x0, x1, y0, y1] = [Math.min(...xs), Math.max(...xs), Math.min(...ys), Math.max(...ys)];
  const pad = 40;
  const fit = Math.min((width - 2 * pad) / Math.max(x1 - x0, 1e-9), (height - 2 * pad) / Math.max(y1 - y0, 1e-9));
  const zoom = Math.max(0, Math.min(18, Math.floor(Math.log2(fit / 256))));
  const scale = 256 * 2 ** zoom;
  const cx = ((x0 + x1) / 2) * scale - width / 2;
  const cy = ((y0 + y1) / 2) * scale - height / 2;
  const at = (lat, lon) => {
    const [x, y] = mercator(lat, lon);
    return [x * scale - cx, y * scale - cy];
  };
  map.appendChild(svg("rect", { x: 0, y: 0, width, height, fill: "#e8edf1" }));
  const tiles = document.body.dataset.tileUrl;
  if (tiles) {
    const layer = svg("g", { "data-testid": "tiles" });
    const count = 2 ** zoom;
    for (let tx = Math.floor(cx / 256); tx <= Math.floor((cx + width) / 256); tx += 1) {
      for (let ty = Math.floor(cy / 256); ty <= Math.floor((cy + height) / 256); ty += 1) {
        if (ty < 0 || ty >= count) continue;
        const wrapped = ((tx % count) + count) % count;
        const href = tiles.replace("{z}", zoom).replace("{x}", wrapped).replace("{y}", ty)
          .replace("{s}", "abc"[(wrapped + ty) % 3]);
        layer.appendChild(svg("image", {
          href, x: tx * 256 - cx, y: ty * 256 - cy, width: 256, height: 256,
        }));
      }
    }
    map.appendChild(layer);
  }
  state.routes.forEach((route, r) => {
    const colour = ROUTE_COLOURS[r % ROUTE_COLOURS.length];
    const path = lines[r].map(([lat, lon]) => at(lat, lon).map((v) => v.toFixed(1)).join(",")).join(" ");
    map.appendChild(titled(svg("polyline", {
      points: path, fill: "none", stroke: colour, "stroke-width": 3.5, "stroke-opacity": 0.85,
      "stroke-linejoin": "round", "data-testid": "route-line", "data-vehicle": route.vehicle_id,
    }), `${route.vehicle_id}: ${km(route.totals.distance_m)}, ${kwh(route.totals.energy_kwh.total)}`));
  });
  const depot = state.request && state.request.depot;
  if (depot) {
    const [x, y] = at(depot.lat, depot.lon);
    map.appendChild(titled(svg("rect", {
      x: x - 8, y: y - 8, width: 16, height: 16, fill: "#12344d", stroke: "#fff",
      "stroke-width": 2, "data-testid": "depot-marker",
    }), `Depot ${depot.id}`));
  }
  state.routes.forEach((route, r) => {
    const colour = ROUTE_COLOURS[r % ROUTE_COLOURS.length];
    route.stops.forEach((stop, k) => {
      const place = state.places[stop.id];
      if (!place) return;
      const [x, y] = at(place.lat, place.lon);
      const window = (state.places[stop.id].time_windows || [])
        .map((w) => `${w.start}–${w.end}`).join(", ") || "none";
      const marker = svg("g", { "data-testid": "stop-marker", "data-stop": stop.id, "data-vehicle": route.vehicle_id });
      marker.appendChild(svg("circle", { cx: x, cy: y, r: 9, fill: "#fff", stroke: colour, "stroke-width": 2.5 }));
      marker.appendChild(svg("text", {
        x, y: y + 3.5, "text-anchor": "middle", "font-size": 10, "font-weight": 700, fill: "#1d2733",
      }, String(k + 1)));
      titled(marker, `${route.vehicle_id} · ${k + 1}. ${stop.id}\narrival ${localTime(stop.arrival)}` +
        `, window ${window}, departure ${localTime(stop.departure)}\nSoC ${percent(stop.soc_arrival)}` +
        ` → ${percent(stop.soc_departure)}, door heat ${stop.door_heat_kwh.toFixed(2)} kWh`);
      map.appendChild(marker);
    });
    for (const charge of route.charges || []) {
      const [x, y] = at(charge.lat, charge.lon);
      map.appendChild(titled(svg("path", {
        d: `M${x - 3},${y - 11} L${x + 5},${y - 11} L${x},${y - 1} L${x + 6},${y - 1} L${x - 5},${y + 12} L${x - 1},${y + 2} L${x - 6},${y + 2} Z`,
        fill: "#f2c200", stroke: "#5a4600", "stroke-width": 1, "data-testid": "charge-marker",
      }), `${route.vehicle_id} charges at ${charge.charger_id} ${localTime(charge.arrive)}–` +
        `${localTime(charge.depart)}: ${percent(charge.soc_before)} → ${percent(charge.soc_after)}`));
    }
  });
  state.routes.forEach((route) => {
    // A reload stands at the depot; a break where the van stands when it begins.
    for (const reload of route.reloads || []) {
      if (!depot) break;
      const [x, y] = at(depot.lat, depot.lon);
      map.appendChild(titled(svg("circle", {
        cx: x, cy: y, r: 13, fill: "none", stroke: "#c46a00", "stroke-width": 2.5,
        "data-testid": "reload-marker",
      }), `${route.vehicle_id} reloads ${localTime(reload.arrive)}–${localTime(reload.depart)}`));
    }
    for (const pause of route.breaks || []) {
      const begins = Date.parse(pause.start);
      const before = route.legs.filter((leg) => Date.parse(leg.arrive) <= begins + 1000).pop();
      const place = state.places[before ? before.to_id : route.legs[0].from_id];
      if (!place) continue;
      const [x, y] = at(place.lat, place.lon);
      map.appendChild(titled(svg("rect", {
        x: x + 7, y: y - 15, width: 9, height: 9, rx: 2, fill: "#7b61c4",
        "data-testid": "break-marker",
      }), `${route.vehicle_id} break (${pause.kind}) ${localTime(pause.start)}–${localTime(pause.end)}`));
    }
  });
  for (const item of unassignedOf()) {
    const place = state.places[item.id];
    if (!place) continue;
    const [x, y] = at(place.lat, place.lon);
    map.appendChild(titled(svg("path", {
      d: `M${x - 6},${y - 6} L${x + 6},${y + 6} M${x - 6},${y + 6} L${x + 6},${y - 6}`,
      stroke: "#b3261e", "stroke-width": 3, "data-testid": "unassigned-marker",
    }), `${item.id} not served: ${item.reason} — ${item.detail}`));
  }
  // The scale, at the map's middle latitude.
  const middle = (y0 + y1) / 2;
  const lat = (Math.atan(Math.sinh(Math.PI * (1 - 2 * middle))) * 180) / Math.PI;
  const metresPerPixel = (40075016.686 * Math.cos((lat * Math.PI) / 180)) / scale;
  const metres = niceLength(120 * metresPerPixel);
  const pixels = metres / metresPerPixel;
  const bar = svg("g", { "data-testid": "scale-bar" });
  bar.appendChild(svg("rect", { x: 10, y: height - 30, width: pixels + 16, height: 22, fill: "#fff", "fill-opacity": 0.8 }));
  bar.appendChild(svg("path", {
    d: `M18,${height - 14} v4 h${pixels} v-4`, stroke: "#1d2733", "stroke-width": 2, fill: "none",
  }));
  bar.appendChild(svg("text", { x: 18, y: height - 18, "font-size": 11, fill: "#1d2733" },
    metres >= 1000 ? `${metres / 1000} km` : `${metres} m`));
  map.appendChild(bar);
  const credit = [document.body.dataset.tileAttribution, state.answer && state.answer.attribution]
    .filter(Boolean).join(" · ");
  if (credit) {
    map.appendChild(svg("text", {
      x: width - 6, y: height - 6, "text-anchor": "end", "font-size": 10, fill: "#3b4855",
    }, credit));
  }
}

// ---------------------------------------------------------------- totals and routes

function drawFleet() {
  const card = $("fleet-card");
  card.hidden = false;
  const totals = $("fleet-totals");
  totals.replaceChildren();
  const served = state.routes.reduce((n, r) => n + r.stops.length, 0);
  const distance = state.routes.reduce((n, r) => n + r.totals.distance_m, 0);
  const energy = state.routes.reduce((n, r) => n + r.totals.energy_kwh.total, 0);
  const grid = state.routes.reduce((n, r) => n + r.totals.grid_kwh, 0);
  const items = [
    ["Vans", String(state.routes.length)], ["Stops served", String(served)],
    ["Not served", String(unassignedOf().length)], ["Distance", km(distance)],
    ["Energy", kwh(energy)], ["From the grid", kwh(grid)],
  ];
  for (const [name, value] of items) {
    const span = el("span");
    span.append(`${name}: `, el("b", {}, value));
    totals.appendChild(span);
  }
  const warnings = $("warnings");
  warnings.replaceChildren();
  for (const route of state.routes) {
    for (const warning of route.warnings || []) {
      warnings.appendChild(el("div", { class: "warning" }, `${route.vehicle_id}: ${warning}`));
    }
  }
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

function drawRoutes() {
  const box = $("routes");
  box.replaceChildren();
  state.routes.forEach((route, r) => {
    const colour = ROUTE_COLOURS[r % ROUTE_COLOURS.length];
    const card = el("div", { class: "card", "data-testid": "route", "data-vehicle": route.vehicle_id });
    const title = el("h2");
    const swatch = el("span", { class: "swatch" });
    swatch.style.background = colour;
    title.append(swatch, `${route.vehicle_id} · ${route.stops.length} stops`);
    const sheet = el("button", { type: "button", class: "secondary", "data-testid": "run-sheet" }, "Run sheet");
    sheet.addEventListener("click", () => printRunSheet(route));
    title.appendChild(sheet);
    card.appendChild(title);
    const battery = route.battery;
    const totals = el("div", { class: "totals" });
    const facts = [
      ["Distance", km(route.totals.distance_m)],
      ["Time", `${(route.totals.duration_s / 3600).toFixed(1)} h`],
      ["Energy", kwh(route.totals.energy_kwh.total)],
      ...CONSUMERS.map((c) => [c, kwh(route.totals.energy_kwh[c])]),
      ["Lowest SoC", percent(battery.min_soc)],
      ["Charges", String((route.charges || []).length)],
      ["Reloads", String((route.reloads || []).length)],
      ["Breaks", String((route.breaks || []).length)],
    ];
    for (const [name, value] of facts) {
      const span = el("span");
      span.append(`${name}: `, el("b", {}, value));
      totals.appendChild(span);
    }
    const verdict = el("span", { class: battery.feasible ? "ok" : "bad" },
      battery.feasible ? "battery holds" : "battery runs short");
    totals.appendChild(verdict);
    card.appendChild(totals);
    const charts = el("div", { class: "charts" });
    charts.append(socChart(route), energyChart(route), boxChart(route));
    card.appendChild(charts);
    card.appendChild(stopTable(route));
    box.appendChild(card);
  });
}

// ---------------------------------------------------------------- charts

function chartFrame(testid, title, route, yLow, yHigh, yLabel) {
  const [t0, t1] = timeRange(route);
  const width = 480;
  const height = 190;
  const margin = { left: 44, right: 10, top: 22, bottom: 24 };
  const chart = svg("svg", { class: "chart", viewBox: `0 0 ${width} ${height}`, "data-testid": testid });
  chart.appendChild(svg("text", { x: margin.left, y: 14, "font-size": 12, "font-weight": 600, fill: "#1d2733" }, title));
  const x = (t) => margin.left + ((t - t0) / Math.max(t1 - t0, 1)) * (width - margin.left - margin.right);
  const y = (v) => height - margin.bottom - ((v - yLow) / Math.max(yHigh - yLow, 1e-9)) * (height - margin.top - margin.bottom);
  const axes = svg("g", { stroke: "#9aa6b2", "stroke-width": 1 });
  axes.appendChild(svg("line", { x1: margin.left, y1: y(yLow), x2: width - margin.right, y2: y(yLow) }));
  axes.appendChild(svg("line", { x1: margin.left, y1: y(yLow), x2: margin.left, y2: y(yHigh) }));
  chart.appendChild(axes);
  for (const v of [yLow, (yLow + yHigh) / 2, yHigh]) {
    chart.appendChild(svg("text", { x: margin.left - 4, y: y(v) + 4, "text-anchor": "end", "font-size": 10, fill: "#4a5866" }, yLabel(v)));
  }
  // Ticks on whole hours of the round's local clock (its times carry their UTC offset).
  const hour = 3600e3;
  const local0 = clockHours(route.legs[0].depart);
  const every = Math.max(1, Math.round((t1 - t0) / hour / 6));
  for (let h = Math.ceil(local0); t0 + (h - local0) * hour <= t1; h += every) {
    const t = t0 + (h - local0) * hour;
    const label = `${String(((h % 24) + 24) % 24).padStart(2, "0")}:00`;
    chart.appendChild(svg("text", { x: x(t), y: height - 8, "text-anchor": "middle", "font-size": 10, fill: "#4a5866" }, label));
  }
  return { chart, x, y };
}

function clockHours(iso) {
  // The local time of day of an ISO time with offset, in hours (06:30:00 is 6.5).
  if (!iso) return 0;
  return Number(iso.slice(11, 13)) + Number(iso.slice(14, 16)) / 60 + Number(iso.slice(17, 19)) / 3600;
}

function spans(route) {
  const bands = [];
  for (const c of route.charges || []) bands.push([c.arrive, c.depart, "#d9f2d9", `charge at ${c.charger_id}`]);
  for (const b of route.breaks || []) bands.push([b.start, b.end, "#e6e0f5", `break (${b.kind})`]);
  for (const r of route.reloads || []) bands.push([r.arrive, r.depart, "#fde9d0", "reload"]);
  return bands;
}

function drawBands(frame, route, top, bottom) {
  for (const [start, end, colour, text] of spans(route)) {
    const x0 = frame.x(Date.parse(start));
    const x1 = frame.x(Date.parse(end));
    frame.chart.insertBefore(titled(svg("rect", {
      x: x0, y: top, width: Math.max(x1 - x0, 1.5), height: bottom - top, fill: colour,
      "data-testid": "chart-band",
    }), `${text} ${localTime(start)}–${localTime(end)}`), frame.chart.children[1]);
  }
}

function timeRange(route) {
  const start = Date.parse(route.legs[0].depart);
  const end = Date.parse(route.legs[route.legs.length - 1].arrive);
  return [start, Math.max(end, start + 60e3)];
}

function socPoints(route) {
  const points = [];
  for (const leg of route.legs) {
    points.push([Date.parse(leg.depart), leg.soc_start, `leave ${leg.from_id}`]);
    points.push([Date.parse(leg.arrive), leg.soc_end, `reach ${leg.to_id}`]);
  }
  for (const c of route.charges || []) {
    points.push([Date.parse(c.arrive), c.soc_before, `plug in at ${c.charger_id}`]);
    points.push([Date.parse(c.depart), c.soc_after, `unplug at ${c.charger_id}`]);
  }
  return points.sort((a, b) => a[0] - b[0]);
}

function socChart(route) {
  const [t0, t1] = timeRange(route);
  const frame = chartFrame("soc-chart", "State of charge", route, 0, 1, percent);
  const profile = route.profile;
  const points = socPoints(route);
  const curve = profile && profile.soc
    ? profile.time.map((t, k) => [Date.parse(t), profile.soc[k]])
    : points.map(([t, s]) => [t, s]);
  drawBands(frame, route, frame.y(1), frame.y(0));
  const reserve = reserveOf(route);
  if (reserve !== null) {
    frame.chart.appendChild(titled(svg("line", {
      x1: frame.x(t0), x2: frame.x(t1), y1: frame.y(reserve), y2: frame.y(reserve),
      stroke: "#b3261e", "stroke-dasharray": "5 4", "stroke-width": 1.5, "data-testid": "reserve-line",
    }), `reserve ${percent(reserve)}`));
  }
  frame.chart.appendChild(svg("polyline", {
    points: curve.map(([t, s]) => `${frame.x(t).toFixed(1)},${frame.y(s).toFixed(1)}`).join(" "),
    fill: "none", stroke: "#1d5c8a", "stroke-width": 2,
  }));
  for (const [t, s, what] of points) {
    frame.chart.appendChild(titled(svg("circle", {
      cx: frame.x(t), cy: frame.y(s), r: 2.5, fill: "#1d5c8a", "data-testid": "soc-point",
    }), `${what}: ${percent(s)} at ${new Date(t).toISOString().slice(11, 16)} UTC`));
  }
  return frame.chart;
}

function reserveOf(route) {
  if (route.battery && typeof route.battery.reserve_soc === "number") return route.battery.reserve_soc;
  const van = vanOf(state.request, route.vehicle_id);
  if (van.battery && typeof van.battery.min_soc === "number") return van.battery.min_soc;
  return null;
}

function cumulativeEnergy(route) {
  if (route.profile && route.profile.energy_kwh) {
    return route.profile.time.map((t, k) => [Date.parse(t),
      Object.fromEntries(CONSUMERS.map((c) => [c, route.profile.energy_kwh[c][k]]))]);
  }
  // Without the day profile: the sums at each leg's and stop's end.
  const sum = Object.fromEntries(CONSUMERS.map((c) => [c, 0]));
  const points = [[Date.parse(route.legs[0].depart), { ...sum }]];
  const stops = Object.fromEntries(route.stops.map((s) => [s.id, s]));
  for (const leg of route.legs) {
    for (const c of CONSUMERS) sum[c] += leg.energy_kwh[c];
    points.push([Date.parse(leg.arrive), { ...sum }]);
    const stop = stops[leg.to_id];
    if (stop) {
      for (const c of CONSUMERS) sum[c] += stop.energy_kwh[c];
      points.push([Date.parse(stop.departure), { ...sum }]);
    }
  }
  return points;
}

function energyChart(route) {
  const points = cumulativeEnergy(route);
  const top = Math.max(...points.map(([, e]) => CONSUMERS.reduce((n, c) => n + e[c], 0)), 0.1);
  const frame = chartFrame("energy-chart", "Energy per consumer (cumulative, stacked)", route, 0, top, (v) => `${v.toFixed(0)} kWh`);
  const below = points.map(() => 0);
  for (const consumer of CONSUMERS) {
    const above = points.map(([, e], k) => below[k] + e[consumer]);
    const upper = points.map(([t], k) => `${frame.x(t).toFixed(1)},${frame.y(above[k]).toFixed(1)}`);
    const lower = points.map(([t], k) => `${frame.x(t).toFixed(1)},${frame.y(below[k]).toFixed(1)}`).reverse();
    frame.chart.appendChild(titled(svg("polygon", {
      points: [...upper, ...lower].join(" "), fill: CONSUMER_COLOURS[consumer], "fill-opacity": 0.8,
      "data-testid": "energy-area", "data-consumer": consumer,
    }), `${consumer}: ${kwh(route.totals.energy_kwh[consumer])}`));
    above.forEach((v, k) => { below[k] = v; });
  }
  CONSUMERS.forEach((consumer, k) => {
    frame.chart.appendChild(svg("rect", { x: 60 + k * 100, y: 28, width: 9, height: 9, fill: CONSUMER_COLOURS[consumer] }));
    frame.chart.appendChild(svg("text", { x: 72 + k * 100, y: 36, "font-size": 10, fill: "#1d2733" }, consumer));
  });
  return frame.chart;
}

function boxChart(route) {
  const [t0, t1] = timeRange(route);
  const series = route.profile && route.profile.box_temperature_c;
  const limit = route.box && typeof route.box.product_limit_c === "number" ? route.box.product_limit_c : null;
  const values = [...(series || []), ...(limit === null ? [] : [limit])];
  const low = Math.floor(Math.min(...values, 0) - 1);
  const high = Math.ceil(Math.max(...values, 8) + 1);
  const frame = chartFrame("box-chart", "Cargo-box temperature", route, low, high, (v) => `${v.toFixed(0)} °C`);
  drawBands(frame, route, frame.y(high), frame.y(low));
  if (limit !== null) {
    frame.chart.appendChild(titled(svg("line", {
      x1: frame.x(t0), x2: frame.x(t1), y1: frame.y(limit), y2: frame.y(limit),
      stroke: "#b3261e", "stroke-dasharray": "5 4", "stroke-width": 1.5, "data-testid": "product-limit",
    }), `product limit ${limit} °C`));
  }
  if (series) {
    frame.chart.appendChild(svg("polyline", {
      points: route.profile.time.map((t, k) => `${frame.x(Date.parse(t)).toFixed(1)},${frame.y(series[k]).toFixed(1)}`).join(" "),
      fill: "none", stroke: "#0b7a75", "stroke-width": 2, "data-testid": "box-line",
    }));
  } else {
    frame.chart.appendChild(svg("text", { x: 52, y: frame.y(low) - 8, "font-size": 11, fill: "#4a5866" },
      "Steady box: the unit holds the set-point (dynamic mode draws the temperature)."));
  }
  return frame.chart;
}

// ---------------------------------------------------------------- tables, sheets, exports

function timeline(route) {
  // Stops, charges, reloads and breaks of a route in the order they happen.
  const rows = route.stops.map((s, k) => ({ at: s.arrival, kind: "stop", n: k + 1, stop: s }));
  for (const c of route.charges || []) rows.push({ at: c.arrive, kind: "charge", item: c });
  for (const r of route.reloads || []) rows.push({ at: r.arrive, kind: "reload", item: r });
  for (const b of route.breaks || []) rows.push({ at: b.start, kind: "break", item: b });
  return rows.sort((a, b) => Date.parse(a.at) - Date.parse(b.at));
}

function stopRow(row) {
  const windows = (place) => ((place && place.time_windows) || []).map((w) => `${w.start}–${w.end}`).join(", ");
  if (row.kind === "stop") {
    const s = row.stop;
    return [String(row.n), s.id, localTime(s.arrival), windows(state.places[s.id]), localTime(s.departure),
      `${s.payload_after_kg.toFixed(0)} kg`, `${percent(s.soc_arrival)} → ${percent(s.soc_departure)}`,
      `${s.door_heat_kwh.toFixed(2)} kWh door heat`];
  }
  const item = row.item;
  if (row.kind === "charge") {
    return ["⚡", item.charger_id, localTime(item.arrive), "", localTime(item.depart), "",
      `${percent(item.soc_before)} → ${percent(item.soc_after)}`,
      `charge ${item.battery_kwh.toFixed(1)} kWh, ${item.minutes.toFixed(0)} min`];
  }
  if (row.kind === "reload") {
    return ["↺", "depot", localTime(item.arrive), "", localTime(item.depart), `${item.payload_kg.toFixed(0)} kg`, "", "reload"];
  }
  return ["☕", "", localTime(item.start), "", localTime(item.end), "", "", `break (${item.kind})`];
}

const SHEET_HEAD = ["#", "Stop", "Arrive", "Window", "Leave", "Payload after", "SoC", "Note"];

function table(route) {
  const t = el("table");
  const head = el("tr");
  for (const name of SHEET_HEAD) head.appendChild(el("th", {}, name));
  t.appendChild(head);
  for (const row of timeline(route)) {
    const tr = el("tr");
    for (const cell of stopRow(row)) tr.appendChild(el("td", {}, cell));
    t.appendChild(tr);
  }
  return t;
}

function stopTable(route) {
  const details = el("details");
  details.appendChild(el("summary", {}, "Stops, charges, reloads and breaks"));
  details.appendChild(table(route));
  return details;
}

function printRunSheet(route) {
  const area = $("print-area");
  area.replaceChildren();
  const van = route.vehicle_id;
  area.appendChild(el("h1", {}, `Run sheet — ${van} — ${state.request ? state.request.date : ""}`));
  area.appendChild(el("p", {}, `Leave ${localTime(route.legs[0].depart)}, back ${localTime(route.legs[route.legs.length - 1].arrive)}; ` +
    `${km(route.totals.distance_m)}, ${route.stops.length} stops, lowest state of charge ${percent(route.battery.min_soc)}.`));
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
  const rows = [["vehicle_id", "sequence", "stop_id", "arrival", "departure", "soc_arrival",
    "soc_departure", "leg_energy_kwh", "stop_energy_kwh", "door_heat_kwh", "payload_after_kg"]];
  for (const route of state.routes) {
    const into = Object.fromEntries(route.legs.map((l) => [l.to_id, l]));
    route.stops.forEach((s, k) => {
      rows.push([route.vehicle_id, k + 1, s.id, s.arrival, s.departure, s.soc_arrival.toFixed(4),
        s.soc_departure.toFixed(4), into[s.id] ? into[s.id].energy_kwh.total.toFixed(4) : "",
        s.energy_kwh.total.toFixed(4), s.door_heat_kwh.toFixed(4), s.payload_after_kg]);
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
          soc_arrival: s.soc_arrival, soc_departure: s.soc_departure } });
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
  window.addEventListener("resize", () => { if (state.answer) drawMap(); });
  await loadVans();
  if (job) follow(job, null, null);
}

// For scripts of dispatch teams (and the tests): the answer shown, as the service sent it.
window.coldroute = { answer: () => state.answer, request: () => state.request };

document.addEventListener("DOMContentLoaded", () => {
  start().catch((error) => showError(`Unexpected: ${error.message}`));
});
