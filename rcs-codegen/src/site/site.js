// The site's only script: the search box over controllers, verbs, buffers
// and states. Its index (window.RCS_SEARCH, search.js: megabytes for a
// large set) is loaded when the box is first focused or typed in, so no
// page pays for it at load. Works from file:// URLs.
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
