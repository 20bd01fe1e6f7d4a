/* infomarket viewer, part 2 of 2 (viewer-draw.js, loaded first, is part 1): the side panel, the
 * animation loop, the two frame sources and the controls.
 *
 * Two sources feed the same drawing code: a live server (WebSocket at ./ws, see viewer/server.py) and
 * a replay whose frames are embedded in the page (<script id="infomarket-replay">, see viewer/recording.py).
 * Tests and curious users read the page's state through window.infomarketViewer.
 */
"use strict";
(() => {
  const {
    $, DROPPED, FLAG, V, arena, decodeFrame, drawArena, drawCharts,
    esc, firstOfKind, fit, pushHistory, robotAt, setScene, showFrame,
  } = infomarketDraw;

  // ------------------------------------------------------------------------------------- panel
  function eventText(e, i) {
    const site = e.site ?? "";
    if (e.kind === "deposit") return "deposited an item";
    if (e.kind === "purchase") return e.buyer === i ? `bought ${site} info from #${e.seller}` : `sold ${site} info to #${e.buyer}`;
    return e.buyer === i ? `#${e.seller} could not stake for ${site} info` : `could not stake to sell ${site} info to #${e.buyer}`;
  }

  function renderPanel() {
    const panel = $("panel"), i = V.selected, s = V.scene, f = V.frame;
    if (i === null || !s || !f) {
      delete panel.dataset.robot;
      delete panel.dataset.detail;
      panel.innerHTML = '<p class="muted">Click a robot to see its navigation table, wealth and trades.</p>';
      return;
    }
    const c = f.c, b = s.behaviours[s.kind[i]];
    const flags = c.flags[i];
    const last = flags & FLAG.lastFood ? "food" : flags & FLAG.lastNest ? "nest" : "none yet";
    const total = f.header.wealth_honest + f.header.wealth_byzantine;
    const rows = [
      ["behaviour", `${esc(b.name)} (${b.honest ? "honest" : "Byzantine"})`],
      ["state", esc(s.states[c.state[i]].replace("_", " "))],
      ["carrying an item", flags & FLAG.carrying ? "yes" : "no"],
      ["odometry bias", `${s.bias[i] >= 0 ? "+" : ""}${s.bias[i].toFixed(4)} °/step`],
      ["wealth", `${c.wealth[i].toFixed(3)} (${total > 0 ? (100 * c.wealth[i] / total).toFixed(2) : "0"} % of all)`],
      ["items collected", `${c.items[i]}`],
      ["last site visited", last],
    ];
    if (s.chain) {
      const br = c.branch[i];
      rows.push(["chain height", `${c.chain_height[i]} (canonical ${f.header.chain_height})`],
                ["chain lag", `${c.chain_lag[i]} block${c.chain_lag[i] === 1 ? "" : "s"}`],
                ["branch", br === 0 ? "canonical" : br === DROPPED ? "dropped (waits for a heavier block)" : `fork ${br}`]);
    }
    let html = `<h2>robot #${i}</h2><table>${rows.map(([k, v]) => `<tr><th>${k}</th><td>${v}</td></tr>`).join("")}</table>`;
    html += "<h3>navigation table</h3><table><tr><th>site</th><th>believed at</th><th>age</th><th>off by</th></tr>";
    s.sites.forEach((site, k) => {
      if (!firstOfKind(s, k)) return; // one table entry per kind; "off by": from the nearest site of it
      const valid = flags & (site.name === "food" ? FLAG.foodValid : FLAG.nestValid);
      const bx = c[`${site.name}_x`][i], by = c[`${site.name}_y`][i];
      const off = Math.min(...s.sites.filter((o) => o.name === site.name).map((o) => Math.hypot(bx - o.x, by - o.y)));
      html += `<tr><td>${site.name}</td>` + (valid
        ? `<td>(${bx.toFixed(0)}, ${by.toFixed(0)})</td><td>${c[`${site.name}_age`][i]}</td><td>${off.toFixed(0)}</td>`
        : `<td colspan="3" class="muted">unknown (age ${c[`${site.name}_age`][i]})</td>`) + "</tr>";
    });
    html += "</table>";
    const pf = c.pending_food[i], pn = c.pending_nest[i];
    const d = V.detail && V.detail.id === i ? V.detail : null;
    if (d && d.chain) {
      html += `<h3>its chain view</h3><table><tr><th>balance at its head</th><td>${d.chain.balance_at_head.toFixed(3)}</td></tr>` +
        `<tr><th>spendable (less its pending reveals)</th><td>${d.chain.spendable.toFixed(3)}</td></tr>` +
        `<tr><th>gas paid</th><td>${d.chain.gas_paid.toFixed(4)}</td></tr>` +
        `<tr><th>mean lag so far</th><td>${d.chain.mean_lag} blocks</td></tr></table>`;
    }
    if (pf || pn || (d && d.pending.length)) {
      html += `<h3>pending information (unconfirmed): food ${pf}, nest ${pn}</h3>`;
      if (d) html += "<ul>" + d.pending.map((p) => `<li>${p.site} from #${p.seller}, age ${p.age}, points at (${p.x.toFixed(0)}, ${p.y.toFixed(0)})</li>`).join("") + "</ul>";
    }
    if (d) {
      html += `<h3>open purchases since last deposit (${d.open_transactions.length})</h3>`;
      html += d.open_transactions.length
        ? "<ul>" + d.open_transactions.slice(-8).map((t) => `<li>${t.site} from #${t.seller}, direction ${t.direction}°</li>`).join("") + "</ul>"
        : '<p class="muted">none</p>';
    }
    const events = d ? d.events : V.mode === "replay" ? replayEvents(i, f.step) : [];
    html += "<h3>last transactions</h3>";
    html += events.length
      ? "<ul>" + events.map((e) => `<li>step ${e.step}: ${eventText(e, i)}</li>`).join("") + "</ul>"
      : '<p class="muted">none yet</p>';
    panel.innerHTML = html;
    panel.dataset.robot = String(i);
    panel.dataset.detail = d ? String(i) : ""; // the server's details (live only) are shown
  }

  function select(i) {
    V.selected = i;
    V.detail = null;
    V.dirty = V.panelDirty = true;
    if (V.source.select) V.source.select(i);
  }

  // ------------------------------------------------------------------------------------- loop
  let lastPanel = 0, lastCharts = 0;
  function tick(now) {
    V.rafs++;
    if (V.source && V.source.tick) V.source.tick(now);
    // a pass before the first frame has arrived draws nothing and is not counted: framesDrawn > 0 must
    // mean robots are on the canvas (the browser test polled ready && framesDrawn and read a blank canvas)
    if (V.dirty) { if (drawArena()) { V.drawn++; V.totalDrawn++; } V.dirty = false; }
    if (V.panelDirty && now - lastPanel > 150) { renderPanel(); V.panelDirty = false; lastPanel = now; }
    if (V.chartsDirty && now - lastCharts > 250) { drawCharts(); V.chartsDirty = false; lastCharts = now; }
    if (now - V.fpsSince >= 1000) {
      const dt = (now - V.fpsSince) / 1000;
      V.fps = V.drawn / dt; V.rafFps = V.rafs / dt;
      V.drawn = 0; V.rafs = 0; V.fpsSince = now;
      $("fps").textContent = V.playing ? V.fps.toFixed(0) : "–";
    }
    requestAnimationFrame(tick);
  }

  /** Show ``message``; a passing one hides after 6 s, a ``lasting`` one (the page cannot go on) stays. */
  function error(message, lasting = false) {
    const el = $("error");
    V.lastError = message;
    el.textContent = message; el.hidden = false;
    clearTimeout(error.timer);
    if (!lasting) error.timer = setTimeout(() => { el.hidden = true; }, 6000);
  }

  function setPlaying(on) {
    V.playing = on;
    $("play").textContent = on ? "❚❚ pause" : "▶ play";
  }

  function fillSpeeds(values, chosen) {
    const sel = $("speed");
    sel.innerHTML = values.map((v) => `<option value="${v}"${v === chosen ? " selected" : ""}>${v}</option>`).join("");
  }

  // -------------------------------------------------------------------------------- live source
  function liveSource() {
    const url = new URL("ws", window.location.href);
    url.protocol = url.protocol === "https:" ? "wss:" : "ws:";
    const seed = new URLSearchParams(window.location.search).get("seed");
    if (seed !== null) url.search = `?seed=${encodeURIComponent(seed)}`;
    const ws = new WebSocket(url);
    ws.binaryType = "arraybuffer";
    const send = (msg) => { if (ws.readyState === WebSocket.OPEN) ws.send(JSON.stringify(msg)); };
    ws.onopen = () => { $("connection").textContent = "live"; };
    ws.onclose = () => { $("connection").textContent = "disconnected (server stopped?)"; setPlaying(false); };
    ws.onmessage = (ev) => {
      if (typeof ev.data !== "string") {
        if (V.layout && ev.data.byteLength === V.layout.size) showFrame(decodeFrame(ev.data, 0, V.layout));
        send({ cmd: "ack" });
        return;
      }
      const msg = JSON.parse(ev.data);
      if (msg.type === "scene") { setScene(msg); if (V.selected !== null) send({ cmd: "select", robot: V.selected }); }
      else if (msg.type === "status") { setPlaying(msg.playing); $("speed").value = String(msg.speed); }
      else if (msg.type === "robot") { V.detail = msg; V.panelDirty = V.dirty = true; }
      else if (msg.type === "error") error(msg.message);
    };
    fillSpeeds([1, 2, 5, 10, 20, 50, 100, 200, 500, 1000], 10);
    return {
      ws,
      play: () => send({ cmd: V.playing ? "pause" : "play" }),
      step: () => send({ cmd: "step", n: 1 }),
      speed: (v) => send({ cmd: "speed", value: v }),
      restart: (seed) => send(seed === null ? { cmd: "restart" } : { cmd: "restart", seed }),
      select: (i) => send({ cmd: "select", robot: i }),
    };
  }

  // ------------------------------------------------------------------------------ replay source
  async function gunzipBase64(text) {
    const bin = atob(text);
    const bytes = new Uint8Array(bin.length);
    for (let k = 0; k < bin.length; k++) bytes[k] = bin.charCodeAt(k);
    const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream("gzip"));
    return new Response(stream).arrayBuffer();
  }

  let replayLog = null;
  function replayEvents(i, step) {
    if (!replayLog) return [];
    const { steps, kind, buyer, seller, site } = replayLog;
    let lo = 0, hi = steps.length; // first event after `step`
    while (lo < hi) { const mid = (lo + hi) >> 1; if (steps[mid] <= step) lo = mid + 1; else hi = mid; }
    const out = [];
    for (let e = lo - 1; e >= 0 && out.length < 8; e--) {
      if (buyer[e] !== i && seller[e] !== i) continue;
      out.push({ step: steps[e], kind: V.scene.events[kind[e]], buyer: buyer[e], seller: seller[e],
                 site: site[e] >= 0 ? (V.scene.site_kinds ? V.scene.site_kinds[site[e]] : V.scene.sites[site[e]].name) : null });
    }
    return out;
  }

  async function replaySource(data) {
    $("restart-box").hidden = true;
    $("scrub-label").hidden = false;
    $("connection").textContent = `replay · ${data.frame_count} frames, one every ${data.every} steps`;
    setScene(data.scene);
    const buffer = await gunzipBase64(data.frames);
    const L = V.layout;
    const count = data.frame_count;
    const ev = new Int32Array(await gunzipBase64(data.events));
    const e = data.event_count;
    replayLog = { steps: ev.subarray(0, e), kind: ev.subarray(e, 2 * e), buyer: ev.subarray(2 * e, 3 * e),
                  seller: ev.subarray(3 * e, 4 * e), site: ev.subarray(4 * e, 5 * e) };
    const frames = [];
    for (let k = 0; k < count; k++) {
      frames.push(decodeFrame(buffer, k * L.size, L));
      pushHistory(V.history, frames[k].header);
    }
    const scrub = $("scrub");
    scrub.max = String(count - 1);
    const src = { index: 0, perTick: 1, last: 0 };
    const show = (k) => {
      src.index = Math.max(0, Math.min(count - 1, k));
      scrub.value = String(src.index);
      showFrame(frames[src.index], false);
    };
    scrub.oninput = () => show(Number(scrub.value));
    const speeds = [1, 2, 5, 10, 20, 50].map((m) => m * data.every);
    fillSpeeds(speeds, speeds[0]);
    Object.assign(src, {
      play: () => { if (!V.playing && src.index >= count - 1) show(0); setPlaying(!V.playing); },
      step: () => { setPlaying(false); show(src.index + 1); },
      speed: (v) => { src.perTick = Math.max(1, Math.round(v / data.every)); },
      tick: (now) => {
        if (!V.playing || now - src.last < 1000 / 30) return;
        src.last = now;
        show(src.index + src.perTick);
        if (src.index >= count - 1) setPlaying(false);
      },
    });
    V.source = src;
    show(0);
    return src;
  }

  // ---------------------------------------------------------------------------------- wiring
  function wire() {
    $("play").onclick = () => V.source && V.source.play();
    $("stepbtn").onclick = () => V.source && V.source.step();
    $("speed").onchange = () => V.source && V.source.speed(Number($("speed").value));
    $("restart").onclick = () => {
      const text = $("seed").value.trim();
      if (V.source && V.source.restart) V.source.restart(text === "" ? null : text);  // as text: seeds go up to 2**63 - 1
    };
    $("comm").onchange = () => { V.showComm = $("comm").checked; V.dirty = true; };
    arena.addEventListener("click", (ev) => {
      const rect = arena.getBoundingClientRect();
      select(robotAt(ev.clientX - rect.left, ev.clientY - rect.top));
    });
    window.addEventListener("resize", () => { fit(); V.chartsDirty = true; });
    window.addEventListener("keydown", (ev) => {
      if (["INPUT", "SELECT", "BUTTON"].includes(ev.target.tagName)) return; // their own keys
      if (ev.code === "Space") { ev.preventDefault(); $("play").click(); }
      else if (ev.code === "ArrowRight") $("stepbtn").click();
    });
  }

  window.infomarketViewer = {
    get ready() { return V.ready; },
    get mode() { return V.mode; },
    get step() { return V.frame ? V.frame.step : -1; },
    get fps() { return V.fps; },
    get rafFps() { return V.rafFps; },
    /** Arena redraws since the page opened (a new frame, a selection, a resize). */
    get framesDrawn() { return V.totalDrawn; },
    get playing() { return V.playing; },
    get robots() { return V.scene ? V.scene.n : 0; },
    get robotsDrawn() { return V.robotsDrawn; },
    /** With the chain model: robots drawn with a branch ring (off the canonical branch) in the current frame. */
    get offCanonical() { return V.offCanonical || 0; },
    /** The last error the page showed (null when none). */
    get lastError() { return V.lastError; },
    /** With collisions on: robots drawn in contact with another in the current frame. */
    get contacts() { return V.contacts || 0; },
    get selected() { return V.selected; },
    get seed() { return V.scene ? V.scene.seed : null; },
    /** CSS pixel position of robot i relative to the arena canvas's top-left corner. */
    robotScreenPosition(i) {
      if (!V.frame || !V.view) return null;
      return { x: V.frame.c.x[i] * V.view.scale, y: V.frame.c.y[i] * V.view.scale };
    },
    select,
  };

  wire();
  const embedded = document.getElementById("infomarket-replay");
  if (embedded) {
    V.mode = "replay";
    replaySource(JSON.parse(embedded.textContent)).catch((exc) => error(`cannot read the replay: ${exc}`, true));
  } else {
    V.source = liveSource();
  }
  requestAnimationFrame(tick);
})();
