// The site's only script (plain JS, no dependencies, works from file://
// URLs). Two parts:
// - The search box over controllers, verbs, buffers and states. Its index
//   (window.RCS_SEARCH, search.js: megabytes for a large set) is loaded
//   when the box is first focused or typed in, so no page pays for it at
//   load.
// - The full-size view of a graph: the "Full size" button on each graph,
//   or a click on the graph's background (not on one of its links, which
//   keep leading to their row or state; not its box's scroll bar), opens a
//   modal dialog showing the same SVG at its natural size, to pan (drag;
//   arrow keys) and zoom (wheel or pinch about the pointer; + / − / 1:1 /
//   Fit buttons; keys + - 0).
//   Esc, the Close button or a click outside the graph's dialog closes it;
//   a link followed from it closes it first.
(function () {
  "use strict";
  var root = document.body.getAttribute("data-root") || "";
  var box = document.getElementById("search");
  var list = document.getElementById("results");
  var index = null;
  var loading = false;
  // Load search.js once; show the results for what was typed meanwhile.
  function load() {
    if (index || loading) { return; }
    if (window.RCS_SEARCH) { index = window.RCS_SEARCH; return; }
    loading = true;
    var script = document.createElement("script");
    script.src = root + "search.js";
    script.onload = function () {
      index = window.RCS_SEARCH || [];
      show(box.value);
    };
    document.head.appendChild(script);
  }
  function show(query) {
    if (!index) { return; }
    while (list.firstChild) { list.removeChild(list.firstChild); }
    var q = query.trim().toLowerCase();
    if (!q) { list.hidden = true; return; }
    var shown = 0;
    for (var i = 0; i < index.length && shown < 30; i++) {
      var e = index[i];
      if (e[0].toLowerCase().indexOf(q) < 0) { continue; }
      var li = document.createElement("li");
      var a = document.createElement("a");
      a.href = root + e[2];
      a.textContent = e[0];
      var kind = document.createElement("span");
      kind.className = "kind";
      kind.textContent = e[1];
      a.appendChild(kind);
      li.appendChild(a);
      list.appendChild(li);
      shown++;
    }
    list.hidden = shown === 0;
  }
  if (box && list) {
    box.addEventListener("focus", load);
    box.addEventListener("input", function () { load(); show(box.value); });
    box.addEventListener("keydown", function (ev) {
      if (ev.key === "Enter") {
        var first = list.querySelector("a");
        if (first) { window.location.href = first.href; }
      } else if (ev.key === "Escape") {
        box.value = ""; show("");
      }
    });
  }
})();

