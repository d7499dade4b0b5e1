/* pkmlab report pages: render the embedded plotly figures, open a design card when a Pareto
   point is clicked, switch the colouring of a hull. No network access: plotly.js and every
   figure and number are embedded in the page. */
(function () {
  "use strict";
  var DATA = JSON.parse(document.getElementById("pkmlab-data").textContent);
  var CONFIG = { responsive: true, displaylogo: false, modeBarButtonsToRemove: ["sendDataToCloud"] };

  function figure(id) {
    var node = document.getElementById(id);
    return node ? JSON.parse(node.textContent) : null;
  }

  function draw(divId, figId) {
    var div = document.getElementById(divId), fig = figure(figId);
    if (!div || !fig) { return Promise.resolve(null); }
    return Plotly.newPlot(div, fig.data, fig.layout, CONFIG).then(function () { return div; });
  }

  function text(node, value) { node.textContent = value; return node; }

  function el(tag, content) {
    var node = document.createElement(tag);
    if (content !== undefined) { text(node, content); }
    return node;
  }

  function fmt(v) {
    if (v === null || v === undefined || (typeof v === "number" && !isFinite(v))) { return "—"; }
    if (typeof v !== "number") { return String(v); }
    if (v !== 0 && (Math.abs(v) >= 1e6 || Math.abs(v) < 1e-3)) { return v.toExponential(3); }
    return String(Number(v.toPrecision(4)));
  }

  function diff(v, b) {
    if (typeof v !== "number" || typeof b !== "number" || !isFinite(v) || !isFinite(b)) {
      return ["—", "—"];
    }
    var d = v - b;
    var pct = b === 0 ? "—" : ((d >= 0 ? "+" : "") + (100 * d / Math.abs(b)).toFixed(1) + " %");
    return [d === 0 ? "0" : (d > 0 ? "+" : "") + String(Number(d.toPrecision(4))), pct];
  }

  function row(table, cells, head) {
    var tr = document.createElement("tr");
    cells.forEach(function (c, i) { tr.appendChild(el(head || i === 0 ? "th" : "td", c)); });
    table.appendChild(tr);
  }

  /* ---- design cards ------------------------------------------------------------------ */
  var shownScene = null;

  function showDesign(n, scroll) {
    var card = document.getElementById("design-" + n), drawn = Promise.resolve(null);
    if (!card) { return drawn; }
    document.querySelectorAll("article.design").forEach(function (a) { a.hidden = a !== card; });
    document.querySelectorAll("[data-show-design]").forEach(function (b) {
      b.setAttribute("aria-selected", String(+b.dataset.showDesign === n));
    });
    var cand = document.getElementById("candidate-card");
    if (cand) { cand.hidden = true; }
    if (shownScene !== null && shownScene !== n) {          // one WebGL scene at a time
      var old = document.getElementById("scene-" + shownScene);
      if (old) { Plotly.purge(old); }
    }
    if (shownScene !== n && document.getElementById("scene-" + n)) {
      drawn = draw("scene-" + n, "fig-design-" + n).then(function (div) {
        var sel = document.querySelector("[data-colour-design='" + n + "']");
        if (div && sel && sel.value !== "0") { recolour(n, +sel.value); }
        return div;
      });
    }
    shownScene = n;
    if (scroll) {
      card.scrollIntoView({ behavior: "smooth", block: "start" });
      card.classList.remove("flash");
      void card.offsetWidth;
      card.classList.add("flash");
    }
    return drawn;
  }

  function recolour(n, k) {
    var div = document.getElementById("scene-" + n);
    var options = (DATA.colours || {})[n];
    if (!div || !options || !options[k] || !div.data) { return; }
    var o = options[k];
    Plotly.restyle(div, { intensity: [o.values], cmin: o.cmin, cmax: o.cmax,
                          "colorbar.title.text": o.label }, [0]);
  }

  /* ---- any candidate ----------------------------------------------------------------- */
  function showCandidate(seq) {
    var c = DATA.candidates.find(function (r) { return r.seq === seq; });
    if (!c) { return; }
    if (c.design) { showDesign(c.design, true); return; }
    var card = document.getElementById("candidate-card");
    if (!card) { return; }
    var base = DATA.candidates.find(function (r) { return r.role === "baseline"; });
    text(document.getElementById("candidate-title"),
         c.role === "baseline" ? "Baseline" : "Design #" + c.seq);
    var status = c.status + (c.status === "ok" ? (c.feasible ? ", feasible" : ", infeasible") : "");
    if (c.pareto_rank) { status += " · on the Pareto front"; }
    if (c.reason) { status += " · " + c.reason; }
    text(document.getElementById("candidate-status"), status);
    var pt = document.getElementById("candidate-params"), mt = document.getElementById("candidate-metrics");
    pt.textContent = ""; mt.textContent = "";
    row(pt, ["variable", "unit", "value", "baseline", "Δ", "Δ %"], true);
    DATA.variables.forEach(function (v) {
      var x = c.params[v.name], b = base ? base.params[v.name] : null, d = diff(x, b);
      row(pt, [v.name, v.unit, fmt(x), fmt(b), d[0], d[1]]);
    });
    row(mt, ["metric", "unit", "value", "baseline", "Δ", "Δ %"], true);
    DATA.metrics.forEach(function (m) {
      var x = c.metrics[m.name], b = base ? base.metrics[m.name] : null, d = diff(x, b);
      row(mt, [m.name, m.unit, fmt(x), fmt(b), d[0], d[1]]);
    });
    text(document.getElementById("candidate-note"), c.pareto_rank
      ? "Not exported in full: evaluate it with `pkmlab compare --pareto pareto.csv --designs " + c.seq + "`."
      : "Not on the Pareto front: no design files were written for it.");
    card.hidden = false;
    card.scrollIntoView({ behavior: "smooth", block: "start" });
  }

  /* ---- wiring ------------------------------------------------------------------------ */
  function onClick(div) {
    if (!div) { return; }
    div.on("plotly_click", function (ev) {
      var p = ev && ev.points && ev.points[0];
      if (p && p.customdata !== undefined && p.customdata !== null) {
        showCandidate(Array.isArray(p.customdata) ? p.customdata[0] : p.customdata);
      }
    });
  }

  document.querySelectorAll("[data-show-design]").forEach(function (b) {
    b.addEventListener("click", function () { showDesign(+b.dataset.showDesign, false); });
  });
  document.querySelectorAll("[data-colour-design]").forEach(function (s) {
    s.addEventListener("change", function () { recolour(+s.dataset.colourDesign, +s.value); });
  });
  document.querySelectorAll("[data-close]").forEach(function (b) {
    b.addEventListener("click", function () { document.getElementById(b.dataset.close).hidden = true; });
  });

  var ready = [];
  if (document.getElementById("pareto-matrix")) {
    ready.push(draw("pareto-matrix", "fig-pareto-matrix").then(onClick));
  }
  if (document.getElementById("pareto-parcoords")) {
    ready.push(draw("pareto-parcoords", "fig-pareto-parcoords"));
  }
  (DATA.scenes || []).forEach(function (s) { ready.push(draw(s.div, s.figure)); });
  var first = document.querySelector("article.design");
  if (first) { ready.push(showDesign(+first.id.replace("design-", ""), false)); }
  Promise.all(ready).then(function () { document.body.dataset.ready = "true"; });
  window.pkmlab = { showDesign: showDesign, showCandidate: showCandidate, data: DATA };
})();
