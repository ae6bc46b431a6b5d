// The site's only script: the search box over controllers, verbs, buffers
// and states (window.RCS_SEARCH, from search.js), and a highlight on the
// graph element a row or state link points at. Works from file:// URLs.
(function () {
  "use strict";
  var root = document.body.getAttribute("data-root") || "";
  var box = document.getElementById("search");
  var list = document.getElementById("results");
  var index = window.RCS_SEARCH || [];
  function show(query) {
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
    box.addEventListener("input", function () { show(box.value); });
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
