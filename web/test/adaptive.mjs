// An adaptive session explained in the browser and in brdfctl (docs/adaptive.md, "Every choice
// explained"), headless Chromium (puppeteer-core) against a real brdfd on brdf-sim: a small
// adaptive plan runs to its reading budget, its prompts answered through the API, while the
// console shows it. The console's rounds table gains its rows live from WatchSession (one per
// round, none before the first), and ends with one row per stored round (Control.ListAdaptiveRounds)
// holding the uncertainty left the events carried, the chart's curve the same values against the
// target, the last round's poses listed; a page opened afterwards shows the same rounds from the
// store. The explorer's uncertainty map: k·u / BRDF at each direction equal to what
// Interpolation.Interpolate answers for it, halved at k = 1, the readings near its θi drawn.
// `brdfctl rounds` and `brdfctl watch` on the same session: a row per round, the stop, every
// line within 80 columns. A sample-fixed session: its rounds carry their poses' directions and the
// console lists those.
import { execFile } from 'node:child_process';
import { join } from 'node:path';
import { startRig, outputDir, check, build, launchBrowser, pageCollectingErrors, signIn } from './rig.mjs';

const out = outputDir();
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

const rig = await startRig({ timeScale: 40 });
async function post(method, body, token = rig.operatorToken) {
  const r = await fetch(new URL(`/api/brdf.v1.${method}`, rig.url), { method: 'POST', headers: { 'Content-Type': 'application/json', Authorization: `Bearer ${token}` }, body: JSON.stringify(body) });
  const text = await r.text();
  if (r.status !== 200) throw new Error(`${method}: ${r.status} ${text}`);
  return text.startsWith('event:') || text.startsWith('data:')
    ? text.split('\n\n').filter((b) => b.startsWith('data: ')).map((b) => JSON.parse(b.slice(6)))
    : JSON.parse(text);
}
function brdfctl(...args) {
  return new Promise((resolve) => execFile(join(build, 'tools/brdfctl/brdfctl'), ['--address', rig.grpc, ...args],
    { env: { ...process.env, BRDF_TOKEN: rig.analystToken } }, (err, stdout, stderr) => resolve({ code: err?.code ?? 0, stdout, stderr })));
}
const columns = (line) => [...line].length;
const close = (a, b, rel = 1e-6) => Math.abs(a - b) <= rel * Math.max(Math.abs(a), Math.abs(b), 1e-12);

// examples/plans/adaptive.json made small (as tests/daemon/sessions/adaptive_daemon_test.cc):
// three detector positions, a seed of 3 + 3 × 4, rounds of 6 to a budget of 33 readings.
const plan = {
  name: 'adaptive, explained',
  adaptive: {
    target: { expandedUncertainty: 0.001 },
    budget: { maxReadings: 33 },
    region: { thetaIMaxDeg: 80, thetaOMaxDeg: 80 },
    method: 'ADAPTIVE_JUDGE_OCTANT',
    delta: { start: 0, stop: 22.5, step: 11.25 },
    seed: { retroReadings: 3, readingsPerDelta: 4 },
    roundReadings: 6,
  },
  reference: { perDetectorPosition: true },
  measurement: { integrationMs: 100, averages: 1 },
};

