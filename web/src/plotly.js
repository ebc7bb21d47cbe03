// plotly.js (the 2D plots: spectra, the polar plot, the console's coverage) as its own chunk,
// loaded on first use. Only the traces the app draws are in it (plotly_partial.js: plotly's core
// with scatter, and scatterpolar): ~1.1 MB minified where the full strict bundle was 5.2 MB,
// which took most of two seconds to load and parse on the explorer's first view.
let loading = null;
export function plotly() {
  loading ??= import('./plotly_partial.js').then((m) => m.default);
  return loading;
}
