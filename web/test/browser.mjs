// The console and the explorer in a real browser: Debian's Chromium, headless, driven by
// puppeteer-core against a real brdfd on brdf-sim. As an operator: sign in, submit the demo plan
// from its file (validated, with the estimated time), watch progress move, answer the prompts
// (doing on the simulator what the prompt asks), pause and resume, then the explorer: Figure 7,
// a reading's spectrum, a direction's interpolated spectrum with its vertices (two methods), the
// plane of incidence, the sample's colour and lit spheres (D65, A), an export downloaded. As an
// analyst: no control anywhere, and the server refuses one sent anyway. No errors in the browser
// console. Screenshots of every view go to $BRDF_TEST_OUTPUT_DIR.
import puppeteer from 'puppeteer-core';
import { readFileSync, readdirSync, existsSync } from 'node:fs';
import { join, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';
import { startRig, outputDir, check } from './rig.mjs';

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
    check(traces === rows + 1, `${method}: the interpolated spectrum and each vertex's own spectrum drawn (${traces} traces for ${rows} vertices)`);
  }
  // The bivariate trend: the same direction, the vertices' residuals blended on top of the trend.
  await page.select('#trend', 'INTERPOLATION_TREND_BIVARIATE');
  await page.evaluate(() => { document.getElementById('interp-status')?.remove(); });
  await clickId(page, 'interpolate');
  await page.waitForSelector('#interp-status');
  const trended = await text(page, '#interp-status');
  check(/wavelengths from \d+ readings.*trend/.test(trended), `Delaunay with the bivariate trend: ${trended}`);
  await page.select('#trend', 'INTERPOLATION_TREND_NONE');
  await page.waitForSelector('#polar .scatterlayer .trace, #polar .trace');
  const nm0 = await text(page, '#wavelength-label');
  await page.$eval('#wavelength', (e) => { e.value = '5'; e.dispatchEvent(new Event('input')); });
  check((await text(page, '#wavelength-label')) !== nm0, `the wavelength slider redraws the polar plot (${nm0} → ${await text(page, '#wavelength-label')})`);
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
  await analyst.goto(rig.url);
  await analyst.waitForSelector('#login-view:not([hidden])');
  await analyst.type('#token', rig.analystToken);
  await analyst.click('#login-button');
  await analyst.waitForFunction(() => document.getElementById('who').textContent === 'analyst');
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
