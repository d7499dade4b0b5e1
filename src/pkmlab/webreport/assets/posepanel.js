/* pkmlab pose panel: jog a mechanism in the page. The inverse kinematics, leg status and κ are
   computed here from the legs pkmlab declares (pkmlab.webreport.posepanel: leg kinds distance,
   rail, crank and pair; hinge planes for dependent coordinates), never from precomputed values.
   window.pkmlabPose.solve(model, pose6) is what the browser test checks against pkmlab. */
(function () {
  "use strict";
  var STATUS = ["ok", "out of stroke", "joint limit", "unreachable"];
  var COLOUR = ["#0072B2", "#D55E00", "#CC79A7", "#000000"];
  var LABEL = {x: "x", y: "y", z: "z", theta_x: "θx", theta_y: "θy", theta_z: "θz"};
  var POSE = ["x", "y", "z", "theta_x", "theta_y", "theta_z"];
  var SINGULAR_RTOL = 1e-12;

  function dot(a, b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
  function sub(a, b) { return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]; }
  function add(a, b) { return [a[0] + b[0], a[1] + b[1], a[2] + b[2]]; }
  function scl(a, s) { return [a[0] * s, a[1] * s, a[2] * s]; }
  function cross(a, b) {
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  }
  function mv(R, v) {
    return [R[0][0] * v[0] + R[0][1] * v[1] + R[0][2] * v[2],
            R[1][0] * v[0] + R[1][1] * v[1] + R[1][2] * v[2],
            R[2][0] * v[0] + R[2][1] * v[1] + R[2][2] * v[2]];
  }
  /* Z-Y-X Euler angles (θx, θy, θz) → R = Rz·Ry·Rx (pkmlab.poses.euler_to_matrix) */
  function euler(tx, ty, tz) {
    var cx = Math.cos(tx), cy = Math.cos(ty), cz = Math.cos(tz);
    var sx = Math.sin(tx), sy = Math.sin(ty), sz = Math.sin(tz);
    return [[cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx],
            [sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx],
            [-sy, cy * sx, cy * cx]];
  }
  function stroke(q, m) { return q < m.stroke[0] || q > m.stroke[1] ? 1 : 0; }
  function wrap(q, m) {
    var lo = m.stroke[0], hi = m.stroke[1], c = 0;
    if (lo < -Math.PI || hi > Math.PI) { c = 0.5 * (lo + hi); }
    var d = q - c;
    d = d - 2 * Math.PI * Math.ceil((d - Math.PI) / (2 * Math.PI));
    return c + d;
  }

  /* the dependent x, y, θz from three hinge planes n_i·(p + Rz(γ)·M·t_i − Z_i) = 0 */
  function dependent(m, X) {
    var M = euler(X[3], X[4], 0), rows = [];
    m.legs.forEach(function (leg) {
      if (!leg.plane) { return; }
      var n = leg.plane, w = mv(M, sub(leg.platform, m.tool_offset));
      rows.push({nx: n[0], ny: n[1], A: n[0] * w[0] + n[1] * w[1], B: n[1] * w[0] - n[0] * w[1],
                 h: dot(n, leg.zero) - n[2] * (X[2] + w[2])});
    });
    var c1 = [rows[0].nx, rows[1].nx, rows[2].nx], c2 = [rows[0].ny, rows[1].ny, rows[2].ny];
    var k = cross(c1, c2);
    var a = k[0] * rows[0].A + k[1] * rows[1].A + k[2] * rows[2].A;
    var b = k[0] * rows[0].B + k[1] * rows[1].B + k[2] * rows[2].B;
    var e = k[0] * rows[0].h + k[1] * rows[1].h + k[2] * rows[2].h;
    var rho = Math.sqrt(a * a + b * b), ce = e / rho;
    if (!(Math.abs(ce) <= 1)) { return null; }
    var se = Math.sqrt(1 - ce * ce), g0 = m.nominal[5];
    var C = [(a * ce - b * se) / rho, (a * ce + b * se) / rho];
    var S = [(b * ce + a * se) / rho, (b * ce - a * se) / rho];
    var pick = C[0] * Math.cos(g0) + S[0] * Math.sin(g0) >= C[1] * Math.cos(g0) + S[1] * Math.sin(g0) ? 0 : 1;
    var cg = C[pick], sg = S[pick];
    var r = rows.map(function (w) { return w.h - cg * w.A - sg * w.B; });
    var n11 = dot(c1, c1), n12 = dot(c1, c2), n22 = dot(c2, c2);
    var b1 = dot(c1, r), b2 = dot(c2, r), det = n11 * n22 - n12 * n12;
    return [(n22 * b1 - n12 * b2) / det, (n11 * b2 - n12 * b1) / det, Math.atan2(sg, cg)];
  }

  /* a strut of a pair sharing its upper link (posepanel._pair_model): t = ±k×(c×(W−A1))/|…|
     with t·c ≥ 0 (c = A2 − A1), B = W + offset·t, q = |B − A|; the row is ∂q/∂(v, ω):
     dq = e·dW + e·dt·offset, dt = (I − ttᵀ)·dn·sgn/|n|, dn = dk×w + k×(c×dW), dk = ω×k,
     dW = v + ω×r, so with g = offset·sgn/|n|·(I − ttᵀ)e and h = e + (g×k)×c the row is
     [h, r×h + k×(w×g)] */
  function pair(m, L, W, r, R) {
    var k = mv(R, L.normal), c = sub(L.a2, L.a1), d = sub(W, L.a1);
    var w = cross(c, d), n = cross(k, w), nn = Math.sqrt(dot(n, n));
    if (!(nn > 1e-12 * Math.sqrt(dot(c, c)) * Math.sqrt(dot(d, d)))) {
      return {q: NaN, status: 3, why: "link plane undefined", E: null, row: null};
    }
    var sg = dot(n, c) >= 0 ? 1 : -1, t = scl(n, sg / nn);
    var B = add(W, scl(t, L.offset)), e = sub(B, L.base), q = Math.sqrt(dot(e, e));
    var st = 0, why = "";
    if (sg * L.branch <= 0) { st = 3; why = "other working mode"; }
    if (!st && stroke(q, m)) { st = 1; why = q < m.stroke[0] ? "below stroke" : "above stroke"; }
    var eu = scl(e, 1 / q), g = scl(sub(eu, scl(t, dot(t, eu))), L.offset * sg / nn);
    var h = add(eu, cross(cross(g, k), c));
    return {q: q, status: st, why: why, E: B, row: h.concat(add(cross(r, h), cross(k, cross(w, g))))};
  }

  /* one leg at platform joint W: {q, status, why, E (intermediate joint), row (6)} */
  function leg(m, L, W, r, R) {
    var q, st = 0, why = "", E = null, Lv, dE, h2;
    if (L.kind === "pair") { return pair(m, L, W, r, R); }
    if (L.kind === "distance") {
      var d = sub(W, L.base);
      q = Math.sqrt(dot(d, d));
      Lv = d;
      if (q < 1e-12) { return {q: q, status: 3, why: "degenerate", E: null, row: null}; }
      if (L.side && d[2] * L.side <= 0) { st = 3; why = "other working mode"; }
      var u = scl(d, 1 / q);
      var rowd = u.concat(cross(r, u));
      if (!st && stroke(q, m)) { st = 1; why = q < m.stroke[0] ? "below stroke" : "above stroke"; }
      return {q: q, status: st, why: why, E: null, row: rowd};
    }
    if (L.kind === "rail") {
      var dd = sub(W, L.zero), t = dot(dd, L.axis);
      h2 = L.link * L.link - dot(dd, dd) + t * t;
      if (!(h2 >= 0)) { return {q: NaN, status: 3, why: "no real solution", E: null, row: null}; }
      q = t + L.branch * Math.sqrt(h2);
      E = add(L.zero, scl(L.axis, q));
      Lv = sub(W, E);
      dE = L.axis;
      if (L.side && Lv[2] * L.side < 0) { st = 3; why = "other working mode"; }
      if (!st && stroke(q, m)) { st = 1; why = q < m.stroke[0] ? "below stroke" : "above stroke"; }
      if (!st && L.limit) {
        var perp = sub(dd, scl(L.axis, t));
        if (dot(perp, perp) > L.limit.bound * L.limit.bound) { st = 2; why = "rod angle limit"; }
      }
    } else {
      var D = sub(W, L.pivot), v = cross(L.axis, L.ref);
      var A = dot(D, L.ref), B = dot(D, v), K = (dot(D, D) + L.crank * L.crank - L.link * L.link) / (2 * L.crank);
      var rho2 = A * A + B * B;
      h2 = rho2 - K * K;
      if (!(h2 >= 0) || rho2 <= 1e-24 * Math.pow(L.crank, 4)) {
        return {q: NaN, status: 3, why: h2 >= 0 ? "degenerate" : "no real solution", E: null, row: null};
      }
      var h = Math.sqrt(h2);
      q = wrap(Math.atan2(B * K + L.branch * A * h, A * K - L.branch * B * h), m);
      var c = Math.cos(q), s = Math.sin(q);
      E = add(L.pivot, add(scl(L.ref, L.crank * c), scl(v, L.crank * s)));
      Lv = sub(W, E);
      dE = add(scl(L.ref, -L.crank * s), scl(v, L.crank * c));
      if (stroke(q, m)) { st = 1; why = q < m.stroke[0] ? "below stroke" : "above stroke"; }
      if (!st && L.limit && Math.abs(dot(D, L.axis)) > L.limit.bound) { st = 2; why = "ball-joint cone"; }
    }
    var den = dot(Lv, dE);
    var row = scl(Lv, 1 / den).concat(scl(cross(r, Lv), 1 / den));
    return {q: q, status: st, why: why, E: E, row: row};
  }

  function solveLinear(A, B) {          /* A (n×n) X = B (n×k), Gaussian elimination */
    var n = A.length, M = A.map(function (r, i) { return r.concat(B[i]); });
    for (var c = 0; c < n; c++) {
      var p = c;
      for (var i = c + 1; i < n; i++) { if (Math.abs(M[i][c]) > Math.abs(M[p][c])) { p = i; } }
      var tmp = M[c]; M[c] = M[p]; M[p] = tmp;
      for (i = 0; i < n; i++) {
        if (i === c) { continue; }
        var f = M[i][c] / M[c][c];
        for (var j = c; j < M[i].length; j++) { M[i][j] -= f * M[c][j]; }
      }
    }
    return M.map(function (r, i) { return r.slice(n).map(function (x) { return x / M[i][i]; }); });
  }

  /* singular values of J (m×n, m ≥ n) by one-sided Jacobi rotations, descending */
  function singularValues(J) {
    var m = J.length, n = J[0].length, U = J.map(function (r) { return r.slice(); });
    for (var sweep = 0; sweep < 60; sweep++) {
      var off = 0;
      for (var j = 0; j < n - 1; j++) {
        for (var k = j + 1; k < n; k++) {
          var a = 0, b = 0, g = 0;
          for (var i = 0; i < m; i++) { a += U[i][j] * U[i][j]; b += U[i][k] * U[i][k]; g += U[i][j] * U[i][k]; }
          if (Math.abs(g) <= 1e-17 * Math.sqrt(a * b) || g === 0) { continue; }
          off = Math.max(off, Math.abs(g) / Math.sqrt(a * b));
          var z = (b - a) / (2 * g), t = (z >= 0 ? 1 : -1) / (Math.abs(z) + Math.sqrt(1 + z * z));
          var c = 1 / Math.sqrt(1 + t * t), s = c * t;
          for (i = 0; i < m; i++) {
            var x = U[i][j], y = U[i][k];
            U[i][j] = c * x - s * y;
            U[i][k] = s * x + c * y;
          }
        }
      }
      if (off <= 1e-16) { break; }
    }
    var sv = [];
    for (var q = 0; q < n; q++) {
      var sum = 0;
      for (var p = 0; p < m; p++) { sum += U[p][q] * U[p][q]; }
      sv.push(Math.sqrt(sum));
    }
    return sv.sort(function (u, v) { return v - u; });
  }

  /* κ as pkmlab.dexterity.metrics.condition_number: σmax/σmin of J with its rotational
     columns divided by the characteristic length; inf when undefined or singular */
  function kappa(m, J) {
    if (!J.every(function (r) { return r.every(isFinite); })) { return Infinity; }
    var H = J.map(function (r) {
      return r.map(function (x, c) { return m.rotational.indexOf(c) >= 0 ? x / m.char_length : x; });
    });
    var s = singularValues(H), smax = s[0], smin = s[s.length - 1];
    return isFinite(smax) && smin > SINGULAR_RTOL * smax ? smax / smin : Infinity;
  }

  function solve(m, X6) {
    var X = X6.slice();
    if (m.dependent.length) {
      var dep = dependent(m, X);
      if (dep === null) {
        return {pose: X, q: m.legs.map(function () { return NaN; }), status: m.legs.map(function () { return 3; }),
                why: m.legs.map(function () { return "no parasitic solution"; }), kappa: Infinity, points: [], W: []};
      }
      X[0] = dep[0]; X[1] = dep[1]; X[5] = dep[2];
    }
    var R = euler(X[3], X[4], X[5]), p = [X[0], X[1], X[2]];
    var out = {pose: X, q: [], status: [], why: [], points: [], W: []}, rows = [], cons = [];
    m.legs.forEach(function (L) {
      var r = mv(R, sub(L.platform, m.tool_offset)), W = add(p, r);
      var s = leg(m, L, W, r, R);
      out.q.push(s.q);
      out.status.push(s.status);
      out.why.push(s.why);
      out.W.push(W);
      var start = L.kind === "distance" || L.kind === "pair" ? L.base : (L.kind === "rail" ? L.zero : L.pivot);
      out.points.push(s.E ? [start, s.E, W] : [start, W]);
      rows.push(s.row || [NaN, NaN, NaN, NaN, NaN, NaN]);
      if (L.plane) { cons.push(L.plane.concat(cross(r, L.plane))); }
    });
    var J;
    if (m.dependent.length) {
      var D = m.dependent.map(function (c) { return POSE.indexOf(c); });
      var Cd = cons.map(function (r) { return D.map(function (c) { return r[c]; }); });
      var Cf = cons.map(function (r) { return m.free.map(function (c) { return r[c]; }); });
      var S = solveLinear(Cd, Cf);                    /* C_dep⁻¹ C_free */
      J = rows.map(function (r) {
        return m.free.map(function (c, jf) {
          var v = r[c];
          D.forEach(function (cd, k) { v -= r[cd] * S[k][jf]; });
          return v;
        });
      });
    } else {
      J = rows.map(function (r) { return m.free.map(function (c) { return r[c]; }); });
    }
    out.J = J;
    out.kappa = kappa(m, J);
    return out;
  }

  window.pkmlabPose = {solve: solve, singularValues: singularValues, STATUS: STATUS};

  /* ---- the panel ---------------------------------------------------------------------- */
  function deg(v) { return v * 180 / Math.PI; }
  function num(v, d) { return isFinite(v) ? v.toFixed(d) : "—"; }

  function traces(m, res) {
    var groups = STATUS.map(function (name, k) {
      var xs = [], ys = [], zs = [];
      res.points.forEach(function (pts, i) {
        if (res.status[i] !== k) { return; }
        pts.forEach(function (P) { xs.push(P[0]); ys.push(P[1]); zs.push(P[2]); });
        xs.push(null); ys.push(null); zs.push(null);
      });
      return {type: "scatter3d", mode: "lines+markers", x: xs, y: ys, z: zs, name: "legs: " + name,
              line: {color: COLOUR[k], width: 7, dash: k === 3 ? "dot" : "solid"},
              marker: {size: 3, color: COLOUR[k]}, hoverinfo: "name", showlegend: xs.length > 0};
    });
    var ring = res.W.slice();
    if (ring.length > 2) {
      var c = [0, 0];
      ring.forEach(function (w) { c[0] += w[0] / ring.length; c[1] += w[1] / ring.length; });
      ring.sort(function (a, b) { return Math.atan2(a[1] - c[1], a[0] - c[0]) - Math.atan2(b[1] - c[1], b[0] - c[0]); });
      ring.push(ring[0]);
    }
    groups.push({type: "scatter3d", mode: "lines", name: "platform", hoverinfo: "name",
                 x: ring.map(function (w) { return w[0]; }), y: ring.map(function (w) { return w[1]; }),
                 z: ring.map(function (w) { return w[2]; }), line: {color: "#333333", width: 6}});
    groups.push({type: "scatter3d", mode: "markers", name: "tool point", x: [res.pose[0]],
                 y: [res.pose[1]], z: [res.pose[2]], marker: {size: 5, color: "#000000", symbol: "diamond"},
                 hovertemplate: "tool point (%{x:.1f}, %{y:.1f}, %{z:.1f}) mm<extra></extra>"});
    return groups;
  }

  function init(panel) {
    var m = JSON.parse(document.getElementById(panel.dataset.posePanel).textContent);
    var sliders = panel.querySelector(".pose-sliders"), body = panel.querySelector(".pose-legs tbody");
    var info = panel.querySelector(".pose-info"), view = panel.querySelector(".pose-view");
    if (!m.supported) {
      info.textContent = "Not available for this mechanism: " + m.reason + ".";
      sliders.hidden = true;
      return;
    }
    var inputs = [], last = null, rad = m.unit === "rad";
    m.coordinates.forEach(function (c, i) {
      var ang = c.indexOf("theta") === 0, span = ang ? m.range_deg : m.range_mm;
      var row = document.createElement("label");
      row.className = "pose-slider";
      row.innerHTML = "<span></span><input type=range step=0.1><output></output>";
      row.firstChild.textContent = "Δ" + LABEL[c] + " (" + (ang ? "deg" : "mm") + ")";
      var inp = row.querySelector("input");
      inp.min = -span; inp.max = span; inp.value = 0;
      inp.dataset.coordinate = c;
      inp.addEventListener("input", update);
      inputs.push({input: inp, out: row.querySelector("output"), angle: ang, index: m.free[i]});
      sliders.appendChild(row);
    });
    panel.querySelector("[data-pose-reset]").addEventListener("click", function () {
      inputs.forEach(function (s) { s.input.value = 0; });
      update();
    });
    function pose() {
      var X = m.nominal.slice();
      inputs.forEach(function (s) {
        var v = +s.input.value;
        s.out.textContent = v.toFixed(1);
        X[s.index] += s.angle ? v * Math.PI / 180 : v;
      });
      return X;
    }
    function update() {
      var res = solve(m, pose());
      body.textContent = "";
      m.legs.forEach(function (L, i) {
        var tr = document.createElement("tr"), q = res.q[i];
        [L.name, rad ? num(deg(q), 2) + "°" : num(q, 2) + " mm", STATUS[res.status[i]] + (res.why[i] && res.status[i] ? " (" + res.why[i] + ")" : "")]
          .forEach(function (t, k) { var td = document.createElement(k ? "td" : "th"); td.textContent = t; tr.appendChild(td); });
        tr.className = "pose-" + STATUS[res.status[i]].replace(/ /g, "-");
        body.appendChild(tr);
      });
      var bad = res.status.filter(function (s) { return s; }).length;
      var dep = m.dependent.map(function (c) {
        var v = res.pose[POSE.indexOf(c)];
        return LABEL[c] + " = " + (c.indexOf("theta") === 0 ? num(deg(v), 3) + "°" : num(v, 3) + " mm");
      });
      info.textContent = "κ = " + (isFinite(res.kappa) ? res.kappa.toPrecision(4) : "∞ (singular or undefined)") +
        (m.char_length ? " (L = " + m.char_length.toPrecision(4) + " mm, " + m.length_source + ")" : " (κ of J: no rotation)") +
        ". " + (bad ? bad + " of " + m.legs.length + " legs not ok." : "All legs ok.") +
        (dep.length ? " Dependent: " + dep.join(", ") + "." : "");
      panel.dataset.kappa = res.kappa;
      last = res;
      draw();
    }
    function draw() {            /* the 3-D view, once it is on screen (cards start hidden) */
      if (!last || !window.Plotly || !view || !view.getClientRects().length) { return; }
      var data = traces(m, last).concat(m.fixed_traces || []);
      {
        var layout = {margin: {l: 0, r: 0, t: 0, b: 0}, height: 420, showlegend: true,
                      legend: {orientation: "h", x: 0, y: 0}, uirevision: "keep",
                      scene: m.scene || {aspectmode: "data"}};
        Plotly.react(view, data, layout, {displaylogo: false, responsive: true});
        panel.dataset.drawn = "true";
      }
    }
    update();
    if (window.IntersectionObserver && view) {
      new IntersectionObserver(function (es) {
        if (es.some(function (e) { return e.isIntersecting; })) { draw(); }
      }).observe(view);
    }
  }
  document.querySelectorAll("[data-pose-panel]").forEach(init);
})();