let browser = null;
let failed = false;
try {
  const submitted = await post('Control/SubmitPlan', { plan });
  const id = submitted.session.session_id;
  browser = await launchBrowser();
  const errors = [];
  const page = await pageCollectingErrors(browser, errors);
  await signIn(page, rig.url, rig.operatorToken, 'operator');
  await page.waitForFunction(() => document.getElementById('session-state')?.textContent === 'queued');
  await page.waitForSelector('#rounds:not([hidden])');
  check(await page.$eval('#rounds-goal', (e) => e.textContent === 'target: U (k = 2) ≤ 0.001; budget: 33 readings'), `the console states the plan's target and budget (${await page.$eval('#rounds-goal', (e) => e.textContent)})`);
  check((await page.$$('#rounds-table tbody tr')).length === 0, 'no round before the session starts');

  // Run it, answering its prompts through the API; the page watches. The row count is sampled
  // as the rounds come: each appears without a reload.
  await post('Control/StartSession', { session_id: id });
  const rowCounts = new Set();
  const deadline = Date.now() + 150000;
  for (;;) {
    if (Date.now() > deadline) throw new Error('the adaptive session did not finish within 150 s');
    rowCounts.add(await page.$$eval('#rounds-table tbody tr', (r) => r.length));
    const s = await post('Control/GetSession', { session_id: id });
    if (s.state === 'SESSION_STATE_COMPLETED') break;
    if (['SESSION_STATE_FAILED', 'SESSION_STATE_ABORTED', 'SESSION_STATE_PAUSED'].includes(s.state)) throw new Error(`the session is ${s.state}: ${s.state_reason}`);
    if (s.state === 'SESSION_STATE_AWAITING_OPERATOR' && s.pending_prompt) {
      await rig.simMount(s.pending_prompt.kind);
      await post('Control/AnswerPrompt', { session_id: id, step_index: s.pending_prompt.step_index ?? 0 }).catch(() => {});
    }
    await sleep(100);
  }
  const stored = (await post('Control/ListAdaptiveRounds', { session_id: id }, rig.analystToken)).rounds;
  check(stored.length >= 2 && stored.every((r, i) => r.round === i + 1), `ListAdaptiveRounds gives the stored rounds in order (${stored.length})`);
  const seedSamples = Number(submitted.session.summary.sample_readings);
  check(stored.every((r, i) => r.spent_rig_s > 0 && r.rig_s > 0 && r.readings_used === (i === 0 ? seedSamples : stored[i - 1].readings_used + stored[i - 1].poses.length) && (i === 0 || close(r.spent_rig_s, stored[i - 1].spent_rig_s + stored[i - 1].rig_s, 1e-9))),
    `each round's spend is the one before plus that round's cost (${stored.map((r) => `${r.spent_rig_s.toFixed(0)} s + ${r.rig_s.toFixed(0)} s`).join(', ')})`);
  await page.waitForFunction((n) => document.querySelectorAll('#rounds-table tbody tr').length === n, { timeout: 15000 }, stored.length);
  await page.waitForFunction(() => /^stopped: /.test(document.getElementById('adaptive-stop').textContent), { timeout: 15000 });
  const seen = [...rowCounts].sort((a, b) => a - b);
  check(seen.includes(0) && seen.some((n) => n > 0 && n < stored.length), `the table gained its rows live, from the watch stream (row counts seen: ${seen.join(', ')})`);

  const rows = await page.$$eval('#rounds-table tbody tr', (r) => r.map((tr) => ({ round: Number(tr.dataset.round), left: Number(tr.dataset.left), cells: [...tr.children].map((td) => td.textContent) })));
  check(rows.length === stored.length && rows.every((r, i) => r.round === stored[i].round && r.left === stored[i].uncertainty_left && r.cells[7] === String(stored[i].poses.length)),
    `one row per stored round, with its uncertainty left and poses (${rows.map((r) => `${r.round}: ${r.cells[2]}`).join(', ')})`);
  const chart = await page.evaluate(() => document.getElementById('rounds-chart').data.map((t) => ({ series: t.meta?.series, y: t.y })));
  const curve = chart.find((t) => t.series === 'left');
  const target = chart.find((t) => t.series === 'target');
  check(curve && curve.y.length === stored.length && curve.y.every((v, i) => v === stored[i].uncertainty_left) && target.y.every((v) => v === 0.001),
    'the chart draws the uncertainty left per round against the target');
  const last = stored.at(-1);
  const nextPoses = await page.$$eval('#next-poses li', (l) => l.map((e) => e.textContent));
  check(nextPoses.length === Math.min(8, last.poses.length) && nextPoses[0].startsWith(`α ${Number(last.poses[0].alpha.toPrecision(6))}° β ${Number(last.poses[0].beta.toPrecision(6))}°`),
    `the last round's poses are listed (${nextPoses[0]})`);
  const stopText = await page.$eval('#adaptive-stop', (e) => e.textContent);
  check(/^stopped: reading budget spent; uncertainty left [\d.]+ \(target 0.001\) after \d+ round\(s\): \d+ of 33 readings/.test(stopText), `the stop is stated: ${stopText}`);
  await page.screenshot({ path: join(out, 'adaptive-01-console-rounds.png'), fullPage: true });

  // A page opened afterwards has the same rounds, from the store.
  const later = await pageCollectingErrors(browser, errors);
  await signIn(later, rig.url, rig.analystToken);
  await later.waitForFunction((n) => document.querySelectorAll('#rounds-table tbody tr').length === n, { timeout: 15000 }, stored.length);
  const laterLeft = await later.$$eval('#rounds-table tbody tr', (r) => r.map((tr) => Number(tr.dataset.left)));
  check(laterLeft.every((v, i) => v === stored[i].uncertainty_left), 'a page opened after the session shows the same rounds (from ListAdaptiveRounds)');
  await later.close();

  // The explorer's uncertainty map.
  await page.goto(`${rig.url}#explorer`);
  await page.waitForFunction(() => document.getElementById('umap').data?.some((t) => t.meta?.map === 'u'), { timeout: 60000 });
  const map = async () => page.evaluate(() => {
    const d = document.getElementById('umap').data;
    const u = d.find((t) => t.meta.map === 'u');
    return { k: u.meta.k, mirror: u.meta.mirror_phi, thetaI: u.meta.theta_i, r: u.r, theta: u.theta, c: u.marker.color, unknown: d.find((t) => t.meta.map === 'unknown').r.length, readings: d.find((t) => t.meta.map === 'readings').meta.ids };
  });
  const m2 = await map();
  check(m2.k === 2 && m2.mirror && m2.c.length >= 5 && m2.c.every((v) => Number.isFinite(v) && v > 0) && m2.c.length + m2.unknown === 18 * 19,
    `the map colours ${m2.c.length} of ${18 * 19} directions at θi ${m2.thetaI}° (${m2.unknown} unknown): ${await page.$eval('#umap-info', (e) => e.textContent)}`);
  // The colours are Interpolate's k·u / BRDF (u combined, both means over 400–700 nm).
  for (const i of [0, Math.floor(m2.c.length / 2), m2.c.length - 1]) {
    const res = (await post('Interpolation/Interpolate', { session_id: id, method: 'INTERPOLATION_METHOD_OCTANT', quantity: 'QUANTITY_BRDF', options: { coordinates: 'INTERPOLATION_COORDINATES_INCIDENCE', trend: 'INTERPOLATION_TREND_NONE', mirror_phi: true }, direction: { iso: { theta_i: m2.thetaI, theta_o: m2.r[i], phi: m2.theta[i] } }, include_uncertainty: true }, rig.analystToken)).result;
    let su = 0, sy = 0;
    res.spectrum.forEach((y, b) => { const nm = res.grid.start_nm + b * res.grid.step_nm; if (nm >= 400 && nm <= 700) { su += res.uncertainty.combined[b]; sy += y; } });
    check(res.status === 'INTERPOLATION_STATUS_OK' && close(m2.c[i], (2 * su) / sy), `θo ${m2.r[i]}°, φ ${m2.theta[i]}°: the map's ${m2.c[i].toFixed(5)} is Interpolate's 2·u/f ${((2 * su) / sy).toFixed(5)}`);
  }
  const points = await post('Data/StreamReadingPoints', { session_id: id, kinds: ['READING_KIND_SAMPLE'] }, rig.analystToken);
  const near = points.flatMap((c) => c.ids.filter((_, i) => Math.abs(c.theta_i[i] - m2.thetaI) <= 2.5));
  check(m2.readings.length === near.length && near.every((x) => m2.readings.includes(x)), `the readings within 2.5° of θi are drawn on the map (${near.length})`);
  await page.$eval('#coverage-k', (e) => { e.value = '1'; e.dispatchEvent(new Event('change')); });
  await page.waitForFunction(() => document.getElementById('umap').data.find((t) => t.meta.map === 'u').meta.k === 1);
  const m1 = await map();
  check(m1.c.every((v, i) => close(2 * v, m2.c[i], 1e-12)), 'k = 1 halves every colour value');
  await page.screenshot({ path: join(out, 'adaptive-02-explorer-map.png'), fullPage: true });
  check(errors.length === 0, `no errors in the browser${errors.length ? `: ${errors.join(' | ')}` : ''}`);

  // brdfctl on the same session.
  const table = await brdfctl('rounds', id);
  console.log(table.stdout, table.stderr);
  const lines = table.stdout.trimEnd().split('\n');
  const tableRows = lines.filter((l) => /^\s+\d+\s+\d+\s+[\d.e-]+\s/.test(l));
  check(table.code === 0 && tableRows.length === stored.length && tableRows.every((l, i) => l.trim().split(/\s+/)[0] === String(stored[i].round)) && /stopped: adaptive: reading budget spent/.test(table.stdout) && table.stdout.includes(`round ${stored.length} (from ${last.readings_used} of 33 readings)`),
    `brdfctl rounds: a row per round and the stop (${tableRows.length} rows)`);
  check(lines.every((l) => columns(l) <= 80), `brdfctl rounds: every line within 80 columns (widest ${Math.max(...lines.map(columns))})`);
  const watched = await brdfctl('watch', id);
  const wlines = watched.stdout.trimEnd().split('\n');
  console.log(watched.stdout, watched.stderr);
  check(watched.code === 0 && wlines.some((l) => l === `${stored.length} round(s) so far; uncertainty left ${stored.map((r) => Number(r.uncertainty_left.toPrecision(3))).join(' → ')}`) && wlines.some((l) => l === 'target U (k = 2) ≤ 0.001; budget 33 readings'),
    `brdfctl watch on the finished session: its goal and the uncertainty falling (${wlines.filter((l) => /round|adaptive/.test(l)).join(' | ')})`);
  const roundLines = wlines.filter((l) => /^(round \d|  |target |\d+ round\(s\)|adaptive stop)/.test(l));
  check(roundLines.length >= 6 && roundLines.every((l) => columns(l) <= 80), `brdfctl watch: the rounds' lines within 80 columns (${roundLines.length} lines)`);

  // The sample-fixed form: each pose is where the operator places lamp and detector by hand, so the
  // rounds carry each pose's directions and the console lists those, not the equivalent poses.
  const fixedPlan = {
    name: 'adaptive sample-fixed, explained',
    adaptive: {
      target: { expandedUncertainty: 0.001 },
      budget: { maxPrompts: 14 },
      region: { thetaIMaxDeg: 70, thetaOMaxDeg: 70 },
      seed: { retroReadings: 2 },
      sampleFixed: { seedReadings: 4 },
      roundReadings: 3,
    },
    reference: { perDetectorPosition: false, everyMinutes: 15 },
    measurement: { integrationMs: 100, averages: 1 },
  };
  const fixedId = (await post('Control/SubmitPlan', { plan: fixedPlan })).session.session_id;
  await post('Control/StartSession', { session_id: fixedId });
  const fixedDeadline = Date.now() + 120000;
  for (;;) {
    if (Date.now() > fixedDeadline) throw new Error('the sample-fixed session did not finish within 120 s');
    const s = await post('Control/GetSession', { session_id: fixedId });
    if (s.state === 'SESSION_STATE_COMPLETED') break;
    if (['SESSION_STATE_FAILED', 'SESSION_STATE_ABORTED', 'SESSION_STATE_PAUSED'].includes(s.state)) throw new Error(`the sample-fixed session is ${s.state}: ${s.state_reason}`);
    if (s.state === 'SESSION_STATE_AWAITING_OPERATOR' && s.pending_prompt) {
      await rig.simMount(s.pending_prompt.kind);
      await post('Control/AnswerPrompt', { session_id: fixedId, step_index: s.pending_prompt.step_index ?? 0 }).catch(() => {});
    }
    await sleep(100);
  }
  const fixedRounds = (await post('Control/ListAdaptiveRounds', { session_id: fixedId }, rig.analystToken)).rounds;
  const whole = (v) => Math.abs(v - Math.round(v)) < 1e-6;
  check(fixedRounds.length >= 1 && fixedRounds.every((r) => r.directions?.length === r.poses.length && r.directions.every((d) => whole(d.theta_i ?? 0) && whole(d.theta_o ?? 0))),
    `the sample-fixed rounds carry each pose's directions, whole degrees as the operator sets them (${fixedRounds.map((r) => r.directions?.length).join(', ')})`);
  const fixedPage = await pageCollectingErrors(browser, errors);
  await signIn(fixedPage, rig.url, rig.analystToken);
  // The sessions table is redrawn as it refreshes: click its row (again) until the session shows.
  await fixedPage.waitForFunction((sid, n) => {
    const row = document.querySelector(`tr[data-id="${sid}"]`);
    if (!row) return false;
    if (document.getElementById('rounds-where')?.textContent !== 'θi') {
      row.click();
      return false;
    }
    return document.querySelectorAll('#rounds-table tbody tr').length === n;
  }, { timeout: 15000, polling: 500 }, fixedId, fixedRounds.length);
  const lastFixed = fixedRounds.at(-1);
  const d0 = lastFixed.directions[0];
  let phi0 = Math.abs((d0.phi_o ?? 0) - (d0.phi_i ?? 0)) % 360;
  if (phi0 > 180) phi0 = 360 - phi0;
  if (Math.round(d0.theta_i ?? 0) === 0 || Math.round(d0.theta_o ?? 0) === 0) phi0 = 0;
  const fixedPoses = await fixedPage.$$eval('#next-poses li', (l) => l.map((e) => e.textContent));
  check(fixedPoses.length === Math.min(8, lastFixed.poses.length) && fixedPoses[0].startsWith(`θi ${Math.round(d0.theta_i ?? 0)}° θo ${Math.round(d0.theta_o ?? 0)}° φ ${Math.round(phi0)}°`),
    `the console lists the sample-fixed round's directions (${fixedPoses[0]})`);
  await fixedPage.screenshot({ path: join(out, 'adaptive-03-console-sample-fixed.png'), fullPage: true });
  await fixedPage.close();
  check(errors.length === 0, `no errors in the browser on the sample-fixed session${errors.length ? `: ${errors.join(' | ')}` : ''}`);
} catch (e) {
  failed = true;
  console.error(e.stack || e);
  try { console.error((await import('node:fs')).readFileSync(rig.daemonLog, 'utf8').slice(-3000)); } catch { /* best effort */ }
} finally {
  if (browser) { await Promise.race([browser.close().catch(() => {}), sleep(5000)]); browser.process()?.kill('SIGKILL'); }
  await rig.stop();
}
process.exit(failed ? 1 : 0);
