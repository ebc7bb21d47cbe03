// The explorer: the paper's Figure 7 (a session's readings in (α, β, δ) and in (θi, θo, φ),
// rotatable WebGL point clouds, points3d.js), a reading's spectrum on click, the interpolated
// spectrum at a chosen direction with its vertices and weights (Figure 8; method, coordinates
// and trend switches), a polar plot in the plane of incidence with a wavelength slider, and
// downloads of every export (Data.Export: readings CSV, grids at a chosen step, MERL, RGL).
// Uncertainties (docs/uncertainty.md) are drawn expanded, ± k·u with k chosen (1 or 2): a
// reading's stored budget as error bars on its BRDF, bands around Figure 8's spectrum (the
// measurement part and the combined one with the interpolation term) and the polar curve; the
// uncertainty map colours the outgoing hemisphere at one θi by k·u / BRDF (uncertainty_map.js).
import { plotly } from './plotly.js';
import { call, stream } from './api.js';
import { el, clear, stateName } from './dom.js';
import { createPoints3d } from './points3d.js';
import { createAppearance } from './appearance.js';
import { createUncertaintyMap } from './uncertainty_map.js';

const PLOT = { displaylogo: false, responsive: true };
const POINT_COLUMNS = ['ids', 'alpha', 'beta', 'delta', 'theta_i', 'theta_o', 'phi', 'flagged'];
// The coverage factors offered, with the coverage each stands for (docs/uncertainty.md,
// "Expanded uncertainty").
const COVERAGE = { 2: 'k = 2 (≈95 %)', 1: 'k = 1 (≈68 %)' };
// A reading's spectra: each quantity's legend name and y axis.
const QUANTITY_AXES = { QUANTITY_RADIANCE: ['radiance (W·m⁻²·sr⁻¹·nm⁻¹)', 'y'], QUANTITY_REFLECTANCE: ['reflectance', 'y2'], QUANTITY_BRDF: ['BRDF (sr⁻¹)', 'y2'] };
const BLUE = '#1f77b4'; // plotly's first colour, kept by the polar curve drawn after its band

// The median of k·u / |y| over the bands, as a percentage ("1.3 %"); '' without u.
function medianPercent(u, y, k) {
  if (!u?.length || u.length !== y.length) return '';
  const r = u.map((v, i) => (k * v) / Math.abs(y[i])).filter(Number.isFinite).sort((a, b) => a - b);
  return r.length ? `${(100 * r[Math.floor(r.length / 2)]).toPrecision(2)} %` : '';
}

function wavelengths(grid, n) {
  const count = n ?? grid.count;
  return Array.from({ length: count }, (_, i) => grid.start_nm + i * grid.step_nm);
}

// A shaded band y ± k·u as two traces: the lower edge, then the upper one filled down to it.
// None when u is not given (not estimated) or is not one value per band. `meta.band` names the
// band (the tests read it).
function band(x, y, u, k, { id, name, color }) {
  if (!u?.length || u.length !== y.length) return [];
  const edge = { x, mode: 'lines', line: { width: 0, color }, legendgroup: id, hoverinfo: 'skip' };
  return [
    { ...edge, y: y.map((v, i) => v - k * u[i]), showlegend: false, meta: { band: id, edge: 'lower', k } },
    { ...edge, y: y.map((v, i) => v + k * u[i]), fill: 'tonexty', fillcolor: color, name, meta: { band: id, edge: 'upper', k } },
  ];
}

// What the combined band of an interpolated spectrum holds: the interpolation term alone where
// the answer has no measurement part (quantities other than the BRDF).
function combinedName(u) {
  return u.measurement?.length ? 'measurement and interpolation' : 'interpolation only';
}

// An answer's combined uncertainty in one band: its `combined`, or sqrt(measurement² +
// interpolation²) where a batch answer leaves combined out; undefined where neither part was
// estimated (combined is then 0, which is not an uncertainty of zero).
function combinedAt(u, at) {
  const m = u?.measurement?.[at];
  const i = u?.interpolation?.[at];
  if (m === undefined && i === undefined) return undefined;
  return u.combined?.length ? u.combined[at] : Math.hypot(m ?? 0, i ?? 0);
}

