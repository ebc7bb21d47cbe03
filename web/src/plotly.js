// plotly.js (the 2D plots: spectra, the polar plot, the console's coverage) as its own chunk,
// loaded on first use: the page and Figure 7 (three.js) need not wait for its ~5 MB to be parsed
// (the explorer loads it once Figure 7 is drawn).
let loading = null;
export function plotly() {
  loading ??= import('plotly.js-strict-dist-min').then((m) => m.default);
  return loading;
}
