// proxseg's batch page (io/batch_page.hpp): the frames of a batch folder as a grid of their
// pictures, with their counts and times, failures marked, sorting, filtering, paging and the
// distributions of time and count. The rows are embedded (#proxseg-rows, JSON); the pictures and
// 3D pages are the batch's own files beside this page, loaded only when shown.
"use strict";
(function () {
  const started = performance.now();
  const data = JSON.parse(document.getElementById("proxseg-rows").textContent);
  const PAGE = 60;
  // A row: [frame, ms, count, named, error, picture, page] (indices below). picture and page
  // are links made by the page's writer (batch_page.cpp): "./" and the name percent-encoded.
  const F = { frame: 0, ms: 1, count: 2, named: 3, error: 4, picture: 5, page: 6 };
  const rows = data.rows;
  const state = { filter: "", status: "all", sort: "name", minCount: 0, minMs: 0, page: 0,
    shown: [] };
  // firstDrawMs: from this script's start; openedMs: from the navigation's start.
  const api = { firstDrawMs: null, openedMs: null };
  window.proxsegBatch = api;

  // Natural order of names: learn2 before learn10.
  const collator = new Intl.Collator(undefined, { numeric: true });
  const orders = {
    name: (a, b) => collator.compare(a[F.frame], b[F.frame]),
    "count-": (a, b) => (b[F.count] ?? -1) - (a[F.count] ?? -1) || orders.name(a, b),
    "count+": (a, b) => (a[F.count] ?? 1e18) - (b[F.count] ?? 1e18) || orders.name(a, b),
    "time-": (a, b) => b[F.ms] - a[F.ms] || orders.name(a, b),
    "time+": (a, b) => a[F.ms] - b[F.ms] || orders.name(a, b),
  };

  // What "found" counts: a segmentation's candidates, a recognition's named objects.
  const count = () => (data.command === "recognize" ? F.named : F.count);

  function selected() {
    const text = state.filter.toLowerCase();
    return rows.filter((r) => {
      if (text && !r[F.frame].toLowerCase().includes(text)) return false;
      if (state.minCount > 0 && !(r[count()] >= state.minCount)) return false;
      if (state.minMs > 0 && !(r[F.ms] >= state.minMs)) return false;
      if (state.status === "failed") return r[F.error] !== null;
      if (state.status === "done") return r[F.error] === null;
      if (state.status === "empty") return r[F.error] === null && !r[F.count];
      return true;
    }).sort(orders[state.sort]);
  }

  const el = (tag, props = {}, ...children) => {
    const e = Object.assign(document.createElement(tag), props);
    e.append(...children);
    return e;
  };
  const seconds = (ms) => (ms >= 1000 ? (ms / 1000).toFixed(2) + " s" : ms.toFixed(0) + " ms");

  // Only such a link is followed or loaded: none that is not relative (a scheme such as
  // javascript:), whatever a page's rows were made of.
  const local = (link) => (typeof link === "string" && link.startsWith("./") ? link : null);

  function card(r) {
    const failed = r[F.error] !== null;
    const page = local(r[F.page]), src = local(r[F.picture]);
    const link = page || src;
    const picture = src
      ? el("img", { src, loading: "lazy", alt: r[F.frame] })
      : el("div", { className: "nopicture", textContent: failed ? "failed" : "no picture" });
    const what = data.command === "recognize"
      ? `${r[F.named]} named of ${r[F.count]}`
      : `${r[F.count]} candidate${r[F.count] === 1 ? "" : "s"}`;
    const lines = [el("b", { textContent: r[F.frame] }),
      el("span", { textContent: failed ? "failed" : `${what} · ${seconds(r[F.ms])}` })];
    if (failed) lines.push(el("span", { className: "error", textContent: r[F.error] }));
    const c = el("figure", { className: failed ? "card failed" : "card" },
      link ? el("a", { href: link, title: page ? "the 3D page" : "the picture" }, picture)
        : picture, el("figcaption", {}, ...lines));
    c.dataset.frame = r[F.frame];
    return c;
  }

  function render() {
    const list = selected();
    const pages = Math.max(1, Math.ceil(list.length / PAGE));
    state.page = Math.min(state.page, pages - 1);
    state.shown = list.slice(state.page * PAGE, (state.page + 1) * PAGE);
    document.getElementById("grid").replaceChildren(...state.shown.map(card));
    const from = list.length ? state.page * PAGE + 1 : 0;
    document.getElementById("position").textContent =
      `${from}-${state.page * PAGE + state.shown.length} of ${list.length} frames` +
      (list.length < rows.length ? ` (${rows.length} in all)` : "");
    document.getElementById("previous").disabled = state.page === 0;
    document.getElementById("next").disabled = state.page >= pages - 1;
    plots(list);
  }

  // A histogram of values in 20 bins, as SVG bars, with the range below.
  function histogram(id, title, values, format) {
    const box = document.getElementById(id);
    box.textContent = "";
    box.append(el("h2", { textContent: title }));
    if (!values.length) return;
    // A loop, not Math.min(...values): spreading a million frames' values overflows the stack.
    let lo = Infinity, hi = -Infinity;
    for (const v of values) (lo = Math.min(lo, v)), (hi = Math.max(hi, v));
    const bins = new Array(20).fill(0);
    for (const v of values) bins[hi > lo ? Math.min(19, Math.floor(((v - lo) / (hi - lo)) * 20)) : 0]++;
    const top = Math.max(...bins), ns = "http://www.w3.org/2000/svg";
    const svg = document.createElementNS(ns, "svg");
    svg.setAttribute("viewBox", "0 0 200 60");
    bins.forEach((n, i) => {
      const bar = document.createElementNS(ns, "rect");
      const h = (n / top) * 58;
      Object.entries({ x: i * 10 + 1, y: 60 - h, width: 8, height: h }).forEach(([k, v]) =>
        bar.setAttribute(k, v));
      const tip = document.createElementNS(ns, "title");
      tip.textContent = `${n} frames`;
      bar.append(tip);
      svg.append(bar);
    });
    box.append(svg, el("div", { className: "range", textContent: `${format(lo)} … ${format(hi)}` }));
  }
  function plots(list) {
    const done = list.filter((r) => r[F.error] === null);
    histogram("time-plot", "Time per frame", done.map((r) => r[F.ms]), seconds);
    histogram("count-plot", data.command === "recognize" ? "Named objects per frame"
      : "Candidates per frame", done.map((r) => r[count()]), (v) => String(v));
  }

  function start() {
    document.title = "proxseg: " + data.title;
    document.getElementById("title").textContent = data.title;
    const failed = rows.filter((r) => r[F.error] !== null).length;
    document.getElementById("summary").textContent =
      `${data.command}: ${rows.length} frames, ${failed} failed` +
      (data.missing ? `, ${data.missing} not done` : "");
    const on = (id, event, f) => document.getElementById(id).addEventListener(event, f);
    on("filter", "input", (e) => ((state.filter = e.target.value), (state.page = 0), render()));
    on("status", "change", (e) => ((state.status = e.target.value), (state.page = 0), render()));
    on("sort", "change", (e) => ((state.sort = e.target.value), (state.page = 0), render()));
    on("min-count", "input", (e) => ((state.minCount = Number(e.target.value) || 0), (state.page = 0),
      render()));
    on("min-ms", "input", (e) => ((state.minMs = Number(e.target.value) || 0), (state.page = 0),
      render()));
    on("previous", "click", () => (--state.page, render()));
    on("next", "click", () => (++state.page, render()));
    render();
    requestAnimationFrame(() => {
      api.openedMs = performance.now();
      api.firstDrawMs = api.openedMs - started;
    });
  }

  // ---- for tests and scripts ----
  Object.assign(api, {
    shown: () => state.shown.map((r) => r[F.frame]),
    total: () => rows.length,
    setFilter(text) { document.getElementById("filter").value = text; state.filter = text; state.page = 0; render(); },
    setStatus(status) { document.getElementById("status").value = status; state.status = status; state.page = 0; render(); },
    setSort(sort) { document.getElementById("sort").value = sort; state.sort = sort; state.page = 0; render(); },
    setMinCount(n) { document.getElementById("min-count").value = n; state.minCount = n; state.page = 0; render(); },
    setMinTime(ms) { document.getElementById("min-ms").value = ms; state.minMs = ms; state.page = 0; render(); },
    nextPage() { document.getElementById("next").click(); },
  });
  start();
})();
