// The console and the explorer in a real browser: Debian's Chromium, headless, driven by
// puppeteer-core against a real brdfd on brdf-sim. As an operator: sign in, submit the demo plan
// from its file (validated, with the estimated time), watch progress move, answer the prompts
// (doing on the simulator what the prompt asks), pause and resume, then the explorer: Figure 7,
// a reading's spectrum (its BRDF with error bars from its stored budget), a direction's
// interpolated spectrum with its vertices (two methods) and its uncertainty bands (the gateway's
// numbers for the same direction; k = 1 and 2; nearest's not-estimated note), the plane of
// incidence with its band, the sample's colour and lit spheres (D65, A), an export downloaded. As an
// analyst: no control anywhere, and the server refuses one sent anyway. No errors in the browser
// console. Screenshots of every view go to $BRDF_TEST_OUTPUT_DIR.
import puppeteer from 'puppeteer-core';
import { readFileSync, readdirSync, existsSync } from 'node:fs';
import { join, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';
import { startRig, outputDir, check, signIn } from './rig.mjs';

const here = dirname(fileURLToPath(import.meta.url));
const demo = join(here, '../../examples/plans/demo.json');
const out = outputDir();
const chromium = process.env.BRDF_CHROMIUM || '/usr/bin/chromium';
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

const rig = await startRig({ timeScale: 30 });
const browser = await puppeteer.launch({
  executablePath: chromium,
  headless: true,
  args: ['--no-sandbox', '--disable-dev-shm-usage', '--enable-unsafe-swiftshader', '--use-angle=swiftshader', '--window-size=1400,1000'],
  defaultViewport: { width: 1400, height: 1000 },
});
const errors = [];
function watchErrors(page, who) {
  page.on('pageerror', (e) => errors.push(`${who}: page error: ${e.message}`));
  page.on('console', (m) => {
    if (m.type() !== 'error') return;
    errors.push(`${who}: console: ${m.text()} ${m.location()?.url || ''}`);
  });
}
const shot = (page, name) => page.screenshot({ path: join(out, `${name}.png`), fullPage: true });
// A click through the DOM: the console re-renders its session panel on every event, so an
// element handle may be stale by the time a mouse click would land.
const clickId = (page, id) => page.evaluate((i) => { const e = document.getElementById(i); if (!e) throw new Error(`no #${i}`); e.click(); }, id);
// The field names of an RGL tensor_file (docs/rgl-format.md: magic, version, count, then per
// field its name, dimensions, dtype, offset and shape).
function rglFields(b) {
  const names = [];
  let at = 14;
  const count = b.readUInt32LE(at);
  at += 4;
  for (let i = 0; i < count && at < b.length; i++) {
    const len = b.readUInt16LE(at);
    names.push(b.subarray(at + 2, at + 2 + len).toString('utf8'));
    const dims = b.readUInt16LE(at + 2 + len);
    at += 2 + len + 2 + 1 + 8 + 8 * dims;
  }
  return names;
}
// Text a view must never show: a value the page failed to fill in.
async function checkNoPlaceholders(page, view) {
  const shown = await page.evaluate(() => document.querySelector('main').innerText);
  const bad = /\b(null|undefined|NaN|\[object Object\])\b/.exec(shown);
  check(!bad, `${view}: no "null", "undefined", "NaN" or "[object Object]" shown${bad ? ` (found "${bad[0]}" in …${shown.slice(Math.max(0, bad.index - 60), bad.index + 20)}…)` : ''}`);
}
const text = (page, sel) => page.$eval(sel, (e) => e.textContent).catch(() => null);
// The gateway asked directly (as the analyst), for the numbers a plot must show: a unary call's
// JSON, or a stream's messages.
async function gateway(method, body, streamed = false) {
  const r = await fetch(new URL(`/api/brdf.v1.${method}`, rig.url), { method: 'POST', headers: { 'Content-Type': 'application/json', Authorization: `Bearer ${rig.analystToken}` }, body: JSON.stringify(body) });
  const answer = await r.text();
  if (r.status !== 200) throw new Error(`${method}: ${r.status} ${answer}`);
  return streamed ? answer.split('\n\n').filter((b) => b.startsWith('data: ')).map((b) => JSON.parse(b.slice(6))) : JSON.parse(answer);
}
// Equal to the last few digits (the page computes y ± k·u, the test k·u from the same doubles).
const close = (a, b) => Math.abs(a - b) <= 1e-9 * Math.max(Math.abs(a), Math.abs(b), 1e-12);
// Figure 8's bands as drawn: per band (meta.band), its coverage factor, legend name and
// half-widths (upper − lower) / 2 per wavelength.
const figure8Bands = (page) => page.evaluate(() => {
  const out = {};
  for (const t of document.getElementById('interp-spectrum').data.filter((d) => d.meta?.band)) {
    const b = (out[t.meta.band] ??= { k: t.meta.k });
    b[t.meta.edge] = t.y;
    if (t.meta.edge === 'upper') b.name = t.name;
  }
  for (const b of Object.values(out)) b.half = b.upper.map((u, i) => (u - b.lower[i]) / 2);
  return out;
});
const setCoverage = (page, k) => page.$eval('#coverage-k', (e, v) => { e.value = v; e.dispatchEvent(new Event('change')); }, String(k));

// Figure 8 asked again with the form as it is.
async function interpolateAgain(page) {
  await page.evaluate(() => { document.getElementById('interp-status')?.remove(); });
  await clickId(page, 'interpolate');
  await page.waitForSelector('#interp-status');
}

// Figure 8 with the paper's method: bands ± k·u whose half-widths are k times the gateway's
// combined and measurement uncertainties for the same direction, finite and non-negative; k = 1
// halves them; the nearest method draws the measurement band alone and says why, a reflectance
// answer the interpolation term's alone.
async function checkFigure8Bands(page, sessionId) {
  await page.select('#method', 'INTERPOLATION_METHOD_OCTANT');
  await interpolateAgain(page);
  const iso = await page.evaluate(() => ({ theta_i: Number(document.getElementById('q-theta-i').value), theta_o: Number(document.getElementById('q-theta-o').value), phi: Number(document.getElementById('q-phi').value) }));
  const request = { session_id: sessionId, method: 'INTERPOLATION_METHOD_OCTANT', quantity: 'QUANTITY_BRDF', options: { coordinates: 'INTERPOLATION_COORDINATES_INCIDENCE', trend: 'INTERPOLATION_TREND_NONE' }, direction: { iso }, include_uncertainty: true };
  const u = (await gateway('Interpolation/Interpolate', request)).result.uncertainty;
  const k2 = await figure8Bands(page);
  for (const part of ['combined', 'measurement']) {
    const b = k2[part];
    check(b && b.k === 2 && b.name.includes('k = 2 (≈95 %)') && b.half.length === u[part].length && b.half.every((h, i) => Number.isFinite(h) && h >= 0 && close(h, 2 * u[part][i])) && b.half.some((h) => h > 0),
      `Figure 8's ${part} band: half-widths 2·u for every one of ${b?.half.length} bands, as the gateway answers (legend "${b?.name}")`);
  }
  check(k2.combined.half.every((h, i) => h >= k2.measurement.half[i] - 1e-15), 'the measurement band lies inside the combined one');
  const summary = await text(page, '#interp-bands');
  check(/^± 2·u, k = 2 \(≈95 %\), median over the wavelengths: [\d.]+ % of the value \(measurement and interpolation\), [\d.]+ % of the value \(measurement\)$/.test(summary), `the bands' median widths are stated: ${summary}`);
  await shot(page, '07a-explorer-bands-k2');
  await setCoverage(page, 1);
  const k1 = await figure8Bands(page);
  check(['combined', 'measurement'].every((p) => k1[p].k === 1 && k1[p].name.includes('k = 1 (≈68 %)') && k1[p].half.every((h, i) => close(2 * h, k2[p].half[i]))), 'k = 1 halves both bands\' half-widths');
  await setCoverage(page, 2);
  await page.select('#method', 'INTERPOLATION_METHOD_NEAREST');
  await interpolateAgain(page);
  const nearest = await figure8Bands(page);
  const notes = await page.$$eval('#interp-not-estimated li', (l) => l.map((e) => e.textContent));
  check(Object.keys(nearest).join() === 'measurement' && notes.some((t) => /^interpolation: the nearest method/.test(t)), `nearest: the measurement band alone, the interpolation term named as not estimated (${notes.length} notes)`);
  await page.select('#method', 'INTERPOLATION_METHOD_OCTANT');
  await page.select('#quantity', 'QUANTITY_REFLECTANCE');
  await interpolateAgain(page);
  const reflectance = await figure8Bands(page);
  const why = await page.$$eval('#interp-not-estimated li', (l) => l.map((e) => e.textContent));
  check(Object.keys(reflectance).join() === 'combined' && /interpolation only/.test(reflectance.combined.name) && reflectance.combined.half.some((h) => h > 0) && why.some((t) => /^measurement: the readings' budgets are of the BRDF/.test(t)),
    `reflectance: the interpolation term's band alone, the measurement part named as not estimated (${reflectance.combined?.name})`);
  await page.select('#quantity', 'QUANTITY_BRDF');
}

// The polar plot's band ± k·u (combined) around its curve: a closed outline around every point,
// finite, its upper edge at or above the curve; k = 1 halves its distance from the curve.
async function checkPolarBand(page) {
  const polarBand = () => page.evaluate(() => {
    const d = document.getElementById('polar').data;
    const b = d.find((t) => t.meta?.band === 'combined');
    const curve = d.find((t) => !t.meta?.band);
    return b && { fill: b.fill, k: b.meta.k, name: b.name, above: curve.r.map((r, i) => b.r[i] - r), r: b.r, n: curve.r.length };
  });
  const k2 = await polarBand();
  check(k2 && k2.fill === 'toself' && k2.r.length === 2 * k2.n && k2.r.every((r) => Number.isFinite(r) && r >= 0) && k2.above.every((a) => a >= 0) && k2.above.some((a) => a > 0) && k2.name.includes('k = 2 (≈95 %)'),
    `the polar plot has its band around the ${k2?.n} points (${k2?.name})`);
  await setCoverage(page, 1);
  const k1 = await polarBand();
  check(k1.k === 1 && k1.above.every((a, i) => close(2 * a, k2.above[i])), 'k = 1 halves the polar band\'s distance above the curve');
  await setCoverage(page, 2);
}

let failed = false;
try {
  // --- operator -------------------------------------------------------------------------------
  const page = await browser.newPage();
  watchErrors(page, 'operator');
  await page.goto(rig.url, { waitUntil: 'load' });
  await page.waitForSelector('#login-view:not([hidden])');
  await shot(page, '01-login');
  await page.type('#token', 'wrong-token-wrong-token');
  await page.click('#login-button');
  await page.waitForFunction(() => document.getElementById('login-error').textContent.length > 0);
  check(/not known/.test(await text(page, '#login-error')), 'a wrong token is refused at sign-in');
  // The server refuses that token once (the sign-in asks who it is only after the listing
  // passed), and Chromium logs the refusal as a failed load: exactly that one error, then none.
  const refusals = errors.filter((e) => /status of 401/.test(e));
  check(errors.length === 1 && refusals.length === 1 && refusals[0].includes('Control/ListSessions'), `a wrong token is refused once, by the listing (${errors.join(' | ')})`);
  errors.length = 0;
  await page.type('#token', rig.operatorToken);
  await page.click('#login-button');
  await page.waitForFunction(() => document.getElementById('who').textContent === 'operator');
  check(await page.evaluate(() => sessionStorage.getItem('brdfd.token') !== null && localStorage.length === 0), 'the token is kept in sessionStorage only');

  const input = await page.waitForSelector('#plan-file');
  await input.uploadFile(demo);
  await page.waitForSelector('#plan-valid');
  const valid = await text(page, '#plan-valid');
  check(/estimated/.test(valid), `the plan file is validated: ${valid}`);
  await shot(page, '02-console-plan-validated');
  await clickId(page, 'submit-start');
  await page.waitForFunction(() => ['running', 'awaiting_operator', 'queued'].includes(document.getElementById('session-state')?.textContent));

  let prompts = 0;
  let paused = false;
  let resumed = false;
  let lastProgress = -1;
  let progressMoves = 0;
  const deadline = Date.now() + 120000;
  for (;;) {
    if (Date.now() > deadline) throw new Error('the demo session did not finish within 2 minutes');
    const state = await text(page, '#session-state');
    if (state === 'completed') break;
    if (['failed', 'aborted'].includes(state)) throw new Error(`the session ended ${state}`);
    const p = await page.$eval('#session-progress', (e) => Number(e.value)).catch(() => lastProgress);
    if (p > lastProgress) { if (lastProgress >= 0) progressMoves++; lastProgress = p; }
    const prompt = await page.$('#answer-prompt');
    if (prompt && state === 'awaiting_operator') {
      const kind = await page.$eval('#prompt', (e) => e.dataset.kind);
      const step = await page.$eval('#prompt', (e) => e.dataset.step);
      if (prompts === 0) await shot(page, '03-console-prompt');
      await rig.simMount(kind);
      await clickId(page, 'answer-prompt');
      prompts++;
      await page.waitForFunction((s) => document.getElementById('prompt')?.dataset.step !== s, { timeout: 15000 }, step);
      continue;
    }
    if (!paused && state === 'running' && progressMoves >= 2 && prompts >= 1) {
      await clickId(page, 'pause-deferred');
      await page.waitForFunction(() => document.getElementById('session-state')?.textContent === 'paused', { timeout: 30000 });
      paused = true;
      const before = await page.$eval('#session-progress', (e) => Number(e.value));
      await sleep(1500);
      const after = await page.$eval('#session-progress', (e) => Number(e.value));
      check(before === after, 'no progress while paused');
      await shot(page, '04-console-paused');
      await clickId(page, 'resume');
      await page.waitForFunction(() => document.getElementById('session-state')?.textContent !== 'paused', { timeout: 15000 });
      resumed = true;
      continue;
    }
    await sleep(150);
  }
  check(true, 'the demo session completed');
  check(prompts >= 1, `prompts answered in the browser: ${prompts}`);
  check(progressMoves >= 3, `progress moved live ${progressMoves} times`);
  check(paused && resumed, 'paused (deferred) and resumed from the browser');
  await page.waitForFunction(() => document.querySelectorAll('#coverage .scatterlayer .point, #coverage .point').length > 0, { timeout: 15000 });
  check((await page.$$eval('#events li', (l) => l.length)) > 5, 'the session\'s events are listed');
  check(/connected/.test(await text(page, '#rig')), 'the rig status shows the devices');
  // The durable history (Control.ListSessionEvents), in the order the rig recorded it.
  await page.waitForFunction(() => [...document.querySelectorAll('#history-table tr[data-state]')].at(-1)?.dataset.state === 'completed', { timeout: 15000 });
  const history = await page.$$eval('#history-table tr[data-state]', (rows) => rows.map((r) => r.dataset.state));
  const order = (s) => history.indexOf(s);
  check(history[0] === 'queued' && order('running') > 0 && order('awaiting_operator') > order('running') &&
        order('paused') > order('awaiting_operator') && history.lastIndexOf('running') > order('paused'),
  `the session's history lists its states in order (${history.join(' → ')})`);
  // The rig's status once it has no active session (it is polled every 2 s).
  await page.waitForFunction(() => !/active session/.test(document.getElementById('rig').textContent), { timeout: 15000 });
  await checkNoPlaceholders(page, 'console');
  await shot(page, '05-console-completed');

  // --- explorer ---------------------------------------------------------------------------------
  // Figure 7 gets its points through the compact listing (Data.StreamReadingPoints: poses and
  // directions as columns, no spectra), never one full reading per event.
  const apiCalls = [];
  const onRequest = (r) => { const m = /\/api\/brdf\.v1\.([A-Za-z]+\/[A-Za-z]+)/.exec(r.url()); if (m) apiCalls.push(m[1]); };
  page.on('request', onRequest);
  await page.goto(`${rig.url}#explorer`);
  const t0 = Date.now();
  await page.waitForFunction(() => /sample readings loaded/.test(document.getElementById('explorer-info')?.textContent || ''), { timeout: 30000 });
  await page.waitForSelector('#fig7-iso canvas');
  console.log(`explorer: first view in ${Date.now() - t0} ms (${await text(page, '#explorer-info')})`);
  page.off('request', onRequest);
  check(apiCalls.includes('Data/StreamReadingPoints') && !apiCalls.includes('Data/StreamReadings'), `Figure 7's readings come from Data/StreamReadingPoints (calls: ${[...new Set(apiCalls)].join(', ')})`);
  const loaded = Number(/^(\d+) sample readings/.exec(await text(page, '#explorer-info'))[1]);
  const plotted = await page.evaluate(() => [document.getElementById('fig7-pose').points3d.count, document.getElementById('fig7-iso').points3d.count]);
  check(loaded > 0 && plotted[0] === loaded && plotted[1] === loaded, `both Figure 7 plots hold every sample reading (${plotted.join(', ')} of ${loaded})`);
  // A real click on a reading's point in the (θi, θo, φ) plot (where the camera projects it).
  const at = await page.evaluate(() => document.getElementById('fig7-iso').points3d.screenPosition(5));
  await page.mouse.click(at.x, at.y);
  await page.waitForFunction(() => document.querySelectorAll('#reading-spectrum .scatterlayer .trace').length >= 2, { timeout: 15000 });
  check(/^reading \d+: α/.test(await text(page, '#reading-info')), `a click on a point shows its reading's spectrum (${await text(page, '#reading-info')})`);
  // Its BRDF with error bars ± k·u_c from the budget stored with the reading (Reading.uncertainty).
  await page.waitForFunction(() => document.getElementById('reading-spectrum').data?.some((t) => t.error_y?.array?.length), { timeout: 15000 });
  const clickedId = /^reading (\d+):/.exec(await text(page, '#reading-info'))[1];
  const sessionId = await page.$eval('#explorer-session', (e) => e.value);
  const stored = (await gateway('Data/StreamReadings', { session_id: sessionId, kinds: ['READING_KIND_SAMPLE'] }, true)).find((m) => m.id === clickedId)?.uncertainty;
  const bars = await page.evaluate(() => document.getElementById('reading-spectrum').data.filter((t) => t.error_y?.array).map((t) => ({ name: t.name, array: t.error_y.array })));
  check(stored?.combined?.length > 0 && bars.length === 1 && /^BRDF .* ± 2·u, k = 2 \(≈95 %\)$/.test(bars[0].name) && bars[0].array.length === stored.combined.length && bars[0].array.every((v, i) => Number.isFinite(v) && v >= 0 && close(v, 2 * stored.combined[i])),
    `reading ${clickedId}'s BRDF has error bars 2·u_c from its stored budget (${bars[0]?.name}; ${bars[0]?.array.length} bands)`);
  await shot(page, '06-explorer-figure7');

  for (const method of ['INTERPOLATION_METHOD_OCTANT', 'INTERPOLATION_METHOD_DELAUNAY']) {
    await page.select('#method', method);
    await page.evaluate(() => { document.getElementById('interp-status')?.remove(); });
    await clickId(page, 'interpolate');
    await page.waitForSelector('#interp-status');
    const status = await text(page, '#interp-status');
    check(/wavelengths from \d+ readings/.test(status), `${method}: ${status}`);
    const rows = await page.$$eval('#vertices tr', (r) => r.length - 1);
    check(rows >= 1, `${method}: ${rows} vertices with weights`);
    await page.waitForFunction(() => document.querySelectorAll('#interp-spectrum .scatterlayer .trace').length >= 2, { timeout: 15000 });
    const traces = await page.$$eval('#interp-spectrum .scatterlayer .trace', (t) => t.length);
    check(traces === rows + 1 + 4, `${method}: the interpolated spectrum, each vertex's own spectrum and two bands of two edges each drawn (${traces} traces for ${rows} vertices)`);
  }
  // The bivariate trend: the same direction, the vertices' residuals blended on top of the trend.
  await page.select('#trend', 'INTERPOLATION_TREND_BIVARIATE');
  await page.evaluate(() => { document.getElementById('interp-status')?.remove(); });
  await clickId(page, 'interpolate');
  await page.waitForSelector('#interp-status');
  const trended = await text(page, '#interp-status');
  check(/wavelengths from \d+ readings.*trend/.test(trended), `Delaunay with the bivariate trend: ${trended}`);
  await page.select('#trend', 'INTERPOLATION_TREND_NONE');
  await checkFigure8Bands(page, sessionId);
  await page.waitForSelector('#polar .scatterlayer .trace, #polar .trace');
  const nm0 = await text(page, '#wavelength-label');
  await page.$eval('#wavelength', (e) => { e.value = '5'; e.dispatchEvent(new Event('input')); });
  check((await text(page, '#wavelength-label')) !== nm0, `the wavelength slider redraws the polar plot (${nm0} → ${await text(page, '#wavelength-label')})`);
  await checkPolarBand(page);
  await shot(page, '07-explorer-direction-polar');

  // The sample's colour and lit spheres under D65 and A (Interpolation/RenderAppearance), drawn
  // to canvases from the session's BRDF.
  await page.waitForSelector('#appearance-sphere-D65', { timeout: 30000 });
  await page.waitForSelector('#appearance-sphere-A');
  const look = await page.evaluate(() => {
    const pixels = (id) => { const c = document.getElementById(id); return c.getContext('2d').getImageData(0, 0, c.width, c.height).data; };
    const sphere = (id) => {
      const d = pixels(id);
      let lit = 0, transparent = 0, r = 0, b = 0;
      for (let i = 0; i < d.length; i += 4) {
        if (d[i + 3] === 0) transparent++;
        else if (d[i] + d[i + 1] + d[i + 2] > 30) { lit++; r += d[i]; b += d[i + 2]; }
      }
      return { lit, transparent, redOverBlue: r / b, size: document.getElementById(id).width };
    };
    const swatch = Array.from(pixels('appearance-swatch-D65').slice(0, 3));
    return { d65: sphere('appearance-sphere-D65'), a: sphere('appearance-sphere-A'), swatch, caption: document.getElementById('appearance-colour-D65').textContent };
  });
  console.log(`appearance: ${look.caption}; D65 sphere ${look.d65.lit} lit pixels, r/b ${look.d65.redOverBlue.toFixed(2)}; A r/b ${look.a.redOverBlue.toFixed(2)}`);
  check(look.swatch.some((v) => v > 10) && !/#000000/.test(look.caption) && /x 0\.\d+, y 0\.\d+/.test(look.caption), `the D65 swatch is not black (${look.swatch.join(', ')}; ${look.caption})`);
  check(look.d65.lit > look.d65.size * look.d65.size / 8 && look.d65.transparent > 0, `the D65 sphere has lit pixels (${look.d65.lit}) and is transparent outside its disc`);
  check(look.a.redOverBlue > look.d65.redOverBlue, `the sphere is redder under illuminant A (r/b ${look.a.redOverBlue.toFixed(2)} > ${look.d65.redOverBlue.toFixed(2)})`);
  await (await page.$('#appearance')).screenshot({ path: join(out, '10-explorer-appearance.png') });

  const cdp = await page.createCDPSession();
  await cdp.send('Browser.setDownloadBehavior', { behavior: 'allow', downloadPath: out });
  await clickId(page, 'export-readings_csv');
  await page.waitForFunction(() => /bytes/.test(document.getElementById('download-info').textContent), { timeout: 30000 });
  let csv = null;
  for (let i = 0; i < 50 && !csv; i++) {
    csv = readdirSync(out).find((f) => f.endsWith('.csv'));
    if (!csv) await sleep(100);
  }
  check(csv && readFileSync(join(out, csv), 'utf8').split('\n').length > 10, `the readings CSV export downloaded (${csv})`);
  // The spectral RGL material, for Mitsuba 3 and pbrt-v4: a tensor_file with the spectral fields.
  await page.evaluate(() => { document.getElementById('download-info').dataset.file = ''; });
  await clickId(page, 'export-rgl_bsdf');
  await page.waitForFunction(() => /\.bsdf$/.test(document.getElementById('download-info').dataset.file || ''), { timeout: 120000 });
  const bsdfName = await page.$eval('#download-info', (e) => e.dataset.file);
  let bsdf = null;
  for (let i = 0; i < 100 && !bsdf; i++) {
    if (existsSync(join(out, bsdfName))) bsdf = readFileSync(join(out, bsdfName));
    else await sleep(100);
  }
  const fields = bsdf ? rglFields(bsdf) : [];
  check(bsdf && bsdf.subarray(0, 12).toString('latin1') === 'tensor_file\0' && ['wavelengths', 'spectra', 'ndf', 'vndf'].every((f) => fields.includes(f)),
    `the spectral RGL .bsdf downloaded (${bsdfName}, ${bsdf?.length} bytes; fields ${fields.join(', ')})`);
  await checkNoPlaceholders(page, 'explorer');
  await shot(page, '11-explorer-downloads');

  // --- analyst ----------------------------------------------------------------------------------
  const queued = await fetch(new URL('/api/brdf.v1.Control/SubmitPlan', rig.url), { method: 'POST', headers: { 'Content-Type': 'application/json', Authorization: `Bearer ${rig.operatorToken}` }, body: JSON.stringify({ plan: JSON.parse(readFileSync(demo, 'utf8')) }) }).then((r) => r.json());
  const context = await browser.createBrowserContext();
  const analyst = await context.newPage();
  watchErrors(analyst, 'analyst');
  await signIn(analyst, rig.url, rig.analystToken, 'analyst');
  await analyst.waitForFunction(() => document.getElementById('session-state')?.textContent === 'queued');
  for (const sel of ['#submit-plan', '#submit-start', '#controls', '#start', '#pause-deferred', '#pause-immediate', '#resume', '#abort', '#answer-prompt']) {
    check((await analyst.$(sel)) === null, `analyst: no ${sel}`);
  }
  // A control call sent anyway with the analyst's token (from outside the page, so that the
  // refusal is not a console error of the page's own).
  const analystToken = await analyst.evaluate(() => sessionStorage.getItem('brdfd.token'));
  const refused = await fetch(new URL('/api/brdf.v1.Control/StartSession', rig.url), { method: 'POST', headers: { 'Content-Type': 'application/json', Authorization: `Bearer ${analystToken}` }, body: JSON.stringify({ session_id: queued.session.session_id }) });
  check(refused.status === 403, `analyst: a control call sent anyway is refused by the server (${refused.status})`);
  await shot(analyst, '08-analyst-console');
  await analyst.goto(`${rig.url}#explorer`);
  await analyst.waitForSelector('#explorer-session option');
  // The session list says each measured session's grid (Session.grid): the PR-650's 101 bands.
  const options = await analyst.$$eval('#explorer-session option', (os) => os.map((o) => o.textContent));
  check(options.some((o) => /, 101 bands\)$/.test(o)), `a measured session shows its grid's bands (${options.join(' | ')})`);
  await shot(analyst, '09-analyst-explorer');
  check(errors.length === 0, `no errors in the browser console${errors.length ? `: ${errors.join(' | ')}` : ''}`);
} catch (e) {
  failed = true;
  console.error(e.stack || e);
  console.error('browser errors:', errors.join('\n'));
  console.error(readFileSync(rig.daemonLog, 'utf8').slice(-3000));
  try { for (const p of await browser.pages()) await p.screenshot({ path: join(out, `failure-${Date.now()}.png`), fullPage: true }); } catch { /* best effort */ }
} finally {
  const t = Date.now();
  await Promise.race([browser.close().catch(() => {}), sleep(5000)]);
  browser.process()?.kill('SIGKILL');
  await rig.stop();
  console.log(`teardown ${Date.now() - t} ms`);
}
process.exit(failed ? 1 : 0);
