// The explorer's uncertainty map (docs/adaptive.md, "Every choice explained"; docs/uncertainty.md,
// "Interpolated values"): at one incidence θi, the outgoing hemisphere — θo every 5° (cell
// centres 2.5° … 87.5°), φ every 10° — coloured by the interpolated BRDF's relative expanded
// uncertainty k·u / y, where the readings measured near that θi are drawn as black points. One
// Interpolation.InterpolateBatch with include_uncertainty; u is the combined one (measurement and
// interpolation term, √(m² + i²) rounded to float as Interpolate's `combined`), u and y each the
// mean over the bands 400–700 nm, as the adaptive engine summarises a reading; φ mirrored (exact
// for an isotropic sample, as the engine judges; not for an anisotropic one). A direction the
// method cannot answer (an empty octant, outside the hull) is drawn grey: unknown.
import { plotly } from './plotly.js';
import { stream } from './api.js';
import { el, clear } from './dom.js';

const SUMMARY_NM = [400, 700];
export const MAP_THETA_O = Array.from({ length: 18 }, (_, i) => 2.5 + 5 * i);
export const MAP_PHI = Array.from({ length: 19 }, (_, i) => 10 * i);

// k·u / y of one InterpolationResult (u combined, both means over 400–700 nm); null when the
// result is not OK, carries no uncertainty, or its value there is not positive.
export function relativeExpanded(result, k) {
  if (result?.status !== 'INTERPOLATION_STATUS_OK') return null;
  const u = result.uncertainty || {};
  const m = u.measurement || [];
  const i = u.interpolation || [];
  if (!m.length && !i.length) return null;
  let su = 0;
  let sy = 0;
  let n = 0;
  result.spectrum.forEach((y, b) => {
    const nm = result.grid.start_nm + b * result.grid.step_nm;
    if (nm < SUMMARY_NM[0] - 1e-9 || nm > SUMMARY_NM[1] + 1e-9) return;
    su += u.combined?.length ? u.combined[b] : Math.fround(Math.hypot(m[b] ?? 0, i[b] ?? 0));
    sy += y;
    n++;
  });
  if (!n || !(sy > 0)) return null;
  return (k * su) / sy;
}

