// lash console: scopes (uPlot), status, events, tuning through the server (docs/console.md).
// No framework, no build step. Everything is fetched from this server only.
"use strict";
(function () {
  const token = new URLSearchParams(location.search).get("token") || "";
  const H = { "X-Lash-Token": token };
  const COLORS = ["#1565c0", "#c62828", "#2e7d32", "#ef6c00", "#6a1b9a", "#00838f", "#ad1457", "#4e342e"];
  const EVCOL = { calibration: "#6a1b9a", state: "#c62828", overrun: "#ef6c00", drift: "#00838f" };
  const $ = (id) => document.getElementById(id);
  let meta = null, panels = [], paused = false, lastData = null, since = 0, events = [], dirty = false;
  let frames = 0, draws = 0, fps = 0, drawsPerS = 0, t0 = performance.now(), fetching = false;
  window.lashStats = { frames: 0, draws: 0, fps: 0 };

  function defaultPanels(sigs) {
    const groups = [["pressure", /kPa$/], ["current", /mA$/], ["state", /^(state|sensor_fresh|dropped)$/]];
    const used = new Set(), out = [];
    for (const [name, re] of groups) {
      const s = sigs.filter((x) => re.test(x) && !used.has(x));
      s.forEach((x) => used.add(x));
      if (s.length) out.push({ name, signals: s });
    }
    const rest = sigs.filter((x) => !used.has(x));
    if (rest.length) out.push({ name: "other", signals: rest });
    return out;
  }

  function makePanel(p) {
    const div = document.createElement("div");
    div.className = "panel";
    div.setAttribute("data-scope", p.name);
    const h = document.createElement("h2");
    h.textContent = p.name;
    div.appendChild(h);
    $("scopes").appendChild(div);
    const series = [{}], bands = [];
    p.signals.forEach((s, k) => {
      const c = COLORS[(meta.signals.indexOf(s)) % COLORS.length];
      series.push({ label: s + " max", stroke: c, width: 1 });
      series.push({ label: s + " min", stroke: c, width: 1 });
      bands.push({ series: [2 * k + 1, 2 * k + 2], fill: c + "33" });
    });
    p.frozen = null;
    const opts = {
      width: Math.max(300, $("scopes").clientWidth - 20), height: 200, series, bands,
      scales: { x: { time: false }, y: { range: (u, lo, hi) => {
        if ($("autoscale").checked || !p.frozen) {
          if (lo === hi || lo == null) { lo = (lo || 0) - 1; hi = (hi || 0) + 1; }
          const pad = 0.05 * (hi - lo);
          p.frozen = [lo - pad, hi + pad];
        }
        return p.frozen;
      } } },
      axes: [{ label: "t [s]" }, {}],
      legend: { live: true },
      hooks: { draw: [(u) => drawEvents(u)] },
    };
    p.plot = new uPlot(opts, [[]].concat(series.slice(1).map(() => [])), div);
    panels.push(p);
  }

  function drawEvents(u) {
    const ctx = u.ctx, [x0, x1] = [u.scales.x.min, u.scales.x.max];
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
    if (!lastData || paused) return;
    const d = lastData;
    for (const p of panels) {
      const cols = [d.t];
      for (const s of p.signals) {
        const i = meta.signals.indexOf(s);
        cols.push(d.max[i], d.min[i]);
      }
      p.plot.setData(cols, true);
    }
    draws++;
  }

  function fmt(v) { return typeof v === "number" ? (Math.abs(v) >= 1000 || Number.isInteger(v) ? v.toFixed(0) : v.toPrecision(4)) : String(v); }

  function showStatus(d) {
    const rows = [["drops (console ring full)", d.drops, d.drops > 0], ["samples", d.samples],
      ["plot frames/s (requestAnimationFrame)", fps.toFixed(1)], ["plot redraws/s", drawsPerS.toFixed(1)],
      ["bucket [ms]", (d.bucket_s * 1e3).toFixed(1)]];
    for (const [k, v] of Object.entries(d.status_text || {})) rows.push([k, v, /lost|cannot/.test(v)]);
    for (const [k, v] of Object.entries(d.status || {})) rows.push([k, v, /gaps|incomplete|overrun|lost/.test(k) && v > 0]);
    const tb = $("status");
    tb.textContent = "";
    for (const [k, v, bad] of rows) {
      const tr = tb.insertRow();
      tr.insertCell().textContent = k;
      const c = tr.insertCell();
      c.textContent = fmt(v);
      c.setAttribute("data-status", k.split(" ")[0]);
      if (bad) c.className = "bad";
    }
  }

  async function poll() {
    if (fetching) return;
    fetching = true;
    try {
      const win = $("window").value;
      const cols = Math.max(100, Math.floor($("scopes").clientWidth - 60));
      const r = await fetch(`/api/data?window=${win}&columns=${cols}&since=${since}`, { headers: H });
      if (!r.ok) { $("conn").textContent = "server: " + r.status; return; }
      const d = await r.json();
      $("conn").textContent = paused ? "paused" : "live";
      for (const e of d.events) { events.push(e); since = Math.max(since, e.id); addEventRow(e); }
      if (events.length > 1000) events = events.slice(-1000);
      for (const [k, v] of Object.entries(d.params || {})) {
        const el = document.querySelector(`[data-readback="${k}"]`);
        if (el && v !== null && el.textContent === "") el.textContent = fmt(v);
      }
      showStatus(d);
      lastData = d;
      dirty = true;
    } catch (e) {
      $("conn").textContent = "disconnected";
    } finally {
      fetching = false;
    }
  }

  function addEventRow(e) {
    const div = document.createElement("div");
    div.textContent = `${e.t.toFixed(3)} s  ${e.kind}: ${e.text}`;
    div.style.color = EVCOL[e.kind] || "#333";
    $("events").prepend(div);
  }

  function makeForms() {
    const box = $("forms");
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
      info.innerHTML = "";
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

  function frame(now) {
    frames++;
    if (dirty) { dirty = false; render(); }
    if (now - t0 >= 1000) {
      fps = frames * 1000 / (now - t0); drawsPerS = draws * 1000 / (now - t0);
      window.lashStats.fps = fps;
      frames = 0; draws = 0; t0 = now;
    }
    window.lashStats.frames++;
    window.lashStats.draws = (window.lashStats.draws || 0) + 0;
    requestAnimationFrame(frame);
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
    $("pause").addEventListener("click", () => { paused = !paused; $("pause").textContent = paused ? "resume" : "pause"; });
    makeForms();
    setInterval(poll, 50);
    requestAnimationFrame(frame);
  }
  init();
})();
