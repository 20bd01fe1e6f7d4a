/* infomarket viewer, part 1 of 2 (viewer.js is part 2): decoding frames and drawing them.
 *
 * The viewer draws frames that the Python engine computed; it simulates nothing itself. A frame is
 * binary: float64 header numbers, then one little-endian column per robot attribute, laid out as the
 * scene's "columns" say (viewer/frames.py); we wrap each column in a typed-array view. This part holds
 * the page's state (V), the frame decoding, the arena and the charts; viewer.js holds the side panel,
 * the animation loop, the two frame sources and the controls.
 *
 * Both parts are classic scripts, loaded in order, that share only the one name `infomarketDraw`:
 * a replay page inlines them and opens from disk, where a browser refuses to load ES modules.
 */
"use strict";
const infomarketDraw = (() => {
  const COLOUR = { honest: "#2f6fd6", byzantine: "#d62f2f", food: "#2ca02c", nest: "#e8b100",
                   none: "#666666", heading: "#ffffff", obstacle: "#5a5a5a", contact: "#111111", comm: "rgba(110,110,110,0.35)" };
  // the chain model (docs/chain-model.md): a robot whose head is off the canonical branch gets a ring in
  // its branch's colour; one whose branch was dropped, a grey dashed ring
  const BRANCH = ["#9467bd", "#ff7f0e", "#17becf", "#8c564b", "#e377c2", "#bcbd22"];
  const DROPPED = 255;
  const FLAG = { carrying: 1, foodValid: 2, nestValid: 4, lastFood: 8, lastNest: 16 };
  const TYPED = { "<f8": Float64Array, "<f4": Float32Array, "|u1": Uint8Array, "<i4": Int32Array };
  const MAX_HISTORY = 4000;
  const $ = (id) => document.getElementById(id);
  const esc = (s) => String(s).replace(/[&<>"]/g, (c) => ({ "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;" }[c]));

  const V = {
    mode: "live", scene: null, layout: null, frame: null, selected: null, detail: null,
    showComm: false, playing: false, dirty: true, panelDirty: true, chartsDirty: true, ready: false,
    history: null, robotsDrawn: 0, view: null, lastError: null,
    fps: 0, rafFps: 0, drawn: 0, totalDrawn: 0, rafs: 0, fpsSince: performance.now(),
    source: null,
  };

  // ------------------------------------------------------------------------------------ frames
  function makeLayout(scene) {
    const n = scene.n;
    let offset = 8 * scene.header.length;
    const columns = scene.columns.map(([name, dtype]) => {
      const Typed = TYPED[dtype];
      const col = { name, Typed, offset };
      offset += n * Typed.BYTES_PER_ELEMENT;
      return col;
    });
    // frames.py pads a frame to a multiple of 8 bytes (ALIGN), so that in a replay, where the frames lie
    // end to end in one buffer, frame k's float64 header starts on an 8-byte boundary
    return { n, columns, size: Math.ceil(offset / 8) * 8, header: scene.header };
  }

  function decodeFrame(buffer, base, L) {
    const head = new Float64Array(buffer, base, L.header.length);
    const header = {};
    L.header.forEach((h, k) => { header[h] = head[k]; });
    const c = {};
    for (const col of L.columns) c[col.name] = new col.Typed(buffer, base + col.offset, L.n);
    return { step: header.step, header, c };
  }

  function newHistory() { return { step: [], itemsH: [], itemsB: [], shareH: [], shareB: [] }; }

  function groupCounts() {
    const s = V.scene;
    let honest = 0;
    for (let i = 0; i < s.n; i++) if (s.behaviours[s.kind[i]].honest) honest++;
    return { honest, byzantine: s.n - honest };
  }

  function pushHistory(h, header) {
    const g = V.groups;
    const total = header.wealth_honest + header.wealth_byzantine;
    h.step.push(header.step);
    h.itemsH.push(g.honest ? header.items_honest / g.honest : NaN);
    h.itemsB.push(g.byzantine ? header.items_byzantine / g.byzantine : NaN);
    h.shareH.push(g.honest && total > 0 ? 100 * header.wealth_honest / total / g.honest : NaN);
    h.shareB.push(g.byzantine && total > 0 ? 100 * header.wealth_byzantine / total / g.byzantine : NaN);
    if (h.step.length > MAX_HISTORY) for (const k in h) h[k] = h[k].filter((_, j) => j % 2 === 0);
  }

  function setScene(scene) {
    V.scene = scene;
    V.layout = makeLayout(scene);
    V.groups = groupCounts();
    V.history = newHistory();
    V.frame = null;
    V.detail = null;
    if (V.selected !== null && V.selected >= scene.n) V.selected = null;
    $("title").textContent = `infomarket · ${scene.name}`;
    const groups = scene.behaviours.map((b, k) => `${scene.kind.filter((x) => x === k).length} ${b.name}`).join(" + ");
    const terrain = [];
    const obstacles = scene.obstacles || [];
    if (obstacles.length) terrain.push(`${obstacles.length} obstacle${obstacles.length > 1 ? "s" : ""}`);
    if (scene.robot.collisions) terrain.push("collisions");
    if (scene.robot.line_of_sight) terrain.push("line of sight");
    if (scene.chain) terrain.push(`chain: PoA, a block every ${scene.chain.period} steps` +
      (scene.chain.backbone ? `, backbone latency ${scene.chain.latency}` : "") +
      (scene.chain.loss ? `, loss ${scene.chain.loss}` : "") + (scene.chain.gas_price ? `, gas price ${scene.chain.gas_price}` : ""));
    $("subtitle").textContent = `${groups} · ${scene.scheme} payment · seed ${scene.seed_text ?? scene.seed}` +
      terrain.map((t) => ` · ${t}`).join("");
    $("legend-chain").hidden = !scene.chain;
    if (V.mode === "live") $("seed").placeholder = `random (now ${scene.seed_text ?? scene.seed})`;
    fit();
  }

  function showFrame(frame, record = true) {
    V.frame = frame;
    if (record) pushHistory(V.history, frame.header);
    $("step").textContent = frame.step;
    V.dirty = V.panelDirty = V.chartsDirty = true;
    if (!V.ready) V.ready = true;
  }

  // ------------------------------------------------------------------------------------- arena
  const arena = $("arena");
  const ctx = arena.getContext("2d");

  function fit() {
    if (!V.scene) return;
    const dpr = window.devicePixelRatio || 1;
    const { width, height } = V.scene.arena;
    const cssW = arena.clientWidth || 900;
    const cssH = Math.round(cssW * height / width);
    arena.style.height = `${cssH}px`;
    arena.width = Math.round(cssW * dpr);
    arena.height = Math.round(cssH * dpr);
    V.view = { scale: cssW / width, dpr };
    V.dirty = true;
  }

  function arrow(x0, y0, x1, y1, colour, dashed, s) {
    const len = Math.hypot(x1 - x0, y1 - y0);
    if (len < 1e-6) return;
    const ux = (x1 - x0) / len, uy = (y1 - y0) / len, head = 9 / s;
    ctx.strokeStyle = colour;
    ctx.fillStyle = colour;
    ctx.lineWidth = 2 / s;
    ctx.setLineDash(dashed ? [6 / s, 4 / s] : []);
    ctx.beginPath(); ctx.moveTo(x0, y0); ctx.lineTo(x1 - ux * head, y1 - uy * head); ctx.stroke();
    ctx.setLineDash([]);
    ctx.beginPath();
    ctx.moveTo(x1, y1);
    ctx.lineTo(x1 - ux * head - uy * head * 0.5, y1 - uy * head + ux * head * 0.5);
    ctx.lineTo(x1 - ux * head + uy * head * 0.5, y1 - uy * head - ux * head * 0.5);
    ctx.closePath(); ctx.fill();
  }

  function drawArena() {
    const s = V.scene, f = V.frame;
    if (!s || !f || !V.view) return false;
    const { scale, dpr } = V.view;
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.clearRect(0, 0, arena.width, arena.height);
    ctx.setTransform(scale * dpr, 0, 0, scale * dpr, 0, 0); // world units from here on
    const px = 1 / scale; // one CSS pixel in world units
    ctx.fillStyle = "#f4f4f1";
    ctx.fillRect(0, 0, s.arena.width, s.arena.height);
    for (const site of s.sites) {
      const colour = COLOUR[site.name];
      ctx.beginPath(); ctx.arc(site.x, site.y, site.radius, 0, 2 * Math.PI);
      ctx.globalAlpha = 0.35; ctx.fillStyle = colour; ctx.fill();
      ctx.globalAlpha = 1; ctx.lineWidth = 2 * px; ctx.strokeStyle = colour; ctx.stroke();
    }
    drawObstacles(s, px);
    const { x, y, heading, flags } = f.c;
    const n = s.n, r = Math.max(s.robot.radius, 2.5 * px);
    if (V.showComm) {
      ctx.beginPath();
      for (let i = 0; i < n; i++) { ctx.moveTo(x[i] + s.robot.comm_range, y[i]); ctx.arc(x[i], y[i], s.robot.comm_range, 0, 2 * Math.PI); }
      ctx.lineWidth = px; ctx.strokeStyle = COLOUR.comm; ctx.stroke();
    }
    // Discs, batched by fill colour; outlines batched by last visited site.
    const honest = s.behaviours.map((b) => b.honest);
    for (const [want, colour] of [[true, COLOUR.honest], [false, COLOUR.byzantine]]) {
      ctx.beginPath();
      for (let i = 0; i < n; i++) {
        if (honest[s.kind[i]] !== want) continue;
        ctx.moveTo(x[i] + r, y[i]); ctx.arc(x[i], y[i], r, 0, 2 * Math.PI);
      }
      ctx.fillStyle = colour; ctx.fill();
    }
    ctx.lineWidth = Math.max(r * 0.35, 1.5 * px);
    for (const [bit, colour] of [[FLAG.lastFood, COLOUR.food], [FLAG.lastNest, COLOUR.nest], [0, COLOUR.none]]) {
      ctx.beginPath();
      for (let i = 0; i < n; i++) {
        const last = flags[i] & (FLAG.lastFood | FLAG.lastNest);
        if (bit ? !(last & bit) : last) continue;
        ctx.moveTo(x[i] + r, y[i]); ctx.arc(x[i], y[i], r, 0, 2 * Math.PI);
      }
      ctx.strokeStyle = colour; ctx.stroke();
    }
    ctx.beginPath(); // headings
    for (let i = 0; i < n; i++) {
      const a = heading[i] * Math.PI / 180;
      ctx.moveTo(x[i], y[i]); ctx.lineTo(x[i] + Math.cos(a) * r, y[i] + Math.sin(a) * r);
    }
    ctx.lineWidth = Math.max(r * 0.25, px); ctx.strokeStyle = COLOUR.heading; ctx.stroke();
    ctx.beginPath(); // a carried item: a dark dot
    for (let i = 0; i < n; i++) {
      if (!(flags[i] & FLAG.carrying)) continue;
      ctx.moveTo(x[i] + r * 0.3, y[i]); ctx.arc(x[i], y[i], r * 0.3, 0, 2 * Math.PI);
    }
    ctx.fillStyle = "#222"; ctx.fill();
    V.contacts = drawContacts(s, x, y, r, px);
    V.offCanonical = s.chain ? drawBranches(s, f.c, r, px) : 0;
    V.robotsDrawn = n;
    if (V.selected !== null) drawSelected(V.selected, px, r);
    return true;
  }

  /** Obstacles (docs/terrain.md): rectangles and circles filled, segments as walls. */
  function firstOfKind(s, k) { return s.sites.findIndex((o) => o.name === s.sites[k].name) === k; }

  function drawObstacles(s, px) {
    const obstacles = s.obstacles || [];
    if (!obstacles.length) return;
    ctx.fillStyle = COLOUR.obstacle; ctx.strokeStyle = COLOUR.obstacle;
    for (const o of obstacles) {
      if (o.shape === "rect") ctx.fillRect(o.x0, o.y0, o.x1 - o.x0, o.y1 - o.y0);
      else if (o.shape === "circle") { ctx.beginPath(); ctx.arc(o.x, o.y, o.radius, 0, 2 * Math.PI); ctx.fill(); }
      else {
        ctx.beginPath(); ctx.moveTo(o.x0, o.y0); ctx.lineTo(o.x1, o.y1);
        ctx.lineWidth = Math.max(4, 3 * px); ctx.lineCap = "round"; ctx.stroke(); ctx.lineCap = "butt";
      }
    }
  }

  /** With collisions on: robots whose discs touch another's (within a tenth of a unit) get a dark ring. */
  function drawContacts(s, x, y, r, px) {
    if (!s.robot.collisions || s.n > 3000) return 0;
    const d = 2 * s.robot.radius + 0.1, d2 = d * d;
    const touching = new Uint8Array(s.n);
    for (let i = 0; i < s.n; i++) for (let j = i + 1; j < s.n; j++) {
      const dx = x[i] - x[j], dy = y[i] - y[j];
      if (dx * dx + dy * dy <= d2) { touching[i] = 1; touching[j] = 1; }
    }
    let count = 0;
    ctx.beginPath();
    for (let i = 0; i < s.n; i++) if (touching[i]) { count++; ctx.moveTo(x[i] + r + 1.5 * px, y[i]); ctx.arc(x[i], y[i], r + 1.5 * px, 0, 2 * Math.PI); }
    ctx.lineWidth = 1.5 * px; ctx.strokeStyle = COLOUR.contact; ctx.stroke();
    return count;
  }

  /** The chain model: a ring around each robot whose head is off the canonical branch, coloured by branch. */
  function drawBranches(s, c, r, px) {
    const { x, y, branch } = c;
    let count = 0;
    const groups = new Map();
    for (let i = 0; i < s.n; i++) {
      if (!branch[i]) continue;
      count++;
      if (!groups.has(branch[i])) groups.set(branch[i], []);
      groups.get(branch[i]).push(i);
    }
    ctx.lineWidth = 2 * px;
    for (const [b, members] of groups) {
      ctx.beginPath();
      for (const i of members) { ctx.moveTo(x[i] + r + 3 * px, y[i]); ctx.arc(x[i], y[i], r + 3 * px, 0, 2 * Math.PI); }
      ctx.setLineDash(b === DROPPED ? [2 * px, 2 * px] : []);
      ctx.strokeStyle = b === DROPPED ? COLOUR.none : BRANCH[(b - 1) % BRANCH.length];
      ctx.stroke();
    }
    ctx.setLineDash([]);
    return count;
  }

  function drawSelected(i, px, r) {
    const s = V.scene, c = V.frame.c;
    ctx.beginPath(); ctx.arc(c.x[i], c.y[i], r + 4 * px, 0, 2 * Math.PI);
    ctx.lineWidth = 2 * px; ctx.strokeStyle = "#000"; ctx.stroke();
    s.sites.forEach((site, k) => {
      // the true site: thin dashed grey arrow; where the robot believes it is: solid arrow in its colour
      arrow(c.x[i], c.y[i], site.x, site.y, "rgba(80,80,80,0.55)", true, 1 / px);
      const valid = c.flags[i] & (site.name === "food" ? FLAG.foodValid : FLAG.nestValid);
      if (!valid || !firstOfKind(s, k)) return; // one table entry per kind
      const bx = c[`${site.name}_x`][i], by = c[`${site.name}_y`][i];
      arrow(c.x[i], c.y[i], bx, by, COLOUR[site.name], false, 1 / px);
      ctx.beginPath(); ctx.arc(bx, by, 5 * px, 0, 2 * Math.PI); ctx.lineWidth = 2 * px; ctx.strokeStyle = "#000"; ctx.stroke();
    });
    if (V.detail && V.detail.id === i) {
      for (const p of V.detail.pending) {
        ctx.beginPath(); ctx.arc(p.x, p.y, 4 * px, 0, 2 * Math.PI);
        ctx.setLineDash([3 * px, 3 * px]); ctx.lineWidth = 1.5 * px; ctx.strokeStyle = COLOUR[p.site]; ctx.stroke(); ctx.setLineDash([]);
      }
    }
  }

  function robotAt(cssX, cssY) {
    if (!V.frame || !V.view) return null;
    const wx = cssX / V.view.scale, wy = cssY / V.view.scale;
    const reach = Math.max(V.scene.robot.radius * 1.6, 8 / V.view.scale);
    let best = null, bestD = reach;
    const { x, y } = V.frame.c;
    for (let i = 0; i < V.scene.n; i++) {
      const d = Math.hypot(x[i] - wx, y[i] - wy);
      if (d <= bestD) { best = i; bestD = d; }
    }
    return best;
  }

  // ------------------------------------------------------------------------------------ charts
  function drawChart(canvas, xs, series, ref) {
    const dpr = window.devicePixelRatio || 1, w = canvas.clientWidth, h = canvas.clientHeight;
    if (canvas.width !== Math.round(w * dpr) || canvas.height !== Math.round(h * dpr)) {
      canvas.width = Math.round(w * dpr); canvas.height = Math.round(h * dpr);
    }
    const g = canvas.getContext("2d");
    g.setTransform(dpr, 0, 0, dpr, 0, 0);
    g.clearRect(0, 0, w, h);
    const m = { l: 40, r: 10, t: 8, b: 18 };
    const x0 = xs.length ? xs[0] : 0, x1 = Math.max(xs.length ? xs[xs.length - 1] : 1, x0 + 1);
    let ymax = ref ? ref * 1.5 : 0;
    for (const sr of series) for (const v of sr.values) if (v > ymax) ymax = v;
    ymax = ymax > 0 ? ymax * 1.08 : 1;
    const X = (v) => m.l + (v - x0) / (x1 - x0) * (w - m.l - m.r);
    const Y = (v) => h - m.b - v / ymax * (h - m.t - m.b);
    g.strokeStyle = "#999"; g.lineWidth = 1;
    g.beginPath(); g.moveTo(m.l, m.t); g.lineTo(m.l, h - m.b); g.lineTo(w - m.r, h - m.b); g.stroke();
    g.fillStyle = "#555"; g.font = "11px system-ui, sans-serif";
    g.textAlign = "right"; g.fillText(ymax.toPrecision(3), m.l - 3, m.t + 9); g.fillText("0", m.l - 3, h - m.b);
    g.textAlign = "left"; g.fillText(`${Math.round(x0)}`, m.l, h - 4);
    g.textAlign = "right"; g.fillText(`step ${Math.round(x1)}`, w - m.r, h - 4);
    if (ref) {
      g.setLineDash([4, 4]); g.strokeStyle = "#888";
      g.beginPath(); g.moveTo(m.l, Y(ref)); g.lineTo(w - m.r, Y(ref)); g.stroke(); g.setLineDash([]);
    }
    for (const sr of series) {
      g.strokeStyle = sr.colour; g.lineWidth = 1.8; g.beginPath();
      let pen = false;
      sr.values.forEach((v, k) => {
        if (!Number.isFinite(v)) { pen = false; return; }
        if (pen) g.lineTo(X(xs[k]), Y(v)); else { g.moveTo(X(xs[k]), Y(v)); pen = true; }
      });
      g.stroke();
    }
  }

  function drawCharts() {
    const h = V.history, f = V.frame;
    if (!h || !f) return;
    let end = 0, hi = h.step.length; // points up to the frame shown (a replay holds the whole run)
    while (end < hi) { const mid = (end + hi) >> 1; if (h.step[mid] <= f.step) end = mid + 1; else hi = mid; }
    const cut = (a) => a.slice(0, end);
    const xs = cut(h.step);
    const series = (a, b) => [{ values: cut(a), colour: COLOUR.honest }]
      .concat(V.groups.byzantine ? [{ values: cut(b), colour: COLOUR.byzantine }] : []);
    drawChart($("chart-items"), xs, series(h.itemsH, h.itemsB), 0);
    drawChart($("chart-wealth"), xs, series(h.shareH, h.shareB), 100 / V.scene.n);
    const hd = f.header, total = hd.items_honest + hd.items_byzantine;
    const byz = V.groups.byzantine;
    $("cap-items").textContent = `items collected per robot — total ${total}` +
      (byz ? ` (honest ${hd.items_honest}, Byzantine ${hd.items_byzantine})` : "");
    const wsum = hd.wealth_honest + hd.wealth_byzantine;
    const pct = (v) => (wsum > 0 ? (100 * v / wsum).toFixed(1) : "0.0");
    $("cap-wealth").textContent = `wealth share per robot, % (dashed: equal share) — groups: honest ${pct(hd.wealth_honest)} %` +
      (byz ? `, Byzantine ${pct(hd.wealth_byzantine)} %` : "");
    if (V.scene.chain) {
      let off = 0, branches = new Set();
      for (let i = 0; i < V.scene.n; i++) if (f.c.branch[i]) { off++; if (f.c.branch[i] !== DROPPED) branches.add(f.c.branch[i]); }
      $("chain-status").textContent = `chain: canonical height ${hd.chain_height}, ${hd.chain_forks} forks, ` +
        `${hd.chain_reorgs} reorganisations so far; ${off} robot${off === 1 ? "" : "s"} off the canonical branch` +
        (branches.size ? ` (${branches.size} other branch${branches.size === 1 ? "" : "es"})` : "");
    }
  }

  // what viewer.js uses
  return {
    $, DROPPED, FLAG, V, arena, decodeFrame, drawArena, drawCharts,
    esc, firstOfKind, fit, pushHistory, robotAt, setScene, showFrame,
  };
})();
