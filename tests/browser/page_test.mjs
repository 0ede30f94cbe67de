// Drives the explorer's page in Debian's chromium, headless, through the DevTools protocol
// (puppeteer-core): opens it, pans and zooms the map, reads the cursor readout, clicks a
// launch and waits for its trajectory, exports the view, saves a screenshot. Prints what it
// saw as JSON for tests/browser/test_browser.py, which checks it against the command line.
//
//   node page_test.mjs URL SCREENSHOT.png
//
// Exit status 1 with a message when the page does not behave.
import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import puppeteer from "puppeteer-core";

const [url, screenshot] = process.argv.slice(2);
const CHROMIUM = process.env.CHROMIUM || "/usr/bin/chromium";
const TIMEOUT_MS = 30000;

function check(ok, what) {
  if (!ok) throw new Error(what);
}

// The quickstart view (jobs/quickstart.toml's window).
const view = new URLSearchParams({ x: "xi", y: "W", fixed: "-1", x_min: "0", x_max: "1", y_min: "-3", y_max: "3",
                                   e: "0.9", alpha: "0.9", max_bounces: "1000" });

const profile = fs.mkdtempSync(path.join(os.tmpdir(), "superball-chromium-"));
// Headless as root needs --no-sandbox; the machine's network is closed, so every
// background connection Chromium would try is turned off (NOTES.md).
const browser = await puppeteer.launch({
  executablePath: CHROMIUM,
  headless: true,
  userDataDir: profile,
  args: ["--no-sandbox", "--disable-gpu", "--disable-background-networking", "--disable-component-update",
         "--disable-sync", "--no-first-run", "--disable-default-apps", "--disable-extensions"],
});
const report = { errors: [] };
try {
  const page = await browser.newPage();
  page.setDefaultTimeout(TIMEOUT_MS);
  await page.setViewport({ width: 1280, height: 800 });
  page.on("pageerror", (e) => report.errors.push("page error: " + e.message));
  // HTTP errors are reported by URL (below), not by the console's copy of them.
  page.on("console", (m) => {
    if (m.type() === "error" && !m.text().startsWith("Failed to load resource")) report.errors.push("console: " + m.text());
  });
  // The cursor over xi <= 0 or U >= 0 is over no launch: the readout shows /api/count's 400
  // message there. Any other HTTP error is the page's fault.
  page.on("response", (r) => {
    if (r.status() >= 400 && !(r.status() === 400 && r.url().includes("/api/count?"))) {
      report.errors.push("HTTP " + r.status() + ": " + r.url());
    }
  });
  page.on("requestfailed", (r) => {
    // Leaflet drops tiles it no longer needs, and the page the count of a position the
    // pointer has left (app.js: a new readout aborts the one in flight); the browser reports
    // both as aborted.
    const dropped = r.url().includes("/tile/") || r.url().includes("/api/count?");
    if (!(dropped && r.failure()?.errorText === "net::ERR_ABORTED")) {
      report.errors.push("request failed: " + r.url() + " " + r.failure()?.errorText);
    }
  });

  const tilesLoaded = async (zoom) => {
    await page.waitForNetworkIdle({ idleTime: 300 });
    return page.evaluate((z) => {
      const imgs = [...document.querySelectorAll(".leaflet-tile-container img")];
      const at = imgs.filter((i) => i.src.includes(`/tile/${z}/`));
      return { loaded: at.filter((i) => i.classList.contains("leaflet-tile-loaded") && i.naturalWidth === 256).length,
               all: at.length };
    }, zoom);
  };
  // The map at rest: no move for 300 ms (a drag's inertia, a zoom's animation can outlast
  // the events the steps wait for on a loaded machine, and a point computed from the view
  // would then be clicked somewhere else).
  const settled = () => page.evaluate(() => new Promise((done) => {
    const m = window.explorer.map;
    let timer = setTimeout(finish, 300);
    function finish() {
      m.off("move zoom", again);
      done();
    }
    function again() {
      clearTimeout(timer);
      timer = setTimeout(finish, 300);
    }
    m.on("move zoom", again);
  }));
  const mapState = () => page.evaluate(() => {
    const m = window.explorer.map;
    return { zoom: m.getZoom(), center: m.getCenter() };
  });

  // The page's own texts, for a failure message.
  const texts = () => page.evaluate(() => Object.fromEntries(["readout", "trajectory-info", "message"].map(
    (id) => [id, document.getElementById(id) ? document.getElementById(id).textContent : null])));
  // The pointer at (x, y) and the count of the launch under it in the readout. A loaded
  // machine (the other tests run beside this one) can swallow a move made while the map
  // still animates: the pointer moves again, off by a pixel and back, up to three times.
  const readoutAt = async (x, y) => {
    for (let attempt = 0; ; ++attempt) {
      await page.mouse.move(x + 1, y);
      await page.mouse.move(x, y);
      try {
        await page.waitForFunction(() => /N  = \d+ wall bounce/.test(document.getElementById("readout").textContent),
                                   { timeout: 10000 });
        return;
      } catch (err) {
        if (attempt == 2) throw new Error("no count in the readout after 3 moves: " + JSON.stringify(await texts()));
      }
    }
  };

  await page.goto(url + "#" + view.toString(), { waitUntil: "networkidle0" });
  await page.waitForFunction(() => window.explorer && window.explorer.map);
  const first = await mapState();
  report.initial = { ...first, tiles: await tilesLoaded(first.zoom) };
  // The first view shows the whole window (map units [-256, 0] x [0, 256]) in the map's
  // final size.
  report.initial.fits = await page.evaluate(() => {
    const b = window.explorer.map.getBounds();
    return b.contains([[-256, 0], [0, 256]]);
  });
  check(report.initial.tiles.loaded > 0 && report.initial.tiles.loaded === report.initial.tiles.all,
        "tiles did not load: " + JSON.stringify(report.initial.tiles));
  const mapBox = await (await page.$("#map")).boundingBox();

  // Pan toward the structure near the wall: drag the map 200 px right and 150 px up.
  const cx = mapBox.x + mapBox.width / 2, cy = mapBox.y + mapBox.height / 2;
  await page.mouse.move(cx, cy);
  await page.mouse.down();
  for (let k = 1; k <= 10; ++k) await page.mouse.move(cx + 20 * k, cy - 15 * k);
  // Held still before the release: Leaflet keeps the pointer's positions of the last 50 ms
  // for the drag's inertia, so the map stops where it was dragged (a release mid-motion
  // would glide on, farther on a loaded machine, whose timing then decides the view).
  await new Promise((r) => setTimeout(r, 200));
  await page.mouse.up();
  await settled();
  const panned = await mapState();
  report.pan = { before: first.center, after: panned.center, scale: Math.pow(2, panned.zoom) };

  // Zoom in twice with the control, with the wheel, then out with the control to zoom 3.
  for (let k = 0; k < 2; ++k) {
    await page.click(".leaflet-control-zoom-in");
    await page.waitForFunction((z) => window.explorer.map.getZoom() === z, {}, first.zoom + k + 1);
  }
  await page.mouse.move(cx + 100, cy + 80);
  await page.mouse.wheel({ deltaY: -100 });
  await page.waitForFunction((z) => window.explorer.map.getZoom() > z, {}, first.zoom + 2);
  const wheeled = (await mapState()).zoom;
  for (let z = wheeled - 1; z >= first.zoom + 2; --z) {
    await page.click(".leaflet-control-zoom-out");
    await page.waitForFunction((z) => window.explorer.map.getZoom() === z, {}, z);
  }
  await settled();
  const zoomed = await mapState();
  report.zoom = { before: first.zoom, wheeled, after: zoomed.zoom, tiles: await tilesLoaded(zoomed.zoom) };
  check(report.zoom.tiles.loaded > 0 && report.zoom.tiles.loaded === report.zoom.tiles.all,
        "zoomed tiles did not load: " + JSON.stringify(report.zoom.tiles));

  // Cursor readout over a launch near the wall.
  const pointOf = (xi, W) => page.evaluate((xi, W) => {
    const s = window.explorer.state, m = window.explorer.map;
    const latlng = L.latLng(((W - s.y_max) / (s.y_max - s.y_min)) * 256, ((xi - s.x_min) / (s.x_max - s.x_min)) * 256);
    return m.latLngToContainerPoint(latlng);
  }, xi, W);
  const zoomView = await page.evaluate(() => {
    const b = window.explorer.map.getBounds(), c = window.explorer.toCoords;
    return { sw: c(b.getSouthWest()), ne: c(b.getNorthEast()) };
  });
  report.visible = zoomView;
  // Points inside the view and inside the launches (0 < xi < 1, the job's W in [-3, 3]).
  const inView = (fx, fy) => {
    const x0 = Math.max(zoomView.sw.x, 0), x1 = Math.min(zoomView.ne.x, 1);
    const y0 = Math.max(zoomView.sw.y, -3), y1 = Math.min(zoomView.ne.y, 3);
    return { xi: x0 + fx * (x1 - x0), W: y0 + fy * (y1 - y0) };
  };
  // The pixels of the tile image at page point (x, y) (it and its 8 neighbours), read back
  // from the image itself through a canvas (same origin), as #rrggbb; null if no tile.
  const pixelsAt = (x, y) => page.evaluate((x, y) => {
    // Tiles take no pointer events (elementsFromPoint passes them by): the loaded tile of
    // the current zoom whose box holds the point.
    const zoom = window.explorer.map.getZoom();
    const img = [...document.querySelectorAll(".leaflet-tile-container img.leaflet-tile-loaded")].find((e) => {
      const b = e.getBoundingClientRect();
      return e.src.includes(`/tile/${zoom}/`) && x >= b.left && x < b.right && y >= b.top && y < b.bottom;
    });
    if (!img) return null;
    const r = img.getBoundingClientRect();
    const canvas = document.createElement("canvas");
    canvas.width = img.naturalWidth;
    canvas.height = img.naturalHeight;
    const ctx = canvas.getContext("2d");
    ctx.drawImage(img, 0, 0);
    const ix = Math.floor((x - r.left) * img.naturalWidth / r.width), iy = Math.floor((y - r.top) * img.naturalHeight / r.height);
    const hex = (d) => "#" + [d[0], d[1], d[2]].map((v) => v.toString(16).padStart(2, "0")).join("");
    const out = [];
    for (let dy = -1; dy <= 1; ++dy) {
      for (let dx = -1; dx <= 1; ++dx) out.push(hex(ctx.getImageData(ix + dx, iy + dy, 1, 1).data));
    }
    return out;
  }, x, y);
  // The probe: the first of a few points of the view that lies inside a region (its 3 x 3
  // pixels of one colour), so that the pixel under it has one count's colour.
  let p = null;
  for (const [fx, fy] of [[0.3, 0.4], [0.35, 0.45], [0.25, 0.35], [0.4, 0.3], [0.45, 0.55], [0.2, 0.6], [0.55, 0.25]]) {
    const probe = inView(fx, fy);
    p = await pointOf(probe.xi, probe.W);
    const around = await pixelsAt(mapBox.x + p.x, mapBox.y + p.y);
    if (around && new Set(around).size === 1) break;
  }
  await readoutAt(mapBox.x + p.x, mapBox.y + p.y);
  report.readout = {
    text: await page.$eval("#readout", (e) => e.textContent),
    start: await page.evaluate(() => window.explorer.readoutStart),
    pixels: await pixelsAt(mapBox.x + p.x, mapBox.y + p.y),
  };

  // Click: the trajectory is drawn and the ball moves. The click must start the launch
  // aimed at (within a pixel's worth of the view): clicked again, at the point as the map
  // now shows it, if the map had not come to rest.
  const aim = inView(0.2, 0.3);
  const pixel = (zoomView.ne.x - zoomView.sw.x) / mapBox.width;
  for (let attempt = 0; ; ++attempt) {
    await settled();
    const q = await pointOf(aim.xi, aim.W);
    await page.mouse.click(mapBox.x + q.x, mapBox.y + q.y);
    const start = await page.evaluate(() => window.explorer.trajectoryStart);
    if (start && Math.abs(start.xi - aim.xi) < 2 * pixel) break;
    if (attempt == 2) throw new Error("the click did not start the launch aimed at: " + JSON.stringify({ aim, start }));
  }
  try {
    await page.waitForFunction(() => /wall bounce/.test(document.getElementById("trajectory-info").textContent));
  } catch (err) {
    const text = await page.$eval("#trajectory-info", (e) => e.textContent);
    const start = await page.evaluate(() => JSON.stringify(window.explorer.trajectoryStart));
    throw new Error(`no trajectory after the click: trajectory-info ${JSON.stringify(text)}, start ${start}: ${err.message}`);
  }
  const ball = () => page.$eval("#trajectory .ball", (b) => [Number(b.getAttribute("cx")), Number(b.getAttribute("cy"))]);
  const b0 = await ball();
  await new Promise((r) => setTimeout(r, 400));
  const b1 = await ball();
  report.trajectory = {
    info: await page.$eval("#trajectory-info", (e) => e.textContent),
    start: await page.evaluate(() => window.explorer.trajectoryStart),
    path_points: await page.$eval("#trajectory .path", (e) => e.getAttribute("points").trim().split(/\s+/).length),
    wall_marks: await page.$$eval("#trajectory .impact", (e) => e.length),
    ball: [b0, b1],
  };

  // Export the visible part as a job.
  await page.click("#export");
  await page.waitForFunction(() => !document.getElementById("job-text").hidden);
  report.job = await page.$eval("#job-text", (e) => e.value);
  report.message = await page.$eval("#message", (e) => e.textContent);

  // SPEC.md 1b from the panel: a finite mu and another ball; the readout at the probe counts
  // with them (the tiles are requested again), and the exported job carries them.
  const setField = (id, value) => page.$eval("#" + id, (e, v) => {
    e.value = v;
    e.dispatchEvent(new Event("change"));
  }, value);
  await setField("mu", "0.3");
  await setField("inertia", "0.5");
  await page.waitForFunction(() => window.explorer.state.mu === 0.3 && window.explorer.state.inertia === 0.5);
  await settled();
  await page.evaluate(() => { document.getElementById("readout").textContent = ""; });
  await readoutAt(mapBox.x + p.x, mapBox.y + p.y);
  report.friction = {
    readout: await page.$eval("#readout", (e) => e.textContent),
    start: await page.evaluate(() => window.explorer.readoutStart),
    tiles: await page.evaluate(() => [...document.querySelectorAll(".leaflet-tile-container img")].filter(
      (i) => i.src.includes("mu=0.3") && i.src.includes("inertia=0.5")).length),
    url: await page.evaluate(() => location.hash),
  };
  await page.click("#export");
  await page.waitForFunction(() => /^mu = /m.test(document.getElementById("job-text").value));
  report.friction.job = await page.$eval("#job-text", (e) => e.value);
  // An inf in the field gives the Cross model back (no mu sent).
  await setField("mu", "inf");
  await page.waitForFunction(() => window.explorer.state.mu === Infinity);
  report.friction.reset_message = await page.$eval("#message", (e) => e.textContent);
  await setField("inertia", "0.4");

  // The screenshot: the map, and the panel from its top (readout, trajectory, view).
  await page.$eval("#panel", (e) => { e.scrollTop = 0; });
  await readoutAt(mapBox.x + p.x, mapBox.y + p.y);
  await page.screenshot({ path: screenshot });
} finally {
  await browser.close();
  fs.rmSync(profile, { recursive: true, force: true });
}
console.log(JSON.stringify(report, null, 1));