export function createUncertaintyMap(report) {
  const thetaI = el('input', { id: 'umap-theta-i', type: 'number', value: 35, min: 0, max: 89, step: 'any' });
  const drawButton = el('button', { id: 'umap-draw' }, 'Draw');
  const info = el('p', { id: 'umap-info', class: 'muted umap-note' });
  const plot = el('div', { id: 'umap', class: 'plot' });
  const element = el('div', {},
    el('h2', {}, 'Uncertainty map: where the interpolated BRDF is least known'),
    el('p', { class: 'muted umap-note' }, 'The outgoing hemisphere at one incidence, each direction coloured by the relative expanded uncertainty k·u / BRDF of the interpolated BRDF (measurement and interpolation term, means over 400–700 nm), with the method, coordinates and trend of Figure 8 and φ mirrored as the adaptive engine judges an isotropic sample; black: the readings measured within 2.5° of that θi; grey ×: directions the method cannot answer. An adaptive session measures next where this is largest.'),
    el('div', { class: 'buttons' }, el('label', {}, 'θi ', thetaI), drawButton), info, plot);

  let shown = null; // { results, directions, near, at } of the last map, redrawn when k changes
  let source = null; // () => { session, method, options, points, k }
  let asked = 0;

  async function draw() {
    const s = source?.();
    if (!s?.session) return;
    const ask = ++asked;
    const at = Number(thetaI.value);
    const directions = [];
    for (const phi of MAP_PHI) for (const thetaO of MAP_THETA_O) directions.push({ iso: { theta_i: at, theta_o: thetaO, phi } });
    const results = new Array(directions.length);
    const t0 = performance.now();
    info.textContent = 'interpolating…';
    // φ mirrored, as the adaptive engine judges an isotropic session (exact there); an
    // anisotropic session refuses the option (INVALID_ARGUMENT) and is asked without it.
    let mirrored = true;
    const ask1 = (options) => stream('Interpolation/InterpolateBatch', { session_id: s.session, method: s.method, quantity: 'QUANTITY_BRDF', options, directions, include_uncertainty: true }, (chunk) => {
      chunk.results.forEach((r, i) => { results[chunk.first_index + i] = r; });
    });
    try {
      await ask1({ ...s.options, mirror_phi: true }).catch((e) => {
        if (e.code !== 'INVALID_ARGUMENT') throw e;
        mirrored = false;
        return ask1(s.options);
      });
    } catch (e) { info.textContent = e.message; report(e.message); return; }
    if (ask !== asked) return;
    const p = s.points;
    const near = [];
    for (let i = 0; p && i < p.ids.length; i++) if (Math.abs(p.theta_i[i] - at) <= 2.5) near.push(i);
    shown = { results, directions, near, points: p, at, ms: performance.now() - t0, method: s.method, mirrored };
    await render(s.k);
  }

  async function render(k) {
    if (!shown) return;
    const { results, directions, near, points, at, ms, method, mirrored } = shown;
    const values = results.map((r) => relativeExpanded(r, k));
    const known = values.map((v, i) => [v, i]).filter(([v]) => v !== null);
    const unknown = values.map((v, i) => [v, i]).filter(([v]) => v === null);
    const sorted = known.map(([v]) => v).sort((a, b) => a - b);
    const median = sorted.length ? sorted[Math.floor(sorted.length / 2)] : NaN;
    info.textContent = `${known.length} of ${directions.length} directions answered (${method.replace('INTERPOLATION_METHOD_', '').toLowerCase()}${mirrored ? ', φ mirrored' : ''}) in ${Math.round(ms)} ms; k = ${k}: median ${(100 * median).toPrecision(2)} %, largest ${(100 * (sorted.at(-1) ?? NaN)).toPrecision(2)} % of the BRDF`;
    if (!known.length) info.textContent = `no direction at θi ${at}° could be interpolated`;
    const iso = (i) => directions[i].iso;
    const Plotly = await plotly();
    Plotly.react(plot, [
      { type: 'scatterpolar', mode: 'markers', r: known.map(([, i]) => iso(i).theta_o), theta: known.map(([, i]) => iso(i).phi), name: `k·u / BRDF, k = ${k}`,
        marker: { size: 11, color: known.map(([v]) => v), colorscale: 'YlOrRd', reversescale: true, cmin: 0, showscale: true, colorbar: { title: { text: `k·u / f (k = ${k})` } } },
        meta: { map: 'u', k, theta_i: at, mirror_phi: mirrored }, hovertemplate: 'θo %{r}°, φ %{theta}°: %{marker.color:.3f}<extra></extra>' },
      { type: 'scatterpolar', mode: 'markers', r: unknown.map(([, i]) => iso(i).theta_o), theta: unknown.map(([, i]) => iso(i).phi), name: 'unknown', marker: { size: 8, symbol: 'x', color: '#999' }, meta: { map: 'unknown' } },
      { type: 'scatterpolar', mode: 'markers', r: near.map((i) => points.theta_o[i]), theta: near.map((i) => points.phi[i]), name: `readings, θi ${at} ± 2.5°`, marker: { size: 5, color: 'black' }, meta: { map: 'readings', ids: near.map((i) => points.ids[i]) } },
    ], { height: 420, margin: { t: 30 }, title: { text: `relative expanded uncertainty at θi ${at}°` }, polar: { sector: [0, 180], radialaxis: { range: [0, 90], title: { text: 'θo °' } }, angularaxis: { direction: 'counterclockwise' } }, legend: { orientation: 'h' } }, { displaylogo: false, responsive: true });
  }

  drawButton.addEventListener('click', () => draw());
  return {
    element,
    // `get` gives the session and the explorer's choices when the map is drawn.
    bind(get) { source = get; },
    draw,
    redraw(k) { return render(k); },
    clear() { shown = null; clear(info); },
  };
}