// What an uncertainty leaves out ("interpolation: the nearest method blends one reading…"), as
// a list under `id`; nothing when it leaves nothing out.
function notEstimated(id, texts) {
  if (!texts?.length) return [];
  return [el('p', { class: 'muted' }, 'Not in the uncertainty:'), el('ul', { id, class: 'muted' }, texts.map((t) => el('li', {}, t)))];
}

function fromBase64(s) {
  const bin = atob(s);
  const out = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) out[i] = bin.charCodeAt(i);
  return out;
}

export function createExplorer(root, report) {
  const sessionSelect = el('select', { id: 'explorer-session' });
  const loadInfo = el('span', { id: 'explorer-info' });
  const fig7aBox = el('div', { id: 'fig7-pose', class: 'plot half' });
  const fig7bBox = el('div', { id: 'fig7-iso', class: 'plot half' });
  const spectrum = el('div', { id: 'reading-spectrum', class: 'plot' });
  const readingInfo = el('p', { id: 'reading-info' }, 'Click a reading in either plot.');
  const quantity = el('select', { id: 'quantity' }, el('option', { value: 'QUANTITY_BRDF' }, 'BRDF (sr⁻¹)'), el('option', { value: 'QUANTITY_REFLECTANCE' }, 'reflectance'), el('option', { value: 'QUANTITY_RADIANCE' }, 'radiance'));
  const method = el('select', { id: 'method' }, el('option', { value: 'INTERPOLATION_METHOD_OCTANT' }, 'octant (paper)'), el('option', { value: 'INTERPOLATION_METHOD_DELAUNAY' }, 'Delaunay'), el('option', { value: 'INTERPOLATION_METHOD_NEAREST' }, 'nearest'));
  const trend = el('select', { id: 'trend' }, el('option', { value: 'INTERPOLATION_TREND_NONE' }, 'none (the paper)'), el('option', { value: 'INTERPOLATION_TREND_BIVARIATE' }, 'bivariate (θh, θd)'));
  const coordinates = el('select', { id: 'coordinates' }, el('option', { value: 'INTERPOLATION_COORDINATES_INCIDENCE' }, '(θi, θo, φ) (the paper)'), el('option', { value: 'INTERPOLATION_COORDINATES_HALF_DIFFERENCE' }, 'half/difference'));
  const gridStep = el('select', { id: 'grid-step' }, [10, 5, 2, 1].map((d) => el('option', { value: d, selected: d === 5 }, `${d}°`)));
  const ti = el('input', { id: 'q-theta-i', type: 'number', value: 35, min: 0, max: 90, step: 'any' });
  const to = el('input', { id: 'q-theta-o', type: 'number', value: 40, min: 0, max: 90, step: 'any' });
  const phi = el('input', { id: 'q-phi', type: 'number', value: 40, min: 0, max: 180, step: 'any' });
  const interp = el('div', { id: 'interp-spectrum', class: 'plot' });
  const interpInfo = el('div', { id: 'interp-info' });
  const polar = el('div', { id: 'polar', class: 'plot half' });
  const slider = el('input', { id: 'wavelength', type: 'range', min: 0, max: 0, value: 0 });
  const sliderLabel = el('span', { id: 'wavelength-label' });
  const downloads = el('div', { id: 'downloads', class: 'buttons' });
  const downloadInfo = el('p', { id: 'download-info' });
  const coverage = el('select', { id: 'coverage-k' }, [2, 1].map((k) => el('option', { value: k }, COVERAGE[k])));
  const readingNotes = el('div', { id: 'reading-notes' });
  const bandSummary = el('p', { id: 'interp-bands', class: 'muted' });
  const uncertaintyMap = createUncertaintyMap(report);

  let Plotly = null; // once loaded (plotly.js)
  let points = null; // columns of ReadingPoints over the whole session
  let session = '';
  let polarData = null;
  let shownReading = null; // the clicked reading's spectra and budget, redrawn when k changes
  let shownInterpolation = null; // Figure 8's answer, likewise
  const measured = new Set(); // sessions the listing showed with sample readings

  root.append(
    el('div', { class: 'buttons' }, el('label', {}, 'Session ', sessionSelect), el('button', { id: 'explorer-load', onclick: () => load(sessionSelect.value) }, 'Load'), el('label', {}, 'uncertainty ± k·u, ', coverage), loadInfo),
    el('h2', {}, 'Figure 7: the readings'),
    el('div', { class: 'row' }, fig7aBox, fig7bBox),
    readingInfo, spectrum, readingNotes,
    el('h2', {}, 'Figure 8: a direction between the readings'),
    el('form', { id: 'direction-form', class: 'buttons', onsubmit: (e) => { e.preventDefault(); interpolate(); } },
      el('label', {}, 'θi ', ti), el('label', {}, 'θo ', to), el('label', {}, 'φ ', phi),
      el('label', {}, 'method ', method), el('label', {}, 'coordinates ', coordinates), el('label', {}, 'trend ', trend), el('label', {}, 'quantity ', quantity),
      el('button', { id: 'interpolate', type: 'submit' }, 'Interpolate')),
    interpInfo, bandSummary, interp,
    uncertaintyMap.element,
    el('h2', {}, 'Plane of incidence'),
    el('div', { class: 'buttons' }, el('label', {}, 'wavelength ', slider), sliderLabel),
    polar,
    el('h2', {}, 'Downloads'),
    el('p', { class: 'muted' }, 'Grids, MERL and RGL files are built with the method, coordinates and trend chosen above; cells the method cannot fill come from Delaunay, then a fitted Cook-Torrance model.'),
    el('div', { class: 'buttons' }, el('label', {}, 'grid step ', gridStep), el('span', { id: 'grid-size', class: 'muted' })),
    downloads, downloadInfo);

  const appearance = createAppearance(root, report);
  // Figure 7's two WebGL plots, made once the first session's readings are asked for: their
  // set-up (two GL contexts, their shaders) then runs while the readings are on their way.
  let fig7a = null;
  let fig7b = null;
  function figure7() {
    if (!fig7a) {
      fig7a = createPoints3d(fig7aBox, { title: '(α, β, δ)', axes: ['α °', 'β °', 'δ °'] });
      fig7b = createPoints3d(fig7bBox, { title: '(θi, θo, φ)', axes: ['θi °', 'θo °', 'φ °'] });
      for (const f of [fig7a, fig7b]) f.onPick(showReading);
    }
    return [fig7a, fig7b];
  }

  const sessionBands = new Map();  // session id → bands of its grid (Session.grid)

  // `listing`: Control.ListSessions's answer when the caller has it already.
  async function listSessions(listing) {
    const r = listing || await call('Control/ListSessions', { page_size: 100 });
    clear(sessionSelect);
    // Each session with its state and, once it has a reading, its grid's bands (101 for a PR-650,
    // 201 for a PR-670, 401 for a CS-2000).
    for (const s of r.sessions) {
      if (s.grid?.count) sessionBands.set(s.session_id, Number(s.grid.count));
      sessionSelect.append(el('option', { value: s.session_id }, `${s.name || s.session_id} (${stateName(s.state)}${s.grid?.count ? `, ${s.grid.count} bands` : ''})`));
    }
    // The newest session with readings first.
    // (brdf-archive's listing has no sample counts: there, a session with steps done.)
    for (const s of r.sessions) {
      const p = s.progress || {};
      if (Number(p.done_samples) > 0 || (!Number(p.total_samples) && Number(p.done_steps) > 0)) measured.add(s.session_id);
    }
    const newest = r.sessions.find((s) => measured.has(s.session_id));
    if (newest) sessionSelect.value = newest.session_id;
  }

  // Figure 7: the readings' poses and directions as columns (Data.StreamReadingPoints, a few
  // messages of up to 8,192 readings, no spectra: 50,000 readings are ~4 MB of JSON), drawn as
  // WebGL point clouds; a reading's spectra are fetched on a click. The plane of incidence's BRDF
  // is asked for at the same time when the listing showed readings (the daemon answers it while
  // the readings stream), else once they are there.
  async function load(id) {
    if (!id) return;
    session = id;
    polarData = null;
    uncertaintyMap.clear();
    const t0 = performance.now();
    const chunks = [];
    const thetaI = Number(ti.value);
    const readings = stream('Data/StreamReadingPoints', { session_id: id, kinds: ['READING_KIND_SAMPLE'] }, (c) => chunks.push(c));
    let plane = measured.has(id) ? planeOfIncidence(id, thetaI) : null;
    const [poses, directions] = figure7();
    await readings;
    const streamed = performance.now() - t0;
    points = joinColumns(chunks);
    if (points.ids.length === 0) {
      loadInfo.textContent = 'this session has no sample readings yet';
      for (const f of [poses, directions]) f.setPoints({ x: [], y: [], z: [], value: [] });
      Plotly = await plotly();
      for (const p of [spectrum, polar]) Plotly.purge(p);
      return;
    }
    poses.setPoints({ x: points.alpha, y: points.beta, z: points.delta, value: points.theta_i });
    directions.setPoints({ x: points.theta_i, y: points.theta_o, z: points.phi, value: points.theta_i });
    loadInfo.textContent = `${points.ids.length} sample readings loaded in ${Math.round(streamed)} ms, plotted in ${Math.round(performance.now() - t0 - streamed)} ms`;
    renderDownloads();
    // plotly (the 2D plots) only once Figure 7 is on screen: parsing it blocks the page, which
    // would hold up the readings' messages and the point clouds' first frame.
    await new Promise((r) => requestAnimationFrame(r));
    Plotly = await plotly();
    plane ??= planeOfIncidence(id, thetaI);
    const data = await plane;
    if (session !== id) return;
    polarData = data;
    if (!polarData) {
      clear(polar).append(el('p', { class: 'muted' }, `no BRDF in the plane of incidence at θi ${thetaI}°`));
    } else {
      slider.max = String(polarData.count - 1);
      slider.value = String(Math.floor(polarData.count / 2));
      drawPolar();
      showGridSize();
    }
    // After the first view: the server renders it with the same work permits as the plots.
    await appearance.load(id, points.ids.length);
    if (session === id) await uncertaintyMap.draw();
  }

  function joinColumns(chunks) {
    const out = {};
    for (const name of POINT_COLUMNS) out[name] = chunks.length === 1 ? chunks[0][name] : [].concat(...chunks.map((c) => c[name]));
    return out;
  }

  async function showReading(k) {
    Plotly = await plotly();
    const p = points;
    const iso = { theta_i: p.theta_i[k], theta_o: p.theta_o[k], phi: p.phi[k] };
    readingInfo.textContent = `reading ${p.ids[k]}: α ${p.alpha[k]}°, β ${p.beta[k]}°, δ ${p.delta[k]}°; θi ${iso.theta_i.toFixed(1)}°, θo ${iso.theta_o.toFixed(1)}°, φ ${iso.phi.toFixed(1)}°${p.flagged[k] ? ' (flagged)' : ''}`;
    for (const f of figure7()) f.mark(k);
    // The reading's own spectrum in each quantity: the nearest reading to its own direction is
    // itself (the daemon converts radiance to reflectance and BRDF with its reference).
    const quantities = ['QUANTITY_RADIANCE', 'QUANTITY_REFLECTANCE', 'QUANTITY_BRDF'];
    const [budget, ...answers] = await Promise.all([readingBudget(p.ids[k]), ...quantities.map((q) => call('Interpolation/Interpolate', { session_id: session, method: 'INTERPOLATION_METHOD_NEAREST', quantity: q, direction: { iso } }).catch((e) => { report(e.message); return null; }))]);
    shownReading = { id: p.ids[k], budget, results: answers.map((a) => a?.result).filter((r) => r?.status === 'INTERPOLATION_STATUS_OK') };
    drawReading();
  }

  // The reading's stored uncertainty budget (Reading.uncertainty), null when it has none (not
  // estimated): the first sample reading after id − 1, without its radiance, the stream cancelled
  // once it is here.
  async function readingBudget(id) {
    const stop = new AbortController();
    let reading = null;
    const request = { session_id: session, kinds: ['READING_KIND_SAMPLE'], after_id: String(BigInt(id) - 1n) };
    try {
      await stream('Data/StreamReadings', request, (r) => { reading ??= r; stop.abort(); }, stop.signal, ['radiance']);
    } catch (e) {
      if (!reading) report(e.message);
    }
    return reading?.id === String(id) ? reading.uncertainty ?? null : null;
  }

  // The clicked reading's spectra, the quantity its budget is of (the BRDF) with error bars
  // ± k·u_c, and what its budget leaves out.
  function drawReading() {
    if (!shownReading) return;
    const k = Number(coverage.value);
    const { budget, results } = shownReading;
    const traces = results.map((res) => {
      const [name, yaxis] = QUANTITY_AXES[res.quantity];
      const trace = { x: wavelengths(res.grid, res.spectrum.length), y: res.spectrum, name, yaxis };
      const u = budget?.quantity === res.quantity ? budget.combined : null;
      if (u?.length === res.spectrum.length) Object.assign(trace, { name: `${name} ± ${k}·u, ${COVERAGE[k]}`, error_y: { type: 'data', array: u.map((v) => k * v), visible: true, thickness: 1, width: 2 } });
      return trace;
    });
    Plotly.react(spectrum, traces, { height: 320, margin: { t: 20 }, xaxis: { title: { text: 'wavelength nm' } }, yaxis: { title: { text: 'radiance' } }, yaxis2: { overlaying: 'y', side: 'right', title: { text: 'reflectance, BRDF' } } }, PLOT);
    clear(readingNotes).append(...(budget ? notEstimated('reading-not-estimated', budget.not_estimated) : [el('p', { class: 'muted', id: 'reading-no-budget' }, `reading ${shownReading.id}: its uncertainty was not estimated (no budget stored with it)`)]));
  }

  // The choices of the Figure 8 form as InterpolationOptions (exports add reciprocity).
  function options() {
    return { coordinates: coordinates.value, trend: trend.value };
  }

  async function interpolate() {
    if (!session) { report('load a session first'); return; }
    Plotly = await plotly();
    const t0 = performance.now();
    try {
      // One call: the vertices come with their own spectra (include_vertex_spectra), the
      // spectrum with its uncertainty (include_uncertainty).
      const res = (await call('Interpolation/Interpolate', { session_id: session, method: method.value, quantity: quantity.value, options: options(), direction: { iso: { theta_i: Number(ti.value), theta_o: Number(to.value), phi: Number(phi.value) } }, include_vertex_spectra: true, include_uncertainty: true })).result;
      const ms = performance.now() - t0;
      clear(interpInfo);
      bandSummary.textContent = '';
      shownInterpolation = null;
      if (res.status !== 'INTERPOLATION_STATUS_OK') {
        interpInfo.append(el('p', { class: 'error', id: 'interp-status' }, `${res.status.replace('INTERPOLATION_STATUS_', '').toLowerCase()}: ${res.detail}`));
        Plotly.purge(interp);
        return;
      }
      const residuals = trend.value === 'INTERPOLATION_TREND_BIVARIATE';
      interpInfo.append(el('p', { id: 'interp-status' }, `${res.spectrum.length} wavelengths from ${res.vertices.length} readings in ${Math.round(ms)} ms` +
        (residuals ? ' (trend + the blend of the vertices\' residuals, so not Σ weight · vertex spectrum)' : '')),
        el('table', { id: 'vertices' }, el('tr', {}, el('th', {}, 'reading'), el('th', {}, '(θi, θo, φ)'), el('th', {}, 'weight')),
          res.vertices.map((v) => el('tr', {}, el('td', {}, v.reading_id), el('td', {}, v.coords.map((c) => c.toFixed(1)).join(', ')), el('td', {}, v.weight.toFixed(3))))),
        ...notEstimated('interp-not-estimated', res.uncertainty?.not_estimated));
      shownInterpolation = { res, unit: quantity.selectedOptions[0].textContent };
      drawInterpolation();
    } catch (e) { report(e.message); }
  }

  // Figure 8: the interpolated spectrum inside its bands ± k·u — the combined one (measurement
  // and interpolation term) when the interpolation term is estimated, the measurement part
  // inside it, darker — and each vertex's own spectrum.
  function drawInterpolation() {
    if (!shownInterpolation) return;
    const { res, unit } = shownInterpolation;
    const k = Number(coverage.value);
    const x = wavelengths(res.grid, res.spectrum.length);
    const u = res.uncertainty || {};
    const traces = [
      ...(u.interpolation?.length ? band(x, res.spectrum, u.combined, k, { id: 'combined', name: `± ${k}·u, ${combinedName(u)}, ${COVERAGE[k]}`, color: 'rgba(255, 127, 14, 0.25)' }) : []),
      ...band(x, res.spectrum, u.measurement, k, { id: 'measurement', name: `± ${k}·u, measurement only, ${COVERAGE[k]}`, color: 'rgba(31, 119, 180, 0.3)' }),
      { x, y: res.spectrum, name: 'interpolated', line: { width: 3, color: 'black' } },
    ];
    for (const v of res.vertices) {
      if (v.spectrum?.length) traces.push({ x, y: v.spectrum, name: `reading ${v.reading_id} (w ${v.weight.toFixed(2)})`, line: { dash: 'dot' } });
    }
    summarizeBands(u, res.spectrum, k);
    Plotly.react(interp, traces, { height: 340, margin: { t: 20 }, xaxis: { title: { text: 'wavelength nm' } }, yaxis: { title: { text: unit } } }, PLOT);
  }

  // One line above Figure 8: each band's median half-width relative to the spectrum (the bands
  // of a matte sample are thin at the plot's scale).
  function summarizeBands(u, y, k) {
    const parts = [['measurement', u.measurement]];
    if (u.interpolation?.length) parts.unshift([combinedName(u), u.combined]);
    const shown = parts.map(([what, v]) => [what, medianPercent(v, y, k)]).filter(([, p]) => p);
    bandSummary.textContent = shown.length ? `± ${k}·u, ${COVERAGE[k]}, median over the wavelengths: ${shown.map(([what, p]) => `${p} of the value (${what})`).join(', ')}` : 'no uncertainty estimated';
  }

  // BRDF along the plane of incidence at θi: θo from −85° (φ 0, the lamp's side) to 85° (φ 180,
  // the specular side), one batch; the slider picks the wavelength. Null when too little of it is
  // covered.
  async function planeOfIncidence(id, thetaI) {
    const angles = [];
    for (let a = -85; a <= 85; a += 5) angles.push(a);
    const directions = angles.map((a) => ({ iso: { theta_i: thetaI, theta_o: Math.abs(a), phi: a >= 0 ? 180 : 0 } }));
    // The paper's method where the readings enclose the direction; the nearest reading (said so
    // in the title) where a sparse grid leaves too little of the plane covered.
    let results = [];
    let used = '';
    for (const m of ['INTERPOLATION_METHOD_OCTANT', 'INTERPOLATION_METHOD_NEAREST']) {
      results = new Array(angles.length);
      try {
        await stream('Interpolation/InterpolateBatch', { session_id: id, method: m, quantity: 'QUANTITY_BRDF', directions, include_uncertainty: true }, (chunk) => {
          chunk.results.forEach((r, i) => { results[chunk.first_index + i] = r; });
        });
      } catch (e) { report(e.message); return null; }
      used = m.replace('INTERPOLATION_METHOD_', '').toLowerCase();
      if (results.filter((r) => r && r.status === 'INTERPOLATION_STATUS_OK').length >= 5) break;
    }
    const grid = results.find((r) => r && r.status === 'INTERPOLATION_STATUS_OK');
    if (!grid) return null;
    return { angles, results, grid: grid.grid, count: grid.spectrum.length, thetaI, used };
  }

  function drawPolar() {
    if (!polarData) return;
    const at = Number(slider.value); // the band (wavelength) shown
    const nm = polarData.grid.start_nm + at * polarData.grid.step_nm;
    sliderLabel.textContent = `${nm} nm`;
    const ok = polarData.results.map((r) => r && r.status === 'INTERPOLATION_STATUS_OK');
    const theta = polarData.angles.filter((_, i) => ok[i]).map((a) => a + 90);
    const results = polarData.results.filter((_, i) => ok[i]);
    const r = results.map((res) => res.spectrum[at]);
    Plotly.react(polar, [...polarBand(theta, r, results.map((res) => combinedAt(res.uncertainty, at))), { type: 'scatterpolar', mode: 'lines+markers', theta, r, name: `θi ${polarData.thetaI}°`, line: { color: BLUE }, marker: { color: BLUE } }],
      { height: 380, margin: { t: 30 }, title: { text: `BRDF (sr⁻¹) in the plane of incidence, θi ${polarData.thetaI}°, ${nm} nm (${polarData.used})` }, polar: { sector: [0, 180], angularaxis: { rotation: 180, direction: 'clockwise', tickvals: [0, 30, 60, 90, 120, 150, 180], ticktext: ['−90° lamp side', '−60°', '−30°', 'normal', '30°', '60°', '90° specular side'] } } }, PLOT);
  }

  // The band r ± k·u (combined) around the polar curve as one closed outline: the upper edge
  // out, the lower edge back, the lower at 0 at least (a BRDF is not negative, nor is a radius).
  // None unless every point has its uncertainty.
  function polarBand(theta, r, u) {
    if (!r.length || u.some((v) => !Number.isFinite(v))) return [];
    const k = Number(coverage.value);
    const upper = r.map((v, i) => v + k * u[i]);
    const lower = r.map((v, i) => Math.max(0, v - k * u[i])).reverse();
    return [{ type: 'scatterpolar', mode: 'lines', theta: [...theta, ...[...theta].reverse()], r: [...upper, ...lower], fill: 'toself', fillcolor: 'rgba(31, 119, 180, 0.25)', line: { width: 0 }, hoverinfo: 'skip', name: `± ${k}·u, ${COVERAGE[k]}`, meta: { band: 'combined', k, points: r.length } }];
  }
  slider.addEventListener('input', drawPolar);
  coverage.addEventListener('change', () => { drawReading(); drawInterpolation(); drawPolar(); uncertaintyMap.redraw(Number(coverage.value)); });
  uncertaintyMap.bind(() => ({ session, method: method.value, options: options(), points, k: Number(coverage.value) }));

  const EXPORTS = [
    ['EXPORT_FORMAT_READINGS_CSV', 'readings CSV'],
    ['EXPORT_FORMAT_GRID_NPY', 'grid .npy'],
    ['EXPORT_FORMAT_GRID_CSV', 'grid CSV'],
    ['EXPORT_FORMAT_MERL_BINARY', 'MERL .binary'],
    ['EXPORT_FORMAT_RGL_BSDF', 'RGL .bsdf (spectral)'],
    ['EXPORT_FORMAT_RGL_BSDF', 'RGL .bsdf (sRGB)', { rgb: true }, 'rgl_bsdf_rgb'],
  ];
  function renderDownloads() {
    clear(downloads);
    for (const [format, label, extra, id] of EXPORTS) {
      downloads.append(el('button', { id: `export-${id || format.replace('EXPORT_FORMAT_', '').toLowerCase()}`, onclick: () => download(format, extra) }, label));
    }
    showGridSize();
  }

  // A grid's size before it is asked for: cells of the chosen step × bands × 8 bytes (.npy).
  function showGridSize() {
    const d = Number(gridStep.value);
    const cells = (90 / d) * (90 / d) * (180 / d);
    const bands = polarData?.count ?? sessionBands.get(session);
    document.getElementById('grid-size').textContent = `${cells.toLocaleString('en')} cells` + (bands ? `, .npy ≈ ${(cells * bands * 8 / 1e6).toFixed(1)} MB` : '');
  }
  gridStep.addEventListener('change', showGridSize);

  // An export as the daemon streams it (Data.Export), kept in memory and handed to the browser
  // as a download. Grids use the step chosen; grids, MERL and RGL the Figure 8 form's options,
  // with reciprocity for MERL and RGL (a cell there stands for a pair of directions and its
  // swap alike, as brdfctl export does).
  async function download(format, extra = {}) {
    const parts = [];
    let reportMsg = null;
    const d = Number(gridStep.value);
    const gridded = format !== 'EXPORT_FORMAT_READINGS_CSV';
    const request = { session_id: session, format, ...extra };
    if (gridded) {
      request.method = method.value;
      request.options = { ...options(), reciprocity: format === 'EXPORT_FORMAT_MERL_BINARY' || format === 'EXPORT_FORMAT_RGL_BSDF' };
    }
    if (format === 'EXPORT_FORMAT_GRID_NPY' || format === 'EXPORT_FORMAT_GRID_CSV') Object.assign(request, { step_theta_i: d, step_theta_o: d, step_phi: d });
    downloadInfo.textContent = 'exporting…';
    try {
      await stream('Data/Export', request, (chunk) => {
        if (chunk.progress) downloadInfo.textContent = `${chunk.progress.stage} ${Math.round(100 * chunk.progress.fraction)} %`;
        if (chunk.data) parts.push(fromBase64(chunk.data.content));
        if (chunk.report) reportMsg = chunk.report;
      });
    } catch (e) { downloadInfo.textContent = e.message; return; }
    const blob = new Blob(parts, { type: 'application/octet-stream' });
    const a = el('a', { href: URL.createObjectURL(blob), download: reportMsg?.file_name || 'export' });
    document.body.append(a);
    a.click();
    a.remove();
    downloadInfo.textContent = `${reportMsg?.file_name}: ${blob.size} bytes. ${reportMsg?.summary || ''}`;
    downloadInfo.dataset.file = reportMsg?.file_name || '';
  }

  return {
    async show(listing) {
      await listSessions(listing);
      if (!session && sessionSelect.value) await load(sessionSelect.value);
    },
    hide() {},
  };
}
