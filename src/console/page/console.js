// lash console: scopes (uPlot), status, events, estimates and tuning through the server
// (docs/console.md). No framework, no build step. Everything is fetched from this server only.
//
// Data path: one binary /api/frame (the decimated window, float32 min/max per pixel column) is in
// flight at a time; each answer is drawn at the next animation frame, which asks for the next one.
// A slow browser therefore loses no sample (every answer is the min/max of the whole window); it
// redraws less often, and each gap > 100 ms between two redraws is counted as a stall.
"use strict";
(function () {
  const token = new URLSearchParams(location.search).get("token") || "";
  const H = { "X-Lash-Token": token };
  const COLORS = ["#1565c0", "#c62828", "#2e7d32", "#ef6c00", "#6a1b9a", "#00838f", "#ad1457", "#4e342e"];
  const EVCOL = { calibration: "#6a1b9a", state: "#c62828", overrun: "#ef6c00", drift: "#00838f",
    threshold: "#b71c1c", stale: "#757575", resumed: "#9e9e9e", demo: "#558b2f" };
  const VERDICT = { yes: "#2e7d32", no: "#9e9e9e" };  // identified / not identified
  const $ = (id) => document.getElementById(id);
  let meta = null, panels = [], estPanels = new Map(), paused = false, frame = null, dirty = false;
  let since = 0, estSince = 0, events = [], fetching = false, lastDraw = 0, stalls = 0, status = null;
  let retryAt = 0, frames = 0, draws = 0, fps = 0, drawsPerS = 0, t0 = performance.now();
  // read by the browser test: rAF callbacks, data redraws, stalls (monotonic counts)
  window.lashStats = { frames: 0, draws: 0, stalls: 0, fps: 0, drawsPerS: 0, bytes: 0, renderMs: 0 };

  function defaultPanels(sigs) {
    const groups = [["slave", /^slave_(measured_kPa|current_mA)$/], ["pressure", /kPa$/], ["current", /mA$/], ["timing", /_us$/],
      ["state", /^(state|sensor_fresh|dropped)$/], ["frames", /^(overruns|frames_late|frames_lost)$/],
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

  function yRange(p) {
    return (u, lo, hi) => {
      if ($("autoscale").checked || !p.frozen) {
        if (lo == null || hi == null) { lo = -1; hi = 1; }
        if (lo === hi) { lo -= 1; hi += 1; }
        const pad = 0.05 * (hi - lo);
        p.frozen = [lo - pad, hi + pad];
      }
      return p.frozen;
    };
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

  // A scope: per signal its min/max envelope per pixel column, drawn by drawEnvelopes as one
  // filled path per signal (a bar per column from min to max, joined to its neighbours); the
  // uPlot series only carry the data for the scales, the cursor and zoom (paths: none).
  function makePanel(p) {
    const div = newPanelDiv(p.name);
    const series = [{}];
    const none = () => null;
    p.idx = p.signals.map((s) => meta.signals.indexOf(s));
    p.colors = p.idx.map((i) => COLORS[i % COLORS.length]);
    p.signals.forEach((s, k) => {
      const c = p.colors[k];
      series.push({ label: s, stroke: c, width: 1, paths: none, points: { show: false } });
      series.push({ label: s + " min", stroke: c, width: 1, paths: none, points: { show: false }, show: true });
    });
    p.frozen = null;
    const opts = {
      width: Math.max(300, $("scopes").clientWidth - 20), height: p.signals.length > 4 ? 170 : 150, series,
      scales: { x: { time: false }, y: { range: yRange(p) } },
      axes: [{ label: "t [s]" }, { size: 64 }],
      legend: { live: false, show: p.signals.length <= 8 },
      hooks: { draw: [(u) => drawEnvelopes(u, p), (u) => drawEvents(u), () => drawn()] },
    };
    p.plot = new uPlot(opts, [[]].concat(series.slice(1).map(() => [])), div);
    if (p.signals.length <= 8)  // one legend entry per signal: hide the "min" twins
      div.querySelectorAll(".u-legend .u-series").forEach((e, i) => { if (i % 2 === 1) e.style.display = "none"; });
    panels.push(p);
  }

  // the page's main-thread time per redraw: from render() to the last scope drawn [ms]
  let renderStart = 0, pending = 0;
  function drawn() {
    if (pending > 0 && --pending === 0) window.lashStats.renderMs += performance.now() - renderStart;
  }

  function drawEnvelopes(u, p) {
    const d = u.data, x = d[0], n = x.length;
    if (!n) return;
    const ctx = u.ctx, top = u.bbox.top, bottom = top + u.bbox.height;
    const px = new Float64Array(n + 1);
    for (let c = 0; c < n; c++) px[c] = u.valToPos(x[c], "x", true);
    px[n] = n > 1 ? 2 * px[n - 1] - px[n - 2] : px[0] + 1;
    ctx.save();
    ctx.beginPath();
    ctx.rect(u.bbox.left, top, u.bbox.width, u.bbox.height);
    ctx.clip();
    // one polygon per run of non-empty columns: along the maxima (each column's top edge from its
    // left to its right pixel), back along the minima; adjacent columns join, a spike is kept
    const up = new Float64Array(2 * n), dn = new Float64Array(2 * n);
    for (let k = 0; k < p.idx.length; k++) {
      const hi = d[1 + 2 * k], lo = d[2 + 2 * k];
      if (!u.series[1 + 2 * k].show) continue;
      ctx.fillStyle = p.colors[k];
      ctx.strokeStyle = p.colors[k];
      ctx.lineWidth = 1;
      ctx.beginPath();
      let c = 0;
      while (c < n) {
        while (c < n && (hi[c] == null || lo[c] == null)) c++;
        const c0 = c;
        while (c < n && hi[c] != null && lo[c] != null) {
          up[c] = u.valToPos(hi[c], "y", true);
          dn[c] = u.valToPos(lo[c], "y", true);
          c++;
        }
        if (c === c0) break;
        ctx.moveTo(px[c0], up[c0]);
        for (let j = c0; j < c; j++) { ctx.lineTo(px[j], up[j]); ctx.lineTo(px[j + 1], up[j]); }
        for (let j = c - 1; j >= c0; j--) { ctx.lineTo(px[j + 1], dn[j]); ctx.lineTo(px[j], dn[j]); }
        ctx.closePath();
      }
      ctx.fill();
      ctx.stroke();  // a flat envelope (min = max) still shows as a 1-px line
    }
    ctx.restore();
  }

  // The monitor's estimates: value with its 95 % band; green when identified, grey when not.
  function estPanel(name) {
    let p = estPanels.get(name);
    if (p) return p;
    const div = newPanelDiv("est:" + name);
    p = { name, t: [], v: [], lo: [], hi: [], ok: [], frozen: null };
    const series = [{}, { label: name + " 95 % high", stroke: "#90a4ae", width: 1 },
      { label: name + " 95 % low", stroke: "#90a4ae", width: 1 },
      { label: name + " (identified)", stroke: VERDICT.yes, width: 2, points: { show: true, size: 4 } },
      { label: name + " (not identified)", stroke: VERDICT.no, width: 1, dash: [4, 3], points: { show: true, size: 4 } }];
    const opts = { width: Math.max(300, $("scopes").clientWidth - 20), height: 150, series,
      bands: [{ series: [1, 2], fill: "#90a4ae44" }],
      scales: { x: { time: false }, y: { range: yRange(p) } }, axes: [{ label: "t [s]" }, { size: 64 }],
      hooks: { draw: [(u) => drawEvents(u)] } };
    p.plot = new uPlot(opts, [[], [], [], [], []], div);
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

  function drawEvents(u) {
    const ctx = u.ctx, x0 = u.scales.x.min, x1 = u.scales.x.max;
    ctx.save();
    for (const e of events) {
      if (e.t < x0 || e.t > x1) continue;
      const x = Math.round(u.valToPos(e.t, "x", true));
      ctx.strokeStyle = EVCOL[e.kind] || "#555";
      ctx.lineWidth = 1.5;
      ctx.setLineDash([4, 3]);
      ctx.beginPath();
      ctx.moveTo(x, u.bbox.top);
      ctx.lineTo(x, u.bbox.top + u.bbox.height);
      ctx.stroke();
    }
    ctx.restore();
  }

  function render() {
    renderStart = performance.now();
    pending = panels.length;
    const f = frame;
    for (const p of panels) {
      const cols = [f.t];
      for (const i of p.idx) {
        const k = f.pos[i];
        cols.push(k === undefined ? f.empty : f.max[k], k === undefined ? f.empty : f.min[k]);
      }
      p.plot.setData(cols, true);
    }
    const x0 = f.t_end - Number($("window").value);
    for (const p of estPanels.values()) {
      p.plot.setData([p.t, p.hi, p.lo, p.v, p.ok], true);
      p.plot.setScale("x", { min: x0, max: f.t_end });
    }
    const now = performance.now();
    if (lastDraw && now - lastDraw > 100) { stalls++; window.lashStats.stalls = stalls; }
    lastDraw = now;
    draws++;
    window.lashStats.draws++;
  }

  function arr(f32, off, n) {  // float32 → array with null for empty columns (uPlot's gaps)
    const a = new Array(n);
    for (let c = 0; c < n; c++) { const v = f32[off + c]; a[c] = v === v ? v : null; }
    return a;
  }

  async function fetchFrame() {
    fetching = true;
    try {
      const want = [...new Set(panels.flatMap((p) => p.idx))].sort((a, b) => a - b);
      const cols = Math.max(100, Math.floor($("scopes").clientWidth - 60));
      const r = await fetch(`/api/frame?window=${$("window").value}&columns=${cols}&sig=${want.join(",")}`, { headers: H });
      if (!r.ok) { $("conn").textContent = "server: " + r.status; retryAt = performance.now() + 1000; return; }
      const buf = await r.arrayBuffer();
      window.lashStats.bytes += buf.byteLength;
      const dv = new DataView(buf);
      const ncol = dv.getUint32(4, true), nsig = dv.getUint32(8, true);
      const t_end = dv.getFloat64(16, true), t0f = dv.getFloat64(24, true), col = dv.getFloat64(32, true);
      const f = { t_end, bucket_s: dv.getFloat64(40, true), samples: dv.getFloat64(48, true),
        drops: dv.getFloat64(56, true), t: new Array(ncol), min: [], max: [], pos: {}, empty: new Array(ncol).fill(null) };
      for (let c = 0; c < ncol; c++) f.t[c] = t0f + c * col;
      const f32 = new Float32Array(buf, 64, nsig * 2 * ncol);
      for (let k = 0; k < nsig; k++) {
        f.pos[want[k]] = k;
        f.min.push(arr(f32, 2 * k * ncol, ncol));
        f.max.push(arr(f32, (2 * k + 1) * ncol, ncol));
      }
      if (!paused) { frame = f; dirty = true; }
      $("conn").textContent = paused ? "paused" : "live";
    } catch (e) {
      $("conn").textContent = "disconnected";
      retryAt = performance.now() + 1000;  // the server is gone: ask again in a second, not every frame
    } finally {
      fetching = false;
    }
  }

  function fmt(v) { return typeof v === "number" ? (Math.abs(v) >= 1000 || Number.isInteger(v) ? v.toFixed(0) : v.toPrecision(4)) : String(v); }

  // counters whose non-zero value is shown in red
  const BAD = /^(drops|stalls|daq_gaps|daq_incomplete|overruns|frames_late|frames_lost|frames_dropped|counter_jumps|stale_silences)$/;
  function showStatus(d) {
    const f = frame;
    const rows = [["drops", d.drops, "samples the console's ring refused (its drain fell behind)"],
      ["stalls", stalls, "gaps > 100 ms between two redraws (the browser fell behind; no sample lost)"],
      ["samples", d.samples, "samples in the decimator"],
      ["frames/s", fps.toFixed(1), "requestAnimationFrame callbacks per second"],
      ["redraws/s", drawsPerS.toFixed(1), "data redraws per second (one per /api/frame answer)"],
      ["bucket_ms", f ? (f.bucket_s * 1e3).toFixed(1) : "-", "decimation bucket of the window [ms]"]];
    for (const [k, v] of Object.entries(d.status_text || {})) rows.push([k, v, "", /lost|cannot|stale/.test(v)]);
    for (const [k, v] of Object.entries(d.status || {})) rows.push([k, v, ""]);
    const tb = $("status");
    tb.textContent = "";
    for (const [k, v, title, badText] of rows) {
      const tr = tb.insertRow();
      const a = tr.insertCell();
      a.textContent = k;
      a.title = title || "";
      const c = tr.insertCell();
      c.textContent = fmt(v);
      c.setAttribute("data-status", k);
      if (badText || (BAD.test(k) && typeof v === "number" && v > 0)) c.className = "bad";
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
    if (!fetching && !paused && now >= retryAt) fetchFrame();
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
    for (const p of defaultPanels(meta.signals)) makePanel(p);
    const sel = $("addsig");
    sel.add(new Option("...", ""));
    for (const s of meta.signals) sel.add(new Option(s, s));
    sel.addEventListener("change", () => { if (sel.value) { makePanel({ name: sel.value, signals: [sel.value] }); sel.value = ""; } });
    $("pause").addEventListener("click", () => {
      paused = !paused; lastDraw = 0;
      $("pause").textContent = paused ? "resume" : "pause";
    });
    makeForms();
    pollStatus();
    setInterval(pollStatus, 250);
    requestAnimationFrame(tick);
  }
  init();
})();
