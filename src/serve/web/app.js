// The superball explorer: a Leaflet map of tiles computed by the server (/tile/Z/X/Y.png)
// over a window of two canonical axes, the cursor's count (/api/count), the clicked
// launch's trajectory (/api/trajectory) and the view as a job file (/api/job). The API is
// documented in docs/commands.md ("Exploring in a browser: superball serve", The API).
"use strict";

(function () {
  const AXES = ["xi", "U", "W"];
  const DEFAULT_RANGES = { xi: [0, 1], U: [-3, 0], W: [-3, 3] };
  const DEFAULT_FIXED = { xi: 0.1, U: -1, W: -1 };
  const TILE = 256;
  // Leaflet keeps positions as doubles in map units (0 to 256 across the window at zoom
  // 0): at zoom 40 a pixel is still 1/16 of their resolution. Deeper, the visible part
  // becomes the window (rebase), so zooming goes on until the coordinates themselves run
  // out of double precision.
  const LEAFLET_MAX_ZOOM = 40;
  const REBASE_ZOOM = 30;
  const COUNT_DELAY_MS = 40;
  const TRAJECTORY_SAMPLES = 24;
  const ANIMATION_SECONDS = 6;
  const SOLID_BALL_INERTIA = 0.4;

  const $ = (id) => document.getElementById(id);

  // The view; the page's URL (after #) holds it, so a view can be bookmarked or shared.
  const state = {
    layer: "", x: "xi", y: "W", fixed: -1, x_min: 0, x_max: 1, y_min: -3, y_max: 3,
    per_surface: false, e: 0.9, alpha: 0.9, e_wall: 0.9, alpha_wall: 0.9, e_floor: 0.9, alpha_floor: 0.9,
    mu: Infinity, mu_wall: Infinity, mu_floor: Infinity, inertia: SOLID_BALL_INERTIA,
    max_bounces: 1000, show: "count", colours: "turbo", colour_max: 20,
  };
  // The view's numbers and the ids of the fields that set them.
  const NUMBER_FIELDS = { fixed: "fixed", x_min: "x-min", x_max: "x-max", y_min: "y-min", y_max: "y-max",
                          e: "e", alpha: "alpha", e_wall: "e_wall", alpha_wall: "alpha_wall", e_floor: "e_floor",
                          alpha_floor: "alpha_floor", mu: "mu", mu_wall: "mu_wall", mu_floor: "mu_floor",
                          inertia: "inertia", max_bounces: "max-bounces", colour_max: "colour-max" };
  const NUMBERS = Object.keys(NUMBER_FIELDS);
  const SURFACE_KEYS = ["e_wall", "alpha_wall", "mu_wall", "e_floor", "alpha_floor", "mu_floor"];
  // SPEC.md 1b: a friction coefficient is infinite (the Cross model: no sliding) unless given;
  // its field shows and takes "inf" for that.
  const FRICTION = ["mu", "mu_wall", "mu_floor"];

  let info = null;   // /api/info
  let map = null;
  let tiles = null;
  let marker = null;
  let outline = null;
  let countRequest = null;
  let countTimer = null;
  let animation = null;

  const fixedAxis = () => AXES.find((a) => a !== state.x && a !== state.y);

  function say(text) { $("message").textContent = text || ""; }

  // --- The view as API parameters -----------------------------------------------------

  // Only what differs from SPEC.md 1b's defaults is sent: the server then computes (and a
  // view exports) the model of section 1 as before.
  function modelParams(p) {
    const keys = state.per_surface ? SURFACE_KEYS : ["e", "alpha", "mu"];
    for (const k of keys) if (!(FRICTION.includes(k) && state[k] === Infinity)) p.set(k, String(state[k]));
    if (state.inertia !== SOLID_BALL_INERTIA) p.set("inertia", String(state.inertia));
    p.set("max_bounces", String(state.max_bounces));
    return p;
  }

  function viewParams(window) {
    const p = new URLSearchParams();
    p.set("x", state.x);
    p.set("y", state.y);
    p.set(fixedAxis(), String(state.fixed));
    for (const k of ["x_min", "x_max", "y_min", "y_max"]) p.set(k, String(window[k]));
    return modelParams(p);
  }

  function tileUrl() {
    const p = viewParams(state);
    p.set("show", state.show);
    p.set("colours", state.colours);
    p.set("colour_max", String(state.colour_max));
    if (state.layer !== "") p.set("layer", state.layer);
    return "/tile/{z}/{x}/{y}.png?" + p.toString();
  }

  async function getJson(url, signal) {
    const r = await fetch(url, { signal });
    const body = await r.json();
    if (!r.ok) throw new Error(body.error || ("HTTP " + r.status));
    return body;
  }

  // --- Map units <-> coordinates ------------------------------------------------------
  // The window spans map units 0..256 across (lng) and 0..-256 down (lat), as one tile at
  // zoom 0; the server computes tile (z, x, y) as the same part of the window.

  function toCoords(latlng) {
    return {
      x: state.x_min + (latlng.lng / TILE) * (state.x_max - state.x_min),
      y: state.y_max + (latlng.lat / TILE) * (state.y_max - state.y_min),
    };
  }

  function startOf(c) {
    const s = {};
    s[state.x] = c.x;
    s[state.y] = c.y;
    s[fixedAxis()] = state.fixed;
    return s;
  }

  function visibleWindow() {
    const b = map.getBounds();
    const sw = toCoords(b.getSouthWest()), ne = toCoords(b.getNorthEast());
    return { x_min: sw.x, x_max: ne.x, y_min: sw.y, y_max: ne.y };
  }

  // Decimals that tell neighbouring pixels apart at the current zoom.
  function formatter() {
    const pixel = Math.min(state.x_max - state.x_min, state.y_max - state.y_min) / TILE / Math.pow(2, map.getZoom());
    const decimals = Math.min(20, Math.max(1, Math.ceil(-Math.log10(pixel)) + 1));
    return (v) => (Math.abs(v) < 1e6 ? v.toFixed(decimals) : v.toPrecision(17));
  }

  // The deepest zoom at which a tile's 256 samples are still distinct doubles (with
  // room to spare), and Leaflet's own limit.
  function precisionZoom() {
    let z = LEAFLET_MAX_ZOOM;
    for (const [lo, hi] of [[state.x_min, state.x_max], [state.y_min, state.y_max]]) {
      const ulp = Math.max(Math.abs(lo), Math.abs(hi)) * Math.pow(2, -52) || Number.MIN_VALUE;
      z = Math.min(z, Math.floor(Math.log2((hi - lo) / (TILE * 16 * ulp))));
    }
    return Math.max(0, z);
  }

  // --- Controls -------------------------------------------------------------------------

  function writeControls() {
    $("layer").value = state.layer;
    $("x-axis").value = state.x;
    $("y-axis").value = state.y;
    $("fixed-name").textContent = fixedAxis();
    for (const el of document.querySelectorAll(".x-name")) el.textContent = state.x;
    for (const el of document.querySelectorAll(".y-name")) el.textContent = state.y;
    $("fixed").value = state.fixed;
    $("x-min").value = state.x_min;
    $("x-max").value = state.x_max;
    $("y-min").value = state.y_min;
    $("y-max").value = state.y_max;
    $("per-surface").checked = state.per_surface;
    $("one-material").hidden = state.per_surface;
    $("two-materials").hidden = !state.per_surface;
    for (const k of ["e", "alpha", "mu", "inertia"].concat(SURFACE_KEYS)) {
      $(k).value = state[k] === Infinity ? "inf" : state[k];
    }
    $("max-bounces").value = state.max_bounces;
    $("show").value = state.show;
    $("colours").value = state.colours;
    $("colour-max").value = state.colour_max;
  }

  // Reads the controls; a number that does not read is named and the view kept.
  function readControls() {
    const next = Object.assign({}, state);
    next.layer = $("layer").value;
    next.per_surface = $("per-surface").checked;
    next.show = $("show").value;
    next.colours = $("colours").value;
    for (const [key, id] of Object.entries(NUMBER_FIELDS)) {
      const text = $(id).value.trim();
      const v = readNumber(key, text);
      if (v === null) {
        say(key + " = " + JSON.stringify(text) + " is not a number" + (FRICTION.includes(key) ? " (or inf)" : ""));
        return null;
      }
      next[key] = v;
    }
    if (!(next.x_min < next.x_max) || !(next.y_min < next.y_max)) {
      say("the window needs from < to on both axes");
      return null;
    }
    return next;
  }

  // A finite number, or for a friction coefficient also inf (empty, "inf", "infinity"); null
  // otherwise. The server checks the ranges and names what it refuses.
  function readNumber(key, text) {
    if (FRICTION.includes(key) && /^(|\+?inf(inity)?|\u221e)$/i.test(text)) return Infinity;
    const v = Number(text);
    return text !== "" && Number.isFinite(v) ? v : null;
  }

  function saveToUrl() {
    const p = new URLSearchParams();
    for (const [k, v] of Object.entries(state)) p.set(k, String(v));
    history.replaceState(null, "", "#" + p.toString());
  }

  function loadFromUrl() {
    const p = new URLSearchParams(location.hash.slice(1));
    for (const [k, v] of p.entries()) {
      if (!(k in state)) continue;
      if (NUMBERS.includes(k)) {
        const n = readNumber(k, v);
        if (n !== null) state[k] = n;
      } else if (k === "per_surface") {
        state[k] = v === "true";
      } else {
        state[k] = v;
      }
    }
    if (!AXES.includes(state.x) || !AXES.includes(state.y) || state.x === state.y) {
      state.x = "xi";
      state.y = "W";
    }
  }

  // The tiles, the legend and the URL after a change; `fit`: show the whole window.
  function refresh(fit) {
    say("");
    saveToUrl();
    writeControls();
    map.setMaxZoom(precisionZoom());
    tiles.setUrl(tileUrl());
    if (outline) outline.remove();
    outline = L.rectangle([[-TILE, 0], [0, TILE]], { color: "#fff", weight: 1, dashArray: "4 4", fill: false,
                                                     interactive: false }).addTo(map);
    if (fit) map.fitBounds([[-TILE, 0], [0, TILE]], { animate: false });
    drawLegend();
  }

  function setWindow(w) {
    Object.assign(state, w);
    refresh(true);
  }

  // The visible part becomes the window: same picture, room for 30 more zoom levels.
  function rebase() {
    const w = visibleWindow();
    if (!(w.x_min < w.x_max && w.y_min < w.y_max)) return;
    setWindow(w);
  }

  function onControlChange() {
    const next = readControls();
    if (!next) return;
    const windowChanged = ["x_min", "x_max", "y_min", "y_max"].some((k) => next[k] !== state[k]);
    Object.assign(state, next);
    refresh(windowChanged);
  }

  function onAxisChange(which) {
    const chosen = $(which === "x" ? "x-axis" : "y-axis").value;
    const other = which === "x" ? "y" : "x";
    if (state[other] === chosen) state[other] = state[which];
    state[which] = chosen;
    const f = fixedAxis();
    state.fixed = DEFAULT_FIXED[f];
    [state.x_min, state.x_max] = DEFAULT_RANGES[state.x];
    [state.y_min, state.y_max] = DEFAULT_RANGES[state.y];
    refresh(true);
  }

  function onLayerChange() {
    state.layer = $("layer").value;
    if (state.layer !== "") {
      const l = info.layers[Number(state.layer)];
      state.x = l.view.x;
      state.y = l.view.y;
      state.fixed = l.view.value;
      [state.x_min, state.x_max] = [l.grid[state.x].min, l.grid[state.x].max];
      [state.y_min, state.y_max] = [l.grid[state.y].min, l.grid[state.y].max];
      // The layer's model as /api/info gives it: SPEC.md 1b's coefficients only where not
      // their defaults, an infinite mu as "inf" (JSON has no infinity).
      const m = Object.assign({ mu_wall: "inf", mu_floor: "inf", inertia: SOLID_BALL_INERTIA }, l.model);
      for (const k of ["mu_wall", "mu_floor"]) m[k] = m[k] === "inf" ? Infinity : Number(m[k]);
      state.per_surface = !(m.e_wall === m.e_floor && m.alpha_wall === m.alpha_floor && m.mu_wall === m.mu_floor);
      Object.assign(state, m, { e: m.e_wall, alpha: m.alpha_wall, mu: m.mu_wall });
      state.max_bounces = l.max_bounces;
    }
    refresh(true);
  }

  async function drawLegend() {
    const p = new URLSearchParams({ show: state.show, colours: state.colours, colour_max: String(state.colour_max) });
    try {
      const legend = await getJson("/api/legend?" + p.toString());
      const list = $("legend");
      list.textContent = "";
      for (const e of legend.entries) {
        const li = document.createElement("li");
        const swatch = document.createElement("span");
        swatch.className = "swatch";
        swatch.style.background = e.colour;
        li.append(swatch, document.createTextNode(e.label));
        list.append(li);
      }
    } catch (err) {
      say("legend: " + err.message);
    }
  }

  // --- Cursor readout -----------------------------------------------------------------

  function onMouseMove(ev) {
    const c = toCoords(ev.latlng);
    const f = formatter();
    const s = startOf(c);
    const coords = AXES.map((a) => (a + "  ").slice(0, 3) + "= " + (a === fixedAxis() ? String(s[a]) : f(s[a])));
    window.explorer.readoutStart = s;
    $("readout").textContent = coords.join("\n") + "\nN  = …";
    clearTimeout(countTimer);
    countTimer = setTimeout(() => readCount(s, coords), COUNT_DELAY_MS);
  }

  async function readCount(s, coords) {
    if (countRequest) countRequest.abort();
    countRequest = new AbortController();
    const p = modelParams(new URLSearchParams());
    for (const a of AXES) p.set(a, String(s[a]));
    let line;
    try {
      const r = await getJson("/api/count?" + p.toString(), countRequest.signal);
      line = "N  = " + r.wall_bounces + " wall bounce" + (r.wall_bounces === 1 ? "" : "s") + ", " + r.outcome;
    } catch (err) {
      if (err.name === "AbortError") return;
      line = "N  : " + err.message;
    }
    $("readout").textContent = coords.join("\n") + "\n" + line;
  }

  // --- Trajectory -----------------------------------------------------------------------

  const SVG = "http://www.w3.org/2000/svg";

  function svg(tag, attrs) {
    const el = document.createElementNS(SVG, tag);
    for (const [k, v] of Object.entries(attrs)) el.setAttribute(k, String(v));
    return el;
  }

  async function onClick(ev) {
    const s = startOf(toCoords(ev.latlng));
    window.explorer.trajectoryStart = s;
    if (marker) marker.remove();
    marker = L.circleMarker(ev.latlng, { radius: 5, color: "#fff", weight: 2, fillColor: "#d62728", fillOpacity: 1 }).addTo(map);
    const p = modelParams(new URLSearchParams());
    for (const a of AXES) p.set(a, String(s[a]));
    p.set("samples", String(TRAJECTORY_SAMPLES));
    $("trajectory-info").textContent = "computing…";
    try {
      drawTrajectory(await getJson("/api/trajectory?" + p.toString()), s);
    } catch (err) {
      stopAnimation();
      $("trajectory").textContent = "";
      $("trajectory-info").textContent = err.message;
    }
  }

  function stopAnimation() {
    if (animation) cancelAnimationFrame(animation);
    animation = null;
  }

  // The centre's path (it touches the wall at x = 0 and the floor at y = 0), drawn in the
  // trajectory's own units, with the wall impacts marked and a ball running along it.
  function drawTrajectory(tr, s) {
    stopAnimation();
    const path = tr.path.length ? tr.path : tr.events;
    let xmax = 0, ymax = 0;
    for (const q of path) {
      xmax = Math.max(xmax, q.x);
      ymax = Math.max(ymax, q.y);
    }
    const extent = Math.max(xmax, ymax) || 1;
    const pad = 0.06 * extent;
    const root = $("trajectory");
    root.textContent = "";
    root.setAttribute("viewBox", [-pad, -(ymax + pad), xmax + 2 * pad, ymax + 2 * pad].join(" "));
    const g = svg("g", { transform: "scale(1,-1)" });
    g.append(svg("rect", { class: "surface", x: -pad, y: -pad, width: pad, height: ymax + 2 * pad }));
    g.append(svg("rect", { class: "surface", x: -pad, y: -pad, width: xmax + 2 * pad, height: pad }));
    g.append(svg("polyline", { class: "path", points: path.map((q) => q.x + "," + q.y).join(" "),
                               "vector-effect": "non-scaling-stroke" }));
    // A wall impact that slid (SPEC.md 1b: its grip exceeded mu) is drawn filled.
    for (const e of tr.events) {
      if (e.event === "wall") g.append(svg("circle", { class: e.contact === "slide" ? "impact slide" : "impact",
                                                         cx: e.x, cy: e.y, r: 0.02 * extent,
                                                         "vector-effect": "non-scaling-stroke" }));
    }
    const slid = tr.events.filter((e) => e.contact === "slide").length;
    const ball = svg("circle", { class: "ball", cx: path[0].x, cy: path[0].y, r: 0.025 * extent });
    g.append(ball);
    root.append(g);
    const f = (v) => Number(v).toPrecision(6);
    $("trajectory-info").textContent =
      "start xi = " + f(s.xi) + ", U = " + f(s.U) + ", W = " + f(s.W) + "\n" + tr.wall_bounces + " wall bounce" +
      (tr.wall_bounces === 1 ? "" : "s") + ", " + tr.outcome + "; " + tr.events.length + " events" +
      (tr.events_truncated ? " (the rest below double precision)" : "") +
      (slid ? "\n" + slid + " of the impacts slid" : "");
    // The ball follows the samples in time, the whole motion in ANIMATION_SECONDS.
    const t0 = path[0].t, t1 = path[path.length - 1].t || 1;
    const begin = performance.now();
    const step = (now) => {
      const t = t0 + ((((now - begin) / 1000) % ANIMATION_SECONDS) / ANIMATION_SECONDS) * (t1 - t0);
      let lo = 0, hi = path.length - 1;
      while (hi - lo > 1) {
        const mid = (lo + hi) >> 1;
        if (path[mid].t <= t) lo = mid; else hi = mid;
      }
      const a = path[lo], b = path[hi];
      const w = b.t > a.t ? (t - a.t) / (b.t - a.t) : 0;
      ball.setAttribute("cx", a.x + w * (b.x - a.x));
      ball.setAttribute("cy", a.y + w * (b.y - a.y));
      animation = requestAnimationFrame(step);
    };
    animation = requestAnimationFrame(step);
  }

  // --- Export ---------------------------------------------------------------------------

  async function onExport() {
    const p = viewParams(visibleWindow());
    p.set("nx", $("export-nx").value.trim());
    p.set("ny", $("export-ny").value.trim());
    p.set("output", $("export-output").value.trim());
    const text = $("job-text");
    const link = $("export-download");
    try {
      const r = await fetch("/api/job?" + p.toString());
      if (!r.ok) throw new Error((await r.json()).error);
      const toml = await r.text();
      text.value = toml;
      text.hidden = false;
      if (link.href) URL.revokeObjectURL(link.href);
      link.href = URL.createObjectURL(new Blob([toml], { type: "application/toml" }));
      link.hidden = false;
    } catch (err) {
      say("export: " + err.message);
    }
  }

  // --- Start ------------------------------------------------------------------------------

  function fillSelect(id, values, labels) {
    const el = $(id);
    for (let k = 0; k < values.length; ++k) {
      const o = document.createElement("option");
      o.value = values[k];
      o.textContent = labels ? labels[k] : values[k];
      el.append(o);
    }
  }

  async function start() {
    loadFromUrl();
    try {
      info = await getJson("/api/info");
    } catch (err) {
      say("cannot reach the server: " + err.message);
      return;
    }
    fillSelect("x-axis", AXES);
    fillSelect("y-axis", AXES);
    fillSelect("colours", info.colour_maps);
    fillSelect("layer", info.layers.map((l) => String(l.index)),
               info.layers.map((l) => l.path + (l.kind === "partial" ? " (" + l.tiles_done + "/" + l.tiles + " tiles)" : "")));
    if (state.layer !== "" && !info.layers[Number(state.layer)]) state.layer = "";

    map = L.map("map", { crs: L.CRS.Simple, minZoom: -3, maxZoom: LEAFLET_MAX_ZOOM, attributionControl: false,
                         zoomSnap: 1 });
    tiles = L.tileLayer(tileUrl(), { tileSize: TILE, minZoom: -3, maxZoom: LEAFLET_MAX_ZOOM, minNativeZoom: 0,
                                     maxNativeZoom: LEAFLET_MAX_ZOOM, noWrap: true, keepBuffer: 1 }).addTo(map);
    let reported = false;
    tiles.on("tileerror", async (ev) => {
      if (reported) return;
      reported = true;
      try {
        const r = await fetch(ev.tile.src);
        if (!r.ok) say("tile: " + (await r.json()).error);
      } catch (err) {
        say("tile: " + err.message);
      }
    });
    tiles.on("load", () => { reported = false; });
    map.on("mousemove", onMouseMove);
    map.on("click", onClick);
    map.on("zoomend", () => { if (map.getZoom() >= REBASE_ZOOM) rebase(); });

    for (const id of Object.values(NUMBER_FIELDS).concat(["show", "colours", "per-surface"])) {
      $(id).addEventListener("change", onControlChange);
    }
    $("x-axis").addEventListener("change", () => onAxisChange("x"));
    $("y-axis").addEventListener("change", () => onAxisChange("y"));
    $("layer").addEventListener("change", onLayerChange);
    $("rebase").addEventListener("click", rebase);
    $("reset").addEventListener("click", () => {
      const [x0, x1] = DEFAULT_RANGES[state.x], [y0, y1] = DEFAULT_RANGES[state.y];
      setWindow({ x_min: x0, x_max: x1, y_min: y0, y_max: y1 });
    });
    $("export").addEventListener("click", onExport);
    // For tests and the console: the map, the view, and the starts of the readout and the
    // trajectory.
    window.explorer = { map, state, toCoords, readoutStart: null, trajectoryStart: null };
    refresh(true);
  }

  document.addEventListener("DOMContentLoaded", start);
})();
