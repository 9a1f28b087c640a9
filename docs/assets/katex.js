// Renders the pages' \( … \) and \[ … \] (pymdownx.arithmatex, generic mode) with the vendored
// KaTeX, on first load and on Material's instant navigation.
function renderMath() {
  renderMathInElement(document.body, {
    delimiters: [
      { left: "\\[", right: "\\]", display: true },
      { left: "\\(", right: "\\)", display: false },
    ],
  });
}
if (window.document$) {
  window.document$.subscribe(renderMath);
} else {
  document.addEventListener("DOMContentLoaded", renderMath);
}
