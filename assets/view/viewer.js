// railforce viewer: replays a run from the scene JSON embedded in the page (no network).
// Track axes: x along the running direction, y to the left, z up. Lengths in the scene are
// in mm, forces in kN, yaw and roll in mrad (see src/view/mod.rs).
"use strict";
(function () {
  window.onerror = function (msg) {
    document.body.dataset.status = "error: " + msg;
  };
  const S = JSON.parse(document.getElementById("scene").textContent);
  const N = S.time.length;
  const $ = (id) => document.getElementById(id);
  const slider = $("slider"), play = $("play"), speedSel = $("speed"), clock = $("clock");
  const COL = { ink: "#222", grid: "#ddd", rail: "#8a8f98", wheel: "#c9b27c", truth: "#1f5fbf",
    ident: "#e07b00", band: "rgba(224, 123, 0, 0.18)", limit: "#c62828", contact: "#d81b60", soft: "#666" };
  slider.max = String(N - 1);
  let frame = 0, playing = false, last = null, simTime = S.time[0];

  // Start frame from the address (#frame=K or #t=SECONDS): used by the browser test.
  const hash = new URLSearchParams(location.hash.slice(1));
  if (hash.has("frame")) frame = Math.max(0, Math.min(N - 1, parseInt(hash.get("frame"), 10) || 0));
  if (hash.has("t")) frame = frameAt(parseFloat(hash.get("t")));

  function frameAt(t) {
    let lo = 0, hi = N - 1;
    if (!(t > S.time[0])) return 0;
    if (t >= S.time[hi]) return hi;
    while (hi - lo > 1) { const m = (lo + hi) >> 1; if (S.time[m] <= t) lo = m; else hi = m; }
    return lo;
  }
  function ctx2d(id) {
    const c = $(id), g = c.getContext("2d");
    g.setTransform(1, 0, 0, 1, 0, 0);
    g.clearRect(0, 0, c.width, c.height);
    g.font = "14px system-ui, sans-serif";
    g.lineJoin = "round";
    return [c, g];
  }
  function arrow(g, x0, y0, x1, y1, color, width) {
    const a = Math.atan2(y1 - y0, x1 - x0), L = Math.hypot(x1 - x0, y1 - y0);
    if (!(L > 2)) return;
    g.strokeStyle = g.fillStyle = color; g.lineWidth = width || 3;
    g.beginPath(); g.moveTo(x0, y0); g.lineTo(x1, y1); g.stroke();
    const h = Math.min(12, L / 2);
    g.beginPath(); g.moveTo(x1, y1);
    g.lineTo(x1 - h * Math.cos(a - 0.4), y1 - h * Math.sin(a - 0.4));
    g.lineTo(x1 - h * Math.cos(a + 0.4), y1 - h * Math.sin(a + 0.4));
    g.closePath(); g.fill();
  }
  const fmt = (x, d) => (x === null || x === undefined || !isFinite(x)) ? "—" : (x >= 0 ? "+" : "−") + Math.abs(x).toFixed(d);
  function sectionAt(s) {
    for (const [a, b, text] of S.sections) if (s >= a && s <= b) return text;
    return "beyond the track's sections";
  }

  // ---- cross-section: each wheel on its own rail, true shapes and positions, magnified ----
  function drawCross() {
    const [c, g] = ctx2d("cross");
    const P = S.profiles, hg = P.half_gauge, W = c.width / 2, H = c.height;
    const k = 4.0; // px per mm
    for (let side = 0; side < 2; side++) {
      const s = side === 0 ? 1 : -1, w = S.wheels[side];
      const x0 = side * W, cx = x0 + W / 2, cy = H * 0.5;
      const yc = s * (hg + 22), zc = 0; // view centre, mm (track axes)
      const X = (y) => cx - (y - yc) * k, Y = (z) => cy - (z - zc) * k;
      g.save(); g.beginPath(); g.rect(x0 + 4, 30, W - 8, H - 34); g.clip();
      // rail head from the mounted profile, closed downward, and a sketch of the web
      const rl = P.rail[P.rail.length - 1], r0 = P.rail[0], neck = -38;
      const mid = s * (hg + 0.5 * (r0[0] + rl[0]));
      g.fillStyle = COL.rail; g.strokeStyle = COL.ink; g.lineWidth = 1.5; g.beginPath();
      P.rail.forEach(([ym, z], i) => { const px = X(s * (hg + ym)), py = Y(z); i ? g.lineTo(px, py) : g.moveTo(px, py); });
      g.lineTo(X(s * (hg + rl[0])), Y(neck)); g.lineTo(X(mid + s * 8), Y(neck)); g.lineTo(X(mid + s * 8), H);
      g.lineTo(X(mid - s * 8), H); g.lineTo(X(mid - s * 8), Y(neck)); g.lineTo(X(s * (hg + r0[0])), Y(neck));
      g.closePath(); g.fill(); g.stroke();
      // wheel from its profile at the frame's shift, height and roll
      const y = w.y[frame], h = w.height[frame], phi = w.roll[frame] / 1000;
      const cs = Math.cos(phi), sn = Math.sin(phi);
      const at = ([cw, r]) => { const cc = s * cw; return [y + cc * cs + r * sn, h + cc * sn - r * cs]; };
      g.fillStyle = COL.wheel; g.beginPath();
      P.wheel.forEach((p, i) => { const [py, pz] = at(p); i ? g.lineTo(X(py), Y(pz)) : g.moveTo(X(py), Y(pz)); });
      const top = 80; // close the wheel upward, off the view
      const wl = at(P.wheel[P.wheel.length - 1]), wf = at(P.wheel[0]);
      g.lineTo(X(wl[0]), Y(top)); g.lineTo(X(wf[0]), Y(top)); g.closePath(); g.fill(); g.stroke();
      // contact patches: the rail's normal force on the wheel at each load centre
      const patches = w.patches[frame];
      patches.forEach(([py, pz, n, angle]) => {
        const px = X(y + py), pyy = Y(h + pz), a = angle * Math.PI / 180, L = Math.min(140, n * 0.8);
        arrow(g, px + s * Math.sin(a) * L, pyy + Math.cos(a) * L, px, pyy, COL.contact, 3);
        g.fillStyle = COL.contact; g.beginPath(); g.arc(px, pyy, 3 + Math.sqrt(Math.max(0, n)) * 0.4, 0, 2 * Math.PI); g.fill();
      });
      // the wheel's resultant Y and Q in a small force diagram
      const fx = x0 + 70, fz = 150, fy0 = w.force_y[frame], fq0 = w.force_q[frame];
      g.fillStyle = "rgba(255,255,255,0.7)"; g.fillRect(x0 + 10, 36, 150, 150);
      arrow(g, fx, fz, fx, fz - Math.max(-110, Math.min(110, fq0 * 0.7)), COL.truth, 4);
      arrow(g, fx, fz, fx - Math.max(-60, Math.min(60, fy0 * 1.2)), fz, COL.ident, 4);
      g.fillStyle = COL.truth; g.fillText("Q " + fq0.toFixed(0) + " kN", fx + 6, 52);
      g.fillStyle = COL.ident; g.fillText("Y " + fy0.toFixed(0) + " kN", x0 + 16, fz + 26);
      g.restore();
      g.fillStyle = COL.ink; g.font = "bold 16px system-ui, sans-serif";
      const name = "1" + (side === 0 ? "L" : "R");
      g.fillText(name + (side === 0 ? " (left rail)" : " (right rail)"), x0 + 12, 22);
      g.font = "14px system-ui, sans-serif";
      const q = w.force_q[frame], fy = w.force_y[frame];
      const yq = q > 0 ? Math.abs(fy) / q : NaN;
      const angles = patches.map((p) => p[3].toFixed(0) + "°").join(" + ");
      g.fillText("Y " + fmt(fy, 1) + " kN   Q " + fmt(q, 1) + " kN   |Y|/Q " + (isFinite(yq) ? yq.toFixed(2) : "—"), x0 + 12, H - 30);
      const rail = railAt(side), bent = rail ? "   rail z " + fmt(rail[1], 2) + " mm, y " + fmt(rail[0], 2) + " mm" : "";
      g.fillText("shift " + fmt(y, 1) + " mm   " + (patches.length === 2 ? "two-point contact " : "contact ") + (angles || "none (lifted)") + bent, x0 + 12, H - 10);
      g.strokeStyle = COL.grid; g.beginPath(); g.moveTo(W, 0); g.lineTo(W, H); g.stroke();
    }
    $("cross-note").textContent = "True profile shapes and positions, magnified 4 px/mm (no exaggeration). " +
      "Pink: each contact patch's normal force from the rail (length and dot ∝ load); the inset: the wheel's resultant Q (blue) and Y (orange). " +
      "Wheelset shift is relative to each rail (irregularity and the rail's own deflection removed); roll " + fmt(S.wheels[0].roll[frame], 2) + " mrad.";
  }

  // ---- the whole wheelset, schematic: shift and roll exaggerated so a class can see them ----
  // the rails' deflection under the wheels (compliant track), mm, [left, right]: [y, z] each;
  // drawn at RAIL_SINK px per mm (the schematic's lengths are 0.55 px per mm), clamped
  const RAIL_SINK = 10;
  function railAt(side) {
    const w = S.wheels[side];
    return w.rail_z.length ? [w.rail_y[frame], w.rail_z[frame]] : null;
  }
  const AXLE_SHIFT = 5, AXLE_ROLL = 20;
  function drawAxle() {
    const [c, g] = ctx2d("axle");
    const k = 0.55, cx = c.width / 2, base = 66; // px per mm at the rail tops
    const ws = S.bodies.find((b) => b.kind === "wheelset");
    const y = ws ? ws.y[frame] : 0.5 * (S.wheels[0].y[frame] + S.wheels[1].y[frame]);
    const phi = S.wheels[0].roll[frame] / 1000 * AXLE_ROLL;
    const hg = S.profiles.half_gauge, r = 22; // wheel drawn 44 px high
    const rails = [railAt(0), railAt(1)];
    // each rail where its deflection puts it: down ×RAIL_SINK, across ×AXLE_SHIFT (as the wheelset)
    const sink = (i) => (rails[i] ? Math.max(-12, Math.min(16, -rails[i][1] * RAIL_SINK)) : 0);
    g.fillStyle = COL.rail;
    [1, -1].forEach((s, i) => {
      const dy = rails[i] ? rails[i][0] * AXLE_SHIFT * k : 0;
      g.fillRect(cx - (s * (hg + 35)) * k - 36 * k - dy, base + sink(i), 72 * k, 14);
    });
    g.strokeStyle = COL.grid; g.setLineDash([4, 4]); g.beginPath(); g.moveTo(cx, 4); g.lineTo(cx, c.height - 4); g.stroke(); g.setLineDash([]);
    g.save(); g.translate(cx - y * AXLE_SHIFT * k, base - r + 0.5 * (sink(0) + sink(1))); g.rotate(phi);
    g.strokeStyle = COL.ink; g.lineWidth = 5; g.beginPath(); g.moveTo(-(hg + 70) * k, 0); g.lineTo((hg + 70) * k, 0); g.stroke();
    g.fillStyle = COL.wheel; g.strokeStyle = COL.ink; g.lineWidth = 1.5;
    for (const s of [1, -1]) { const xw = -s * (hg + 35) * k; g.fillRect(xw - 40 * k, -r, 80 * k, 2 * r); g.strokeRect(xw - 40 * k, -r, 80 * k, 2 * r); }
    g.restore();
    g.fillStyle = COL.ink; g.font = "13px system-ui, sans-serif";
    g.fillText("whole wheelset, schematic: shift ×" + AXLE_SHIFT + " (" + fmt(y, 1) + " mm from the track centre), roll ×" + AXLE_ROLL + " (" + fmt(S.wheels[0].roll[frame], 2) + " mrad)", 8, 16);
    g.fillText("left", 8, base + 12); g.fillText("right", c.width - 40, base + 12);
    g.fillText(rails[0] ? "rails under the wheels, " + RAIL_SINK + " px/mm down: left " + fmt(rails[0][1], 2) + " mm, right " + fmt(rails[1][1], 2) +
      " mm vertical; " + fmt(rails[0][0], 2) + " / " + fmt(rails[1][0], 2) + " mm lateral" : "rail deflection not recorded (a run from before it was a channel)", 200, c.height - 4);
  }

  // ---- plan view: track map above, the wagon in the track's (unrolled) frame below ----
  function drawPlan() {
    const [c, g] = ctx2d("plan");
    const Wd = c.width, mapH = 120;
    // track map, true shape
    let xs = S.map.map((p) => p[1]), ys = S.map.map((p) => p[2]);
    const [x0, x1, y0, y1] = [Math.min(...xs), Math.max(...xs), Math.min(...ys), Math.max(...ys)];
    const sc = Math.min(260 / Math.max(1, x1 - x0), (mapH - 30) / Math.max(1, y1 - y0));
    const mx = (x) => 20 + (x - x0) * sc, my = (y) => mapH - 8 - (y - y0) * sc;
    g.strokeStyle = COL.grid; g.lineWidth = 1; g.strokeRect(8, 24, 284, mapH - 26);
    g.strokeStyle = COL.rail; g.lineWidth = 4; g.beginPath();
    S.map.forEach((p, i) => i ? g.lineTo(mx(p[1]), my(p[2])) : g.moveTo(mx(p[1]), my(p[2]))); g.stroke();
    const s = S.s[frame];
    let j = 1; while (j < S.map.length - 1 && S.map[j][0] < s) j++;
    const a = S.map[j - 1], b = S.map[j], f = Math.max(0, Math.min(1, (s - a[0]) / Math.max(1e-9, b[0] - a[0])));
    g.fillStyle = COL.contact; g.beginPath(); g.arc(mx(a[1] + f * (b[1] - a[1])), my(a[2] + f * (b[2] - a[2])), 7, 0, 2 * Math.PI); g.fill();
    g.fillStyle = COL.ink;
    g.font = "bold 15px system-ui, sans-serif";
    g.fillText("s = " + s.toFixed(1) + " m of " + S.map[S.map.length - 1][0].toFixed(0) + " m: " + sectionAt(s), 8, 16);
    g.font = "14px system-ui, sans-serif";
    // the wagon, running to the right; left (+y) is up
    const [FL, FY] = S.plan_factors, top = mapH + 4, H = c.height - top, k = (Wd - 40) / 18.0;
    const cx = Wd / 2, cy = top + H / 2;
    const kap = S.curvature[frame] / 1000, mid = FL * kap * 25 / 4; // half the bend at x = ±5 m
    const X = (x) => cx + x * k, Y = (y) => cy - (y - mid) * k;
    // The centre line bends by the curvature at s, with the lateral exaggeration: a body is
    // drawn on it at its x, turned by the drawn slope plus its own yaw (exaggerated apart).
    const yc = (x) => FL * kap * x * x / 2, slope = (x) => Math.atan(FL * kap * x);
    const hgm = S.profiles.half_gauge / 1000;
    const band = (off, color, width, dash) => {
      g.strokeStyle = color; g.lineWidth = width; g.setLineDash(dash); g.beginPath();
      for (let px = 0; px <= Wd; px += 10) { const x = (px - cx) / k; const y = Y(yc(x) + off); px ? g.lineTo(px, y) : g.moveTo(px, y); }
      g.stroke(); g.setLineDash([]);
    };
    band(hgm, COL.rail, 3, []); band(-hgm, COL.rail, 3, []); band(0, COL.grid, 1, [6, 6]);
    const shapes = { carbody: [13.0, 3.1], bolster: [0.35, 2.5], sideframe: [2.3, 0.18], wheelset: [0.12, 1.75], other: [0.3, 0.3] };
    const order = ["carbody", "bolster", "sideframe", "wheelset", "other"];
    for (const kind of order) for (const body of S.bodies.filter((b) => b.kind === kind)) {
      const [L, Wb] = shapes[kind];
      // On the drawn centre line at x, across it by the static place and the exaggerated
      // displacement, then turned by the exaggerated yaw relative to the track.
      const off = body.y0 + body.y[frame] / 1000 * FL, yaw = body.yaw[frame] / 1000 * FY;
      g.save(); g.translate(X(body.x), Y(yc(body.x))); g.rotate(-slope(body.x));
      g.translate(0, -off * k); g.rotate(-yaw);
      g.lineWidth = 2; g.strokeStyle = COL.ink;
      if (kind === "carbody") { g.setLineDash([8, 5]); g.strokeRect(-L / 2 * k, -Wb / 2 * k, L * k, Wb * k); g.setLineDash([]); }
      else if (kind === "wheelset") {
        g.fillStyle = COL.ink; g.fillRect(-L / 2 * k, -Wb / 2 * k, L * k, Wb * k);
        g.fillStyle = COL.wheel;
        for (const r of [1, -1]) g.fillRect(-0.42 * k, (r * 0.75 - 0.07) * k, 0.84 * k, 0.14 * k);
      } else { g.fillStyle = kind === "bolster" ? "rgba(80,120,200,0.35)" : "rgba(60,60,60,0.25)"; g.fillRect(-L / 2 * k, -Wb / 2 * k, L * k, Wb * k); g.strokeRect(-L / 2 * k, -Wb / 2 * k, L * k, Wb * k); }
      g.restore();
      if (kind === "wheelset") {
        g.fillStyle = COL.ink; g.font = "13px system-ui, sans-serif";
        g.fillText("ψ " + fmt(body.yaw[frame], 1), X(body.x) - 24, Y(yc(body.x) - 1.25));
        g.fillText("y " + fmt(body.y[frame], 1), X(body.x) - 24, Y(yc(body.x) - 1.45));
      }
    }
    // A run in a train: each coupler from the carbody's end towards its neighbour, turned by
    // the carbody's yaw and its own angle to the carbody (both exaggerated as the yaw), red in
    // tension, blue in compression, thicker with the force; the neighbours' ends beyond.
    const C = S.couplers, cb = S.bodies.find((b) => b.kind === "carbody");
    if (C && cb) {
      const half = shapes.carbody[0] / 2, len = 1.6;
      for (const [i, dir] of [[0, 1], [1, -1]]) {
        const F = C.force[i][frame], psi = C.yaw[i][frame] / 1000 * FY;
        const off = cb.y0 + cb.y[frame] / 1000 * FL, yaw = cb.yaw[frame] / 1000 * FY;
        const x = cb.x + dir * half;
        g.save(); g.translate(X(x), Y(yc(x))); g.rotate(-slope(x)); g.translate(0, -off * k); g.rotate(-yaw);
        g.strokeStyle = F >= 0 ? COL.limit : COL.truth;
        g.lineWidth = 2 + 6 * Math.min(1, Math.abs(F) / C.limit_kn);
        g.beginPath(); g.moveTo(0, 0); g.lineTo(dir * len * k * Math.cos(psi), -len * k * Math.sin(dir * psi)); g.stroke();
        g.restore();
        g.fillStyle = F >= 0 ? COL.limit : COL.truth; g.font = "bold 14px system-ui, sans-serif";
        g.textAlign = dir > 0 ? "right" : "left";
        g.fillText((i ? "rear coupler: " : "front coupler: ") + (F >= 0 ? "tension " : "compression ") + Math.abs(F).toFixed(0) + " kN, angle " + fmt(C.yaw[i][frame], 1) + " mrad",
          dir > 0 ? Wd - 10 : 10, top + 20);
        g.textAlign = "left";
      }
    }
    g.fillStyle = COL.ink; g.font = "14px system-ui, sans-serif";
    g.fillText("running direction →", Wd - 170, c.height - 8);
    g.fillText("left rail", 8, Y(yc(-cx / k) + hgm) - 6);
    g.fillText("right rail", 8, Y(yc(-cx / k) - hgm) + 18);
    $("plan-note").textContent = "Lateral displacement from each body's static place over the track centre line drawn ×" + FL +
      " and yaw relative to the track (the angle of attack of a wheelset) ×" + FY +
      "; lengths along the track at true scale; the rails bend with the track's curvature at the wagon centre, drawn with the same lateral exaggeration. " +
      "Under each wheelset: yaw ψ in mrad and lateral shift y in mm.";
  }

  // ---- traces of the label wheel with the cursor ----
  // The traces are drawn once into an off-screen canvas; each frame copies it and adds the
  // cursor and the values (smooth playback of long runs on a modest laptop).
  let traceCache = null;
  function traceLayout(c) {
    const left = 70, right = c.width - 15, ph = (c.height - 40) / 3, t0 = S.time[0], t1 = S.time[N - 1];
    const X = (t) => left + (t - t0) / Math.max(1e-9, t1 - t0) * (right - left);
    return { left, right, ph, t0, t1, X };
  }
  function tracePlots() {
    const T = S.traces, I = S.identified, Lm = S.limits;
    return [
      { name: "Y (kN)", t: T.y, i: I && I.y, b: I && I.band && I.band.y, lim: [] },
      { name: "Q (kN)", t: T.q, i: I && I.q, b: I && I.band && I.band.q, lim: [[Lm.q_min, "Q min (unloading " + Lm.q_min.toFixed(0) + " kN)"], [Lm.q_static, "static Q̄"]] },
      { name: "|Y|/Q", t: T.y_over_q, i: I && I.y_over_q, lim: [[Lm.y_over_q, "limit " + Lm.y_over_q]] },
    ];
  }
  function drawTraceLines(c) {
    const off = document.createElement("canvas");
    off.width = c.width; off.height = c.height;
    const g = off.getContext("2d");
    g.font = "14px system-ui, sans-serif";
    const { left, right, ph, t0, t1, X } = traceLayout(c);
    tracePlots().forEach((p, k) => {
      const top = 10 + k * ph, bot = top + ph - 22;
      const vals = p.t.concat(p.i || [], p.b ? p.b[0].concat(p.b[1]) : [], p.lim.map((l) => l[0])).filter((v) => v !== null && isFinite(v));
      let lo = Math.min(...vals), hi = Math.max(...vals);
      if (!(hi > lo)) { lo -= 1; hi += 1; }
      const pad = 0.08 * (hi - lo); lo -= pad; hi += pad;
      const Y = (v) => bot - (v - lo) / (hi - lo) * (bot - top);
      g.strokeStyle = COL.grid; g.lineWidth = 1; g.strokeRect(left, top, right - left, bot - top);
      g.fillStyle = COL.ink; g.fillText(p.name, 6, top + 14);
      g.fillStyle = COL.soft; g.fillText(hi.toFixed(hi - lo > 10 ? 0 : 2), 6, top + 32); g.fillText(lo.toFixed(hi - lo > 10 ? 0 : 2), 6, bot);
      for (const [v, label] of p.lim) {
        g.strokeStyle = COL.limit; g.setLineDash([6, 4]); g.beginPath(); g.moveTo(left, Y(v)); g.lineTo(right, Y(v)); g.stroke(); g.setLineDash([]);
        g.fillStyle = COL.limit; g.fillText(label, right - 230, Y(v) - 4);
      }
      const line = (arr, color, dash) => {
        g.strokeStyle = color; g.lineWidth = 1.5; g.setLineDash(dash); g.beginPath(); let pen = false;
        arr.forEach((v, j) => { if (v === null || !isFinite(v)) { pen = false; return; } const x = X(S.time[j]), y = Y(v); pen ? g.lineTo(x, y) : g.moveTo(x, y); pen = true; });
        g.stroke(); g.setLineDash([]);
      };
      if (p.b) {
        // The identified force's interval (identify --coverage): a shaded band, drawn first.
        g.fillStyle = COL.band; g.beginPath(); let open = false;
        const close = (j0, j1) => { for (let j = j1; j >= j0; j--) g.lineTo(X(S.time[j]), Y(p.b[0][j])); g.closePath(); g.fill(); g.beginPath(); };
        let start = 0;
        p.b[1].forEach((v, j) => {
          const ok = v !== null && isFinite(v) && p.b[0][j] !== null && isFinite(p.b[0][j]);
          if (ok && !open) { g.moveTo(X(S.time[j]), Y(v)); open = true; start = j; }
          else if (ok) g.lineTo(X(S.time[j]), Y(v));
          else if (open) { close(start, j - 1); open = false; }
        });
        if (open) close(start, p.b[1].length - 1);
      }
      line(p.t, COL.truth, []);
      if (p.i) line(p.i, COL.ident, [5, 3]);
    });
    g.fillStyle = COL.soft; g.fillText(t0.toFixed(1) + " s", left, c.height - 8); g.fillText(t1.toFixed(1) + " s", right - 50, c.height - 8);
    return off;
  }
  function drawTraces() {
    const [c, g] = ctx2d("traces");
    if (!traceCache) traceCache = drawTraceLines(c);
    g.drawImage(traceCache, 0, 0);
    const I = S.identified, Lm = S.limits;
    const { left, ph, X } = traceLayout(c);
    tracePlots().forEach((p, k) => {
      const top = 10 + k * ph;
      const tv = p.t[frame], iv = p.i ? p.i[frame] : null;
      g.fillStyle = COL.truth; g.fillText("true " + fmt(tv, 2), left + 8, top + 16);
      if (p.i) { g.fillStyle = COL.ident; g.fillText("identified " + fmt(iv, 2), left + 120, top + 16); }
    });
    const x = X(S.time[frame]);
    g.strokeStyle = COL.ink; g.lineWidth = 2; g.beginPath(); g.moveTo(x, 6); g.lineTo(x, c.height - 28); g.stroke();
    $("trace-title").textContent = "Forces of the label wheel " + S.label + (I ? ": true (blue) and identified (orange, dashed" + (I.band ? ", its interval shaded" : "") + ")" : ": true");
    $("trace-note").textContent = "Limits: " + Lm.source + "." + (S.identified_source ? " Identified: " + S.identified_source + "." : "");
  }

  function draw() {
    slider.value = String(frame);
    clock.textContent = "t = " + S.time[frame].toFixed(2) + " s   s = " + S.s[frame].toFixed(1) + " m   frame " + (frame + 1) + " / " + N;
    drawAxle(); drawCross(); drawPlan(); drawTraces();
    document.body.dataset.frame = String(frame);
    if (!document.body.dataset.status) document.body.dataset.status = "ok";
  }
  function tick(ts) {
    if (!playing) return;
    if (last !== null) simTime += (ts - last) / 1000 * speed;
    last = ts;
    frame = frameAt(simTime);
    if (frame >= N - 1) { playing = false; play.textContent = "▶ play"; }
    draw();
    if (playing) requestAnimationFrame(tick);
  }
  function toggle() {
    playing = !playing; play.textContent = playing ? "❚❚ pause" : "▶ play";
    if (playing) { if (frame >= N - 1) frame = 0; simTime = S.time[frame]; last = null; requestAnimationFrame(tick); }
  }
  play.addEventListener("click", toggle);
  speedSel.addEventListener("change", () => { speed = parseFloat(speedSel.value); });
  let speed = parseFloat(speedSel.value);
  slider.addEventListener("input", () => { frame = parseInt(slider.value, 10); simTime = S.time[frame]; draw(); });
  document.addEventListener("keydown", (e) => {
    if (e.target && e.target.tagName === "SELECT") return;
    if (e.key === " ") { e.preventDefault(); toggle(); }
    else if (e.key === "ArrowRight") { frame = Math.min(N - 1, frame + 1); draw(); }
    else if (e.key === "ArrowLeft") { frame = Math.max(0, frame - 1); draw(); }
    else if (e.key === "Home") { frame = 0; draw(); }
    else if (e.key === "End") { frame = N - 1; draw(); }
  });
  draw();
  // #check: record how much of each drawing area holds ink (for the browser test; a region
  // left blank reads 0).
  if (hash.has("check")) {
    const ink = (id, x0, y0, x1, y1) => {
      const c = $(id), d = c.getContext("2d").getImageData(0, 0, c.width, c.height).data;
      let n = 0, all = 0;
      for (let y = Math.floor(y0 * c.height); y < y1 * c.height; y += 2)
        for (let x = Math.floor(x0 * c.width); x < x1 * c.width; x += 2) {
          const i = 4 * (y * c.width + x); all++;
          if (d[i + 3] > 0 && (d[i] < 235 || d[i + 1] < 235 || d[i + 2] < 235)) n++;
        }
      return (n / Math.max(1, all)).toFixed(4);
    };
    const regions = { axle: ["axle", 0, 0.25, 1, 1], cross_left: ["cross", 0, 0, 0.5, 1], cross_right: ["cross", 0.5, 0, 1, 1],
      plan_map: ["plan", 0, 0.05, 0.3, 0.24], plan_wagon: ["plan", 0, 0.26, 1, 1],
      trace_y: ["traces", 0.07, 0, 1, 0.33], trace_q: ["traces", 0.07, 0.33, 1, 0.66],
      trace_yq: ["traces", 0.07, 0.66, 1, 0.95] };
    document.body.dataset.ink = Object.entries(regions).map(([k, r]) => k + "=" + ink(...r)).join(",");
  }
})();
