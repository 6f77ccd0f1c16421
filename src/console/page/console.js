// lash console: scopes (uPlot), status, events, estimates and tuning through the server
// (docs/console.md). No framework, no build step. Everything is fetched from this server only.
//
// Data path (cheap enough for 32 signals at 1 kHz at the display's frame rate on a loaded
// machine): the server decimates per pixel column (min/max) on a fixed grid of columns; the page
// keeps one /api/frame request in flight asking only for the columns it lacks (from its newest,
// partial one minus a margin of 0.25 s for late samples: a few hundred bytes per frame), stores
// them in typed-array rings, and at the next animation frame paints each visible scope's
// envelopes straight into an ImageData (a vertical run of pixels per column and signal, joined to
// its neighbour) laid over the uPlot chart. uPlot draws only the frame (axes, grid, legend,
// cursor, zoom); its x axis is the time before the newest sample (t - now), so it is redrawn only
// when the y range (rounded, with hysteresis) or the window changes. A slow browser loses no
// sample (the columns it lacks are sent at its next request): it redraws less often, and each
// gap > 100 ms between two redraws is counted as a stall.
"use strict";
(function () {
  const token = new URLSearchParams(location.search).get("token") || "";
  const H = { "X-Lash-Token": token };
  const COLORS = ["#1565c0", "#c62828", "#2e7d32", "#ef6c00", "#6a1b9a", "#00838f", "#ad1457", "#4e342e"];
  const EVCOL = { calibration: "#6a1b9a", state: "#c62828", slave_state: "#ad1457", overrun: "#ef6c00", drift: "#00838f",
    threshold: "#b71c1c", stale: "#757575", resumed: "#9e9e9e", demo: "#558b2f" };
  const VERDICT = { yes: "#2e7d32", no: "#9e9e9e" };  // identified / not identified
  const $ = (id) => document.getElementById(id);
  let meta = null, panels = [], estPanels = new Map(), paused = false, store = null, dirty = false;
  let since = 0, estSince = 0, events = [], fetching = false, lastDraw = 0, stalls = 0, status = null;
  let retryAt = 0, frames = 0, draws = 0, fps = 0, drawsPerS = 0, t0 = performance.now(), lastEst = 0;
  let columns = 0, winS = 10, lastAsk = 0;
  const ASK_MS = 8;  // at most one /api/frame request per 8 ms (125/s)
  // read by the browser test: rAF callbacks, data redraws, stalls (monotonic counts)
  window.lashStats = { frames: 0, draws: 0, stalls: 0, fps: 0, drawsPerS: 0, bytes: 0, renderMs: 0 };

  function defaultPanels(sigs) {
    const groups = [["slave", /^slave_(measured_kPa|current_mA)$/], ["pressure", /kPa$/], ["current", /mA$/], ["timing", /_us$/],
      ["state", /^(slave_log_)?(state|sensor_fresh|command_fresh|dropped)$/], ["frames", /^(overruns|frames_late|frames_lost)$/],
      ["v", /^v$/], ["y", /^y$/]];
    const used = new Set(), out = [];
    for (const [name, re] of groups) {
      const s = sigs.filter((x) => re.test(x) && !used.has(x));
      s.forEach((x) => used.add(x));
      if (s.length) out.push({ name, signals: s });
    }
    const rest = sigs.filter((x) => !used.has(x));
    for (let i = 0; i < rest.length; i += 8)
      out.push({ name: rest.length > 8 ? "other" + (i / 8 + 1) : "other", signals: rest.slice(i, i + 8) });
    return out;
  }

  function yRange(p) {  // the range given (autoscale) or the one frozen (autoscale off)
    return (u, lo, hi) => {
      if ($("autoscale").checked || !p.frozen) {
        if (lo == null || hi == null) { lo = -1; hi = 1; }
        if (lo === hi) { lo -= 1; hi += 1; }
        p.frozen = [lo, hi];
      }
      return p.frozen;
    };
  }

  // A y range for the data [lo, hi]: 5 % padding, rounded out to a "nice" step (1, 2, 5 x 10^n of
  // a tenth of the span); kept while the data stay inside and fill more than half of it, so that
  // uPlot's axes are redrawn only when the range really changes.
  function niceRange(cur, lo, hi) {
    if (!(lo <= hi)) return cur || [-1, 1];
    if (cur && lo >= cur[0] && hi <= cur[1] && hi - lo >= 0.5 * (cur[1] - cur[0])) return cur;
    const span = hi - lo || Math.max(Math.abs(hi), 1e-9) * 0.1 || 1;
    const raw = span / 10, e = Math.pow(10, Math.floor(Math.log10(raw))), m = raw / e;
    const step = (m <= 1 ? 1 : m <= 2 ? 2 : m <= 5 ? 5 : 10) * e;
    return [Math.floor((lo - 0.05 * span) / step) * step, Math.ceil((hi + 0.05 * span) / step) * step];
  }

  function newPanelDiv(name) {
    const div = document.createElement("div");
    div.className = "panel";
    div.setAttribute("data-scope", name);
    const h = document.createElement("h2");
    h.textContent = name;
    div.appendChild(h);
    $("scopes").appendChild(div);
    return div;
  }

  function u32color(css) {  // "#rrggbb" → an ImageData pixel (little-endian RGBA as uint32)
    const n = parseInt(css.slice(1), 16);
    return (0xff000000 | ((n & 0xff) << 16) | (n & 0xff00) | ((n >> 16) & 0xff)) >>> 0;
  }

  const visibility = new IntersectionObserver((entries) => {
    for (const e of entries) {
      const p = panels.find((q) => q.div === e.target) || [...estPanels.values()].find((q) => q.div === e.target);
      if (!p) continue;
      p.visible = e.isIntersecting;
      if (p.visible && p.paint) p.paint();
    }
  });

  // A scope: uPlot draws the frame of the chart (its series carry only the y range, paths none);
  // the envelopes are painted by paintScope into a canvas over the plot area.
  function makePanel(p) {
    const div = newPanelDiv(p.name);
    p.div = div;
    p.idx = p.signals.map((s) => meta.signals.indexOf(s));
    p.colors = p.idx.map((i) => COLORS[i % COLORS.length]);
    p.pix = p.colors.map(u32color);
    p.frozen = null;
    p.yr = null;
    p.visible = true;
    const none = () => null;
    const series = [{}].concat(p.signals.map((s, k) => ({ label: s, stroke: p.colors[k], width: 1, paths: none,
      points: { show: false } })));
    const opts = {
      width: Math.max(300, $("scopes").clientWidth - 20), height: p.signals.length > 4 ? 170 : 150, series,
      scales: { x: { time: false }, y: { range: yRange(p) } },
      axes: [{ label: "t − now [s]" }, { size: 64 }],
      legend: { live: false, show: p.signals.length <= 8 },
      cursor: { points: { show: false } },
      hooks: { draw: [() => paintScope(p)] },
    };
    p.plot = new uPlot(opts, scopeData(p), div);
    p.canvas = document.createElement("canvas");
    p.canvas.style.cssText = "position:absolute;left:0;top:0;width:100%;height:100%;pointer-events:none";
    p.plot.over.prepend(p.canvas);
    p.ctx = p.canvas.getContext("2d");
    p.paint = () => paintScope(p);
    visibility.observe(div);
    panels.push(p);
    if (!columns) columns = Math.max(100, Math.round(p.plot.bbox.width));
    paintScope(p);
  }

  function scopeData(p) {  // x: the window before now; each series: the y range (for the scale)
    const y = p.yr || [null, null];
    return [[-winS, 0]].concat(p.signals.map(() => y));
  }

  // The newest columns of the window: per signal asked for, min and max per column in rings of
  // typed arrays (slot = column index mod cap), the column index each slot holds in `col`.
  function newStore(key, want, col_s, bucket_s) {
    const cap = Math.ceil(winS / col_s) + 64, n = want.length;
    const pos = new Map();
    want.forEach((g, k) => pos.set(g, k));
    return { key, want, pos, col_s, bucket_s, cap, last: null, t_end: 0, samples: 0, drops: 0,
      margin: Math.max(2, Math.ceil(0.25 / col_s)), col: new Float64Array(cap).fill(NaN),
      lo: new Float32Array(cap * n), hi: new Float32Array(cap * n) };
  }

  // The envelopes of a scope's signals over uPlot's x and y scales: per column a vertical run of
  // pixels from min to max, stretched to meet the previous column's run (a line, not dots; a
  // one-sample spike stays), written into an ImageData and put in one call; then the events.
  function paintScope(p) {
    if (!p.visible || !p.ctx) return;
    const u = p.plot, bw = Math.round(u.bbox.width), bh = Math.round(u.bbox.height);
    if (bw <= 0 || bh <= 0) return;
    if (p.canvas.width !== bw || p.canvas.height !== bh || !p.img) {
      p.canvas.width = bw; p.canvas.height = bh;
      p.img = p.ctx.createImageData(bw, bh);
      p.buf = new Uint32Array(p.img.data.buffer);
    }
    const buf = p.buf, s = store;
    buf.fill(0);
    const x0 = u.scales.x.min, x1 = u.scales.x.max, y0 = u.scales.y.min, y1 = u.scales.y.max;
    if (s && s.last !== null && x1 > x0 && y1 > y0) {
      const sx = bw / (x1 - x0), sy = bh / (y1 - y0), col = s.col_s, tEnd = s.t_end, cap = s.cap;
      const jA = Math.max(Math.floor((tEnd + x0) / col), s.last - cap + 1);
      const jB = Math.min(s.last, Math.floor((tEnd + x1) / col));
      for (let k = 0; k < p.idx.length; k++) {
        const g = s.pos.get(p.idx[k]);
        if (g === undefined || !u.series[1 + k].show) continue;
        const c = p.pix[k], base = g * cap, LO = s.lo, HI = s.hi;
        let plo = NaN, phi = NaN;
        for (let j = jA; j <= jB; j++) {
          const slot = ((j % cap) + cap) % cap;
          if (s.col[slot] !== j) { plo = phi = NaN; continue; }
          const lo = LO[base + slot], hi = HI[base + slot];
          if (lo !== lo) { plo = phi = NaN; continue; }
          const a = phi < lo ? phi : lo, b = plo > hi ? plo : hi;  // NaN compares false: no join
          plo = lo; phi = hi;
          let xa = Math.floor((j * col - tEnd - x0) * sx), xb = Math.floor(((j + 1) * col - tEnd - x0) * sx) - 1;
          if (xb < xa) xb = xa;
          if (xa < 0) xa = 0;
          if (xb > bw - 1) xb = bw - 1;
          let ya = Math.floor((y1 - b) * sy), yb = Math.floor((y1 - a) * sy);
          if (xa > xb || yb < 0 || ya >= bh) continue;
          if (ya < 0) ya = 0;
          if (yb > bh - 1) yb = bh - 1;
          for (let y = ya; y <= yb; y++) {
            const row = y * bw;
            for (let x = xa; x <= xb; x++) buf[row + x] = c;
          }
        }
      }
    }
    p.ctx.putImageData(p.img, 0, 0);
    if (s && events.length) {
      const ctx = p.ctx, sx = bw / (x1 - x0);
      ctx.save();
      ctx.lineWidth = 1.5;
      ctx.setLineDash([4, 3]);
      for (const e of events) {
        const x = Math.round((e.t - s.t_end - x0) * sx);
        if (x < 0 || x >= bw) continue;
        ctx.strokeStyle = EVCOL[e.kind] || "#555";
        ctx.beginPath();
        ctx.moveTo(x, 0);
        ctx.lineTo(x, bh);
        ctx.stroke();
      }
      ctx.restore();
    }
  }

  // The monitor's estimates: value with its 95 % band; green when identified, grey when not.
  // Few points (one per period): uPlot draws them, at most four times a second.
  function estPanel(name) {
    let p = estPanels.get(name);
    if (p) return p;
    const div = newPanelDiv("est:" + name);
    p = { name, div, t: [], v: [], lo: [], hi: [], ok: [], frozen: null, visible: true, dirty: true };
    const series = [{}, { label: name + " 95 % high", stroke: "#90a4ae", width: 1 },
      { label: name + " 95 % low", stroke: "#90a4ae", width: 1 },
      { label: name + " (identified)", stroke: VERDICT.yes, width: 2, points: { show: true, size: 4 } },
      { label: name + " (not identified)", stroke: VERDICT.no, width: 1, dash: [4, 3], points: { show: true, size: 4 } }];
    const yr = (u, lo, hi) => {
      if ($("autoscale").checked || !p.frozen) p.frozen = niceRange(p.frozen, lo == null ? -1 : lo, hi == null ? 1 : hi);
      return p.frozen;
    };
    const opts = { width: Math.max(300, $("scopes").clientWidth - 20), height: 150, series,
      bands: [{ series: [1, 2], fill: "#90a4ae44" }],
      scales: { x: { time: false }, y: { range: yr } }, axes: [{ label: "t − now [s]" }, { size: 64 }],
      hooks: { draw: [(u) => drawEvents(u)] } };
    p.plot = new uPlot(opts, [[], [], [], [], []], div);
    p.paint = () => { p.dirty = true; };
    visibility.observe(div);
    estPanels.set(name, p);
    return p;
  }

  function addEstimate(e) {
    const p = estPanel(e.name);
    p.t.push(e.t); p.hi.push(e.hi); p.lo.push(e.lo);
    p.v.push(e.identified ? e.value : null);
    p.ok.push(e.identified ? null : e.value);
    if (p.t.length > 3600) for (const a of [p.t, p.hi, p.lo, p.v, p.ok]) a.shift();
    p.dirty = true;
  }

  function drawEvents(u) {  // on an estimate panel (x: t - now)
    if (!store) return;
    const ctx = u.ctx, x0 = u.scales.x.min, x1 = u.scales.x.max;
    ctx.save();
    ctx.lineWidth = 1.5;
    ctx.setLineDash([4, 3]);
    for (const e of events) {
      const t = e.t - store.t_end;
      if (t < x0 || t > x1) continue;
      const x = Math.round(u.valToPos(t, "x", true));
      ctx.strokeStyle = EVCOL[e.kind] || "#555";
      ctx.beginPath();
      ctx.moveTo(x, u.bbox.top);
      ctx.lineTo(x, u.bbox.top + u.bbox.height);
      ctx.stroke();
    }
    ctx.restore();
  }

  // One data redraw: each visible scope painted (uPlot's frame redrawn only when its y range
  // changed); the estimate panels at most every 250 ms.
  function render() {
    const start = performance.now(), s = store;
    const jA = Math.max(Math.floor((s.t_end - winS) / s.col_s), s.last - s.cap + 1);
    for (const p of panels) {
      if (!p.visible) continue;
      let lo = Infinity, hi = -Infinity;
      for (let k = 0; k < p.idx.length; k++) {
        const g = s.pos.get(p.idx[k]);
        if (g === undefined || !p.plot.series[1 + k].show) continue;
        const base = g * s.cap;
        for (let j = jA; j <= s.last; j++) {
          const slot = ((j % s.cap) + s.cap) % s.cap;
          if (s.col[slot] !== j) continue;
          const a = s.lo[base + slot], b = s.hi[base + slot];
          if (a < lo) lo = a;
          if (b > hi) hi = b;
        }
      }
      const yr = niceRange(p.yr, lo, hi);
      if (yr !== p.yr || p.win !== winS) {
        p.yr = yr; p.win = winS;
        p.plot.setData(scopeData(p), true);  // redraws the frame, whose draw hook paints the scope
      } else {
        paintScope(p);
      }
    }
    if (estPanels.size && start - lastEst >= 250) {
      lastEst = start;
      for (const p of estPanels.values()) {
        if (!p.visible) continue;
        p.plot.setData([p.t.map((t) => t - s.t_end), p.hi, p.lo, p.v, p.ok], false);
        p.plot.setScale("x", { min: -winS, max: 0 });
        p.dirty = false;
      }
    }
    const now = performance.now();
    window.lashStats.renderMs += now - start;
    if (lastDraw && now - lastDraw > 100) { stalls++; window.lashStats.stalls = stalls; }
    lastDraw = now;
    draws++;
    window.lashStats.draws++;
  }

  // Asks for the columns the store lacks (all of the window for a new store: a new window,
  // width or signal set) and puts them in its rings.
  async function fetchFrame() {
    fetching = true;
    lastAsk = performance.now();
    let again = true;  // false after an error: then the animation frames retry (retryAt)
    try {
      const want = [...new Set(panels.flatMap((p) => p.idx))].sort((a, b) => a - b);
      const key = `${winS}|${columns}|${want.join(",")}`;
      let url = `/api/frame?window=${winS}&columns=${columns}&sig=${want.join(",")}`;
      if (store && store.key === key && store.last !== null) url += `&from=${store.last - store.margin}`;
      const r = await fetch(url, { headers: H });
      if (!r.ok) { $("conn").textContent = "server: " + r.status; retryAt = performance.now() + 1000; again = false; return; }
      const buf = await r.arrayBuffer();
      window.lashStats.bytes += buf.byteLength;
      if (paused) return;
      const dv = new DataView(buf);
      const ncol = dv.getUint32(4, true), nsig = dv.getUint32(8, true);
      const t_end = dv.getFloat64(16, true), t0f = dv.getFloat64(24, true), col = dv.getFloat64(32, true);
      const bucket_s = dv.getFloat64(40, true);
      if (nsig !== want.length || !(col > 0)) return;
      if (!store || store.key !== key || store.col_s !== col) {
        if (url.includes("&from=")) return;  // asked for the old grid: ask again
        store = newStore(key, want, col, bucket_s);
      }
      const s = store, cap = s.cap, f32 = new Float32Array(buf, 64, nsig * 2 * ncol);
      const first = Math.round(t0f / col);
      for (let c = 0; c < ncol; c++) {
        const j = first + c, slot = ((j % cap) + cap) % cap;
        s.col[slot] = j;
        for (let k = 0; k < nsig; k++) {
          s.lo[k * cap + slot] = f32[2 * k * ncol + c];
          s.hi[k * cap + slot] = f32[(2 * k + 1) * ncol + c];
        }
      }
      if (ncol > 0) s.last = s.last === null ? first + ncol - 1 : Math.max(s.last, first + ncol - 1);
      s.t_end = t_end; s.samples = dv.getFloat64(48, true); s.drops = dv.getFloat64(56, true);
      if (s.last !== null) dirty = true;
      if ($("conn").textContent !== "live") $("conn").textContent = "live";
    } catch (e) {
      $("conn").textContent = "disconnected";
      again = false;
      retryAt = performance.now() + 1000;  // the server is gone: ask again in a second, not every frame
    } finally {
      fetching = false;
      // the next request as soon as this answer is in, not at the next animation frame (a round
      // trip longer than a frame would halve the redraws), but at most one per ASK_MS
      if (again && !paused) setTimeout(() => { if (!fetching && !paused) fetchFrame(); },
        Math.max(0, lastAsk + ASK_MS - performance.now()));
    }
  }

  function fmt(v) { return typeof v === "number" ? (Math.abs(v) >= 1000 || Number.isInteger(v) ? v.toFixed(0) : v.toPrecision(4)) : String(v); }

  // counters whose non-zero value is shown in red
  const BAD = /^(drops|stalls|daq_gaps|daq_incomplete|overruns|frames_late|frames_lost|frames_dropped|counter_jumps|stale_silences)$/;
  // The status table: a row per key, made once; afterwards only changed texts are written.
  const statusRows = new Map();
  function showStatus(d) {
    const s = store;
    const rows = [["drops", d.drops, "samples the console's ring refused (its drain fell behind)"],
      ["stalls", stalls, "gaps > 100 ms between two redraws (the browser fell behind; no sample lost)"],
      ["samples", d.samples, "samples in the decimator"],
      ["t_s", s ? s.t_end.toFixed(3) : "-", "time of the newest sample (the scopes' 0) [s]"],
      ["frames/s", fps.toFixed(1), "requestAnimationFrame callbacks per second"],
      ["redraws/s", drawsPerS.toFixed(1), "data redraws per second (one per /api/frame answer painted)"],
      ["bucket_ms", s ? (s.bucket_s * 1e3).toFixed(1) : "-", "decimation bucket of the window [ms]"]];
    for (const [k, v] of Object.entries(d.status_text || {})) rows.push([k, v, "", /lost|cannot|stale/.test(v)]);
    for (const [k, v] of Object.entries(d.status || {})) rows.push([k, v, ""]);
    const tb = $("status");
    for (const [k, v, title, badText] of rows) {
      let c = statusRows.get(k);
      if (!c) {
        const tr = tb.insertRow();
        const a = tr.insertCell();
        a.textContent = k;
        a.title = title || "";
        c = tr.insertCell();
        c.setAttribute("data-status", k);
        statusRows.set(k, c);
      }
      const text = fmt(v), cls = badText || (BAD.test(k) && typeof v === "number" && v > 0) ? "bad" : "";
      if (c.textContent !== text) c.textContent = text;
      if (c.className !== cls) c.className = cls;
    }
  }

  async function pollStatus() {
    try {
      const r = await fetch(`/api/status?since=${since}&est_since=${estSince}`, { headers: H });
      if (!r.ok) return;
      const d = await r.json();
      for (const e of d.events) { events.push(e); since = Math.max(since, e.id); addEventRow(e); }
      if (events.length > 1000) events = events.slice(-1000);
      for (const e of d.estimates) { addEstimate(e); estSince = Math.max(estSince, e.id); }
      for (const [k, v] of Object.entries(d.params || {})) {
        const el = document.querySelector(`[data-readback="${k}"]`);
        if (el && v !== null && el.textContent === "") el.textContent = fmt(v);
      }
      status = d;
      showStatus(d);
    } catch (e) {
      $("conn").textContent = "disconnected";
    }
  }

  function addEventRow(e) {
    const div = document.createElement("div");
    div.textContent = `${e.t.toFixed(3)} s  ${e.kind}: ${e.text}`;
    div.style.color = EVCOL[e.kind] || "#333";
    $("events").prepend(div);
    while ($("events").childNodes.length > 200) $("events").lastChild.remove();
  }

  function makeForms() {
    const box = $("forms");
    if (!meta.params.length) { $("tune").style.display = "none"; return; }
    if (meta.read_only) box.insertAdjacentHTML("beforebegin", "<p class='lim'>read-only console (--console-read-only)</p>");
    for (const p of meta.params) {
      const f = document.createElement("form");
      f.setAttribute("data-tune", "");
      const lab = document.createElement("label");
      lab.textContent = p.name;
      lab.title = p.doc;
      const inp = document.createElement("input");
      inp.type = "number"; inp.step = "any"; inp.min = p.min; inp.max = p.max; inp.required = true;
      inp.setAttribute("data-param", p.name);
      inp.disabled = meta.read_only;
      if (p.value !== null) inp.value = p.value;
      const btn = document.createElement("button");
      btn.textContent = "set"; btn.disabled = meta.read_only;
      const info = document.createElement("span");
      info.className = "unit";
      info.textContent = `${p.unit} [${p.min} .. ${p.max}] ECU: `;
      const rb = document.createElement("span");
      rb.setAttribute("data-readback", p.name);
      if (p.value !== null) rb.textContent = fmt(p.value);
      info.appendChild(rb);
      info.style.gridColumn = "1 / span 3";
      const err = document.createElement("span");
      err.setAttribute("data-error", p.name);
      f.append(lab, inp, btn, info, err);
      f.addEventListener("submit", async (ev) => {
        ev.preventDefault();
        err.textContent = "";
        rb.textContent = "...";
        try {
          const r = await fetch("/api/tune", { method: "POST", headers: Object.assign({ "Content-Type": "application/json" }, H),
            body: JSON.stringify({ name: p.name, value: Number(inp.value) }) });
          const j = await r.json();
          if (j.ok) rb.textContent = fmt(j.readback);
          else { rb.textContent = "(unchanged)"; err.textContent = j.error || ("HTTP " + r.status); }
        } catch (e) { err.textContent = String(e); }
      });
      box.appendChild(f);
    }
  }

  function tick(now) {
    frames++;
    window.lashStats.frames++;
    if (dirty && !paused) { dirty = false; render(); }
    if (!fetching && !paused && now >= retryAt && now - lastAsk > 100) fetchFrame();  // (re)start the stream
    if (now - t0 >= 1000) {
      fps = frames * 1000 / (now - t0); drawsPerS = draws * 1000 / (now - t0);
      window.lashStats.fps = fps; window.lashStats.drawsPerS = drawsPerS;
      frames = 0; draws = 0; t0 = now;
    }
    requestAnimationFrame(tick);
  }

  async function init() {
    const r = await fetch("/api/meta", { headers: H });
    if (!r.ok) { $("conn").textContent = "the token in the URL was refused (" + r.status + ")"; return; }
    meta = await r.json();
    $("title").textContent = "lash console: " + meta.title;
    document.title = "lash console: " + meta.title;
    winS = Number($("window").value);
    for (const p of defaultPanels(meta.signals)) makePanel(p);
    const sel = $("addsig");
    sel.add(new Option("...", ""));
    for (const s of meta.signals) sel.add(new Option(s, s));
    sel.addEventListener("change", () => { if (sel.value) { makePanel({ name: sel.value, signals: [sel.value] }); sel.value = ""; } });
    $("pause").addEventListener("click", () => {
      paused = !paused; lastDraw = 0;
      $("pause").textContent = paused ? "resume" : "pause";
      if (!paused) for (const p of panels) p.plot.setData(scopeData(p), true);  // zoom back to the window
      $("conn").textContent = paused ? "paused" : "live";
    });
    $("window").addEventListener("change", () => { winS = Number($("window").value); dirty = false; });
    makeForms();
    pollStatus();
    setInterval(pollStatus, 250);
    requestAnimationFrame(tick);
  }
  init();
})();