(function () {
  "use strict";
  var XLINK = "http://www.w3.org/1999/xlink";
  var MIN_SCALE = 0.1;
  var MAX_SCALE = 8;
  var STEP = 1.25;
  var graphs = document.querySelectorAll("div.graph");
  if (!graphs.length || !window.HTMLDialogElement) { return; }

  // The link (with a target) that an event happened in, if any.
  function linkOf(node, stop) {
    for (var n = node; n && n !== stop; n = n.parentNode) {
      if (n.nodeType === 1 && n.localName === "a" &&
          (n.hasAttribute("href") || n.hasAttributeNS(XLINK, "href"))) {
        return n;
      }
    }
    return null;
  }
  function hrefOf(a) {
    return a.getAttribute("href") || a.getAttributeNS(XLINK, "href");
  }
  function button(text, label, cls) {
    var b = document.createElement("button");
    b.type = "button";
    b.textContent = text;
    b.setAttribute("aria-label", label);
    b.title = label;
    if (cls) { b.className = cls; }
    return b;
  }

  // The dialog, made once and shared by every graph of the page.
  var dialog = document.createElement("dialog");
  dialog.className = "graph-full";
  dialog.setAttribute("aria-label", "Graph at full size");
  var bar = document.createElement("div");
  bar.className = "graph-full-bar";
  var title = document.createElement("span");
  title.className = "graph-full-title";
  var zoomOut = button("\u2212", "Zoom out", "zoom-out");
  var zoomIn = button("+", "Zoom in", "zoom-in");
  var natural = button("1:1", "Natural size", "zoom-reset");
  var fit = button("Fit", "Fit to the window", "zoom-fit");
  var close = button("Close \u2715", "Close the full-size view (Esc)", "close");
  var level = document.createElement("span");
  level.className = "zoom-level";
  level.setAttribute("aria-live", "polite");
  [title, zoomOut, level, zoomIn, natural, fit, close].forEach(function (e) { bar.appendChild(e); });
  var view = document.createElement("div");
  view.className = "graph-full-view";
  view.tabIndex = 0;
  view.setAttribute("aria-label", "Graph: drag or arrow keys to pan, wheel or + and - to zoom");
  dialog.appendChild(bar);
  dialog.appendChild(view);
  document.body.appendChild(dialog);

  var svg = null;       // the SVG shown, moved here from its page box
  var home = null;      // where it came from: its box, and a stand-in
  var stand = null;
  var opener = null;    // what to give the focus back to
  var savedStyle = null;
  var w = 0, h = 0;     // the SVG's natural size, in CSS px
  var s = 1, tx = 0, ty = 0;

  function apply() {
    svg.style.transform = "translate(" + tx + "px," + ty + "px) scale(" + s + ")";
    svg.setAttribute("data-scale", String(s));
    level.textContent = Math.round(s * 100) + "%";
  }
  // Zoom by `k` keeping the point (x, y) of the view where it is.
  function zoomAt(k, x, y) {
    var next = Math.min(MAX_SCALE, Math.max(MIN_SCALE, s * k));
    k = next / s;
    tx = x - (x - tx) * k;
    ty = y - (y - ty) * k;
    s = next;
    apply();
  }
  function zoomCentre(k) { zoomAt(k, view.clientWidth / 2, view.clientHeight / 2); }
  // Scale `to`, the drawing centred where it is smaller than the view.
  function place(to) {
    s = to;
    tx = Math.max(0, (view.clientWidth - w * s) / 2);
    ty = Math.max(0, (view.clientHeight - h * s) / 2);
    apply();
  }
  function fitScale() {
    return Math.min(view.clientWidth / w, view.clientHeight / h, MAX_SCALE);
  }

  function open(box, from) {
    if (dialog.open) { return; }
    svg = box.querySelector("svg");
    if (!svg) { return; }
    opener = from || null;
    home = box;
    // Keep the page's layout while the SVG is away.
    stand = document.createElement("div");
    stand.style.height = svg.getBoundingClientRect().height + "px";
    box.insertBefore(stand, svg);
    savedStyle = svg.getAttribute("style");
    w = svg.width.baseVal.value;
    h = svg.height.baseVal.value;
    var t = svg.querySelector("title");
    title.textContent = t ? t.textContent : "";
    view.appendChild(svg);
    svg.style.width = w + "px";
    svg.style.height = h + "px";
    dialog.showModal();
    place(1);
    view.focus();
  }
  function restore() {
    if (!svg) { return; }
    if (savedStyle === null) { svg.removeAttribute("style"); } else { svg.setAttribute("style", savedStyle); }
    svg.removeAttribute("data-scale");
    home.insertBefore(svg, stand);
    home.removeChild(stand);
    svg = null;
    if (opener) { opener.focus(); }
  }
  dialog.addEventListener("close", restore);
  close.addEventListener("click", function () { dialog.close(); });
  zoomIn.addEventListener("click", function () { zoomCentre(STEP); });
  zoomOut.addEventListener("click", function () { zoomCentre(1 / STEP); });
  natural.addEventListener("click", function () { place(1); });
  fit.addEventListener("click", function () { place(fitScale()); });
  // A click on the backdrop (outside the dialog's box) closes it.
  dialog.addEventListener("click", function (ev) {
    if (ev.target !== dialog) { return; }
    var r = dialog.getBoundingClientRect();
    if (ev.clientX < r.left || ev.clientX > r.right || ev.clientY < r.top || ev.clientY > r.bottom) {
      dialog.close();
    }
  });
  dialog.addEventListener("keydown", function (ev) {
    if (ev.target.localName === "button" && (ev.key === "Enter" || ev.key === " ")) { return; }
    var pan = 60;
    switch (ev.key) {
      case "+": case "=": zoomCentre(STEP); break;
      case "-": case "_": zoomCentre(1 / STEP); break;
      case "0": place(1); break;
      case "ArrowLeft": tx += pan; apply(); break;
      case "ArrowRight": tx -= pan; apply(); break;
      case "ArrowUp": ty += pan; apply(); break;
      case "ArrowDown": ty -= pan; apply(); break;
      default: return;
    }
    ev.preventDefault();
  });

  view.addEventListener("wheel", function (ev) {
    ev.preventDefault();
    var r = view.getBoundingClientRect();
    var dy = ev.deltaMode === 1 ? ev.deltaY * 16 : ev.deltaY;
    zoomAt(Math.exp(-dy * 0.002), ev.clientX - r.left, ev.clientY - r.top);
  }, { passive: false });

  // Drag to pan, two pointers to pinch. A press that moves more than a few
  // pixels is a drag, and the click that ends it follows no link.
  var pointers = {};
  var dragged = false;
  var last = null;
  function count() { return Object.keys(pointers).length; }
  function pair() {
    var ids = Object.keys(pointers);
    var a = pointers[ids[0]], b = pointers[ids[1]];
    return { x: (a.x + b.x) / 2, y: (a.y + b.y) / 2, d: Math.hypot(a.x - b.x, a.y - b.y) };
  }
  view.addEventListener("pointerdown", function (ev) {
    if (ev.button !== 0) { return; }
    var r = view.getBoundingClientRect();
    pointers[ev.pointerId] = { x: ev.clientX - r.left, y: ev.clientY - r.top, x0: ev.clientX, y0: ev.clientY };
    if (count() === 1) { dragged = false; }
    last = count() === 2 ? pair() : null;
  });
  view.addEventListener("pointermove", function (ev) {
    var p = pointers[ev.pointerId];
    if (!p) { return; }
    var r = view.getBoundingClientRect();
    var x = ev.clientX - r.left, y = ev.clientY - r.top;
    if (!dragged && Math.hypot(ev.clientX - p.x0, ev.clientY - p.y0) > 4) {
      dragged = true;
      // Captured only once it is a drag: a capture retargets the click,
      // and a plain click must reach the link under it.
      view.setPointerCapture(ev.pointerId);
      view.classList.add("dragging");
    }
    if (count() === 2) {
      p.x = x; p.y = y;
      var now = pair();
      if (last && last.d > 0) {
        tx += now.x - last.x;
        ty += now.y - last.y;
        zoomAt(now.d / last.d, now.x, now.y);
      }
      last = now;
    } else if (dragged) {
      tx += x - p.x;
      ty += y - p.y;
      p.x = x; p.y = y;
      apply();
    }
  });
  function up(ev) {
    delete pointers[ev.pointerId];
    last = count() === 2 ? pair() : null;
    if (!count()) { view.classList.remove("dragging"); }
  }
  view.addEventListener("pointerup", up);
  view.addEventListener("pointercancel", up);
  view.addEventListener("click", function (ev) {
    if (dragged) {
      dragged = false;
      ev.preventDefault();
      ev.stopPropagation();
      return;
    }
    var a = linkOf(ev.target, view);
    if (!a) { return; }
    // Close first, so the row or state the link leads to is on the page.
    ev.preventDefault();
    var to = new URL(hrefOf(a), document.baseURI).href;
    opener = null;
    dialog.close();
    window.location.href = to;
  }, true);

  // Each graph of the page: a button, and a click on its background.
  Array.prototype.forEach.call(graphs, function (box) {
    if (!box.querySelector("svg")) { return; }
    var b = button("\u2922 Full size", "Open this graph full size, to pan and zoom", "graph-open");
    box.parentNode.insertBefore(b, box);
    b.addEventListener("click", function () { open(box, b); });
    box.addEventListener("click", function (ev) {
      // In the drawing only: not on the box's scroll bar or beside the SVG.
      var inSvg = ev.target.closest ? ev.target.closest("svg") : null;
      if (!inSvg || linkOf(ev.target, box)) { return; }
      var sel = window.getSelection && window.getSelection();
      if (sel && !sel.isCollapsed) { return; }
      open(box, b);
    });
  });
})();
