// The web front end served by brdf-archive, in a real browser: a real PostgreSQL (pg.mjs), a rig
// (brdf-sim and brdfd, rig.mjs) that records the demo plan and ships it to the archive, then
// brdf-archive with [web] listen and Debian's headless Chromium driven by puppeteer-core. The
// archive's console is read-only for every token (no plan, no rig, no control; the session's rig
// named; its history as the rig recorded it); the explorer draws Figure 7 from the archive,
// interpolates a direction (with its uncertainty bands) and downloads the readings CSV. No errors in the browser console.
// Screenshots go to $BRDF_TEST_OUTPUT_DIR/archive.
import puppeteer from 'puppeteer-core';
import { readFileSync, readdirSync, mkdirSync, mkdtempSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';
import { startRig, startArchive, outputDir, check, removeTestDir } from './rig.mjs';
import { startPostgres } from './pg.mjs';

const here = dirname(fileURLToPath(import.meta.url));
const demo = JSON.parse(readFileSync(join(here, '../../examples/plans/demo.json'), 'utf8'));
const out = join(outputDir(), 'archive');
mkdirSync(out, { recursive: true });
const chromium = process.env.BRDF_CHROMIUM || '/usr/bin/chromium';
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

async function api(base, token, method, body = {}) {
  const r = await fetch(new URL(`/api/brdf.v1.${method}`, base), { method: 'POST', headers: { 'Content-Type': 'application/json', Authorization: `Bearer ${token}` }, body: JSON.stringify(body) });
  const json = await r.json();
  if (!r.ok) throw new Error(`${method}: ${r.status} ${json.code} ${json.message}`);
  return json;
}

let pg = null;
let rig = null;
let archive = null;
let browser = null;
let failed = false;
let secrets = null;
const errors = [];
try {
  // --- the archive, a rig shipping to it, one recorded session --------------------------------
  pg = await startPostgres();
  secrets = mkdtempSync(join(tmpdir(), 'brdf-web-rig-'));
  const credentials = join(secrets, 'archive.conninfo');
  writeFileSync(credentials, `${pg.conninfo}\n`, { mode: 0o600 });
  rig = await startRig({ timeScale: 40, extraConfig: `[rig]\nname = "rig-web"\n[archive]\ncredentials = "${credentials}"\n` });
  const submitted = await api(rig.url, rig.operatorToken, 'Control/SubmitPlan', { plan: demo, start_now: true });
  const id = submitted.session.session_id;
  const uuid = submitted.session.uuid;
  const until = Date.now() + 120000;
  let s = submitted.session;
  while (s.state !== 'SESSION_STATE_COMPLETED') {
    if (Date.now() > until) throw new Error(`the demo session did not complete within 2 minutes (${s.state})`);
    if (['SESSION_STATE_FAILED', 'SESSION_STATE_ABORTED'].includes(s.state)) throw new Error(`the session ended ${s.state}: ${s.end_reason}`);
    if (s.state === 'SESSION_STATE_AWAITING_OPERATOR' && s.pending_prompt) {
      await rig.simMount(s.pending_prompt.kind);
      await api(rig.url, rig.operatorToken, 'Control/AnswerPrompt', { session_id: id, step_index: s.pending_prompt.step_index });
    }
    await sleep(100);
    s = await api(rig.url, rig.operatorToken, 'Control/GetSession', { session_id: id });
  }
  check(true, `the rig recorded session ${id} (${s.progress.done_samples} sample readings)`);
  const rigHistory = (await api(rig.url, rig.analystToken, 'Control/ListSessionEvents', { session_id: id })).events;

  archive = await startArchive({ conninfo: pg.conninfo, operatorToken: rig.operatorToken, analystToken: rig.analystToken });
  const about = await (await fetch(new URL('/api/about', archive.url))).json();
  check(about.server === 'brdf-archive', `GET /api/about on the archive: ${JSON.stringify(about)}`);
  // Shipped: the archive holds the session completed, with every reading and event.
  let shipped = null;
  for (const stop = Date.now() + 60000; ; await sleep(250)) {
    const list = await api(archive.url, rig.analystToken, 'Control/ListSessions', { page_size: 50 });
    const listed = list.sessions.find((x) => x.uuid === uuid);
    // The listing leaves out the sample counts (they need the steps); GetSession has them.
    shipped = listed && await api(archive.url, rig.analystToken, 'Control/GetSession', { session_id: listed.session_id });
    if (shipped && shipped.state === 'SESSION_STATE_COMPLETED' && shipped.progress.done_samples === s.progress.done_samples) {
      const events = (await api(archive.url, rig.analystToken, 'Control/ListSessionEvents', { session_id: shipped.session_id })).events;
      if (events.length === rigHistory.length) break;
    }
    if (Date.now() > stop) throw new Error(`the archive did not hold the completed session within 60 s (${JSON.stringify(shipped)}): ${readFileSync(rig.daemonLog, 'utf8').slice(-2000)}`);
  }
  check(shipped.rig === 'rig-web', `the archive holds session ${shipped.session_id} of rig "${shipped.rig}"`);

  // --- the browser -------------------------------------------------------------------------------
  browser = await puppeteer.launch({
    executablePath: chromium,
    headless: true,
    args: ['--no-sandbox', '--disable-dev-shm-usage', '--enable-unsafe-swiftshader', '--use-angle=swiftshader', '--window-size=1400,1000'],
    defaultViewport: { width: 1400, height: 1000 },
  });
  for (const [who, token] of [['operator', rig.operatorToken], ['analyst', rig.analystToken]]) {
    // The operator in the default context (downloads are allowed there), the analyst in its own.
    const context = who === 'operator' ? null : await browser.createBrowserContext();
    const page = await (context ?? browser).newPage();
    page.on('pageerror', (e) => errors.push(`${who}: page error: ${e.message}`));
    page.on('console', (m) => { if (m.type() === 'error') errors.push(`${who}: console: ${m.text()} ${m.location()?.url || ''}`); });
    await page.goto(archive.url, { waitUntil: 'load' });
    await page.waitForSelector('#login-view:not([hidden])');
    check(await page.$eval('header h1', (e) => e.textContent) === 'brdf-archive', `${who}: the page says it is the archive`);
    await page.type('#token', token);
    await page.click('#login-button');
    await page.waitForFunction(() => document.getElementById('who').textContent === 'reader');
    await page.waitForFunction(() => document.getElementById('session-state')?.textContent === 'completed', { timeout: 15000 });
    const row = await page.$$eval('#sessions tbody tr', (rows) => rows.map((r) => r.querySelector('.rig')?.textContent));
    check(row.includes('rig-web'), `${who}: the sessions list names the rig (${row.join(', ')})`);
    for (const sel of ['#plan-file', '#submit-plan', '#submit-start', '#rig', '#controls', '#start', '#pause-deferred', '#pause-immediate', '#resume', '#abort', '#answer-prompt']) {
      check((await page.$(sel)) === null, `${who}: no ${sel} on the archive`);
    }
    await page.waitForFunction((n) => document.querySelectorAll('#history-table tr[data-state]').length === n, { timeout: 15000 }, rigHistory.length);
    const history = await page.$$eval('#history-table tr[data-state]', (rows) => rows.map((r) => r.dataset.state));
    const expected = rigHistory.map((e) => e.state.replace('SESSION_STATE_', '').toLowerCase());
    check(history.join() === expected.join(), `${who}: the history is the rig's (${history.length} states, ${history[0]} … ${history.at(-1)})`);
    await page.waitForFunction(() => document.querySelectorAll('#coverage .point').length > 0, { timeout: 15000 });
    await page.screenshot({ path: join(out, `archive-console-${who}.png`), fullPage: true });
    if (context) { await context.close(); continue; }

    await page.goto(`${archive.url}#explorer`);
    await page.waitForFunction(() => /sample readings loaded/.test(document.getElementById('explorer-info')?.textContent || ''), { timeout: 30000 });
    const loaded = Number(/^(\d+) sample readings/.exec(await page.$eval('#explorer-info', (e) => e.textContent))[1]);
    check(loaded === s.progress.done_samples, `explorer: Figure 7 from the archive holds ${loaded} readings`);
    await page.evaluate(() => document.getElementById('interpolate').click());
    await page.waitForSelector('#interp-status');
    const status = await page.$eval('#interp-status', (e) => e.textContent);
    check(/wavelengths from \d+ readings/.test(status), `explorer: a direction interpolated by the archive: ${status}`);
    // With its uncertainty bands, from the budgets the rig shipped with the readings.
    const bands = await page.evaluate(() => document.getElementById('interp-spectrum').data.filter((t) => t.meta?.band).map((t) => t.meta.band).join());
    check(bands === 'combined,combined,measurement,measurement', `explorer: the archive's answer has its combined and measurement bands (${bands}; ${await page.$eval('#interp-bands', (e) => e.textContent)})`);
    await page.waitForSelector('#appearance-sphere-D65', { timeout: 60000 });
    const cdp = await page.createCDPSession();
    await cdp.send('Browser.setDownloadBehavior', { behavior: 'allow', downloadPath: out });
    await page.evaluate(() => document.getElementById('export-readings_csv').click());
    await page.waitForFunction(() => /bytes/.test(document.getElementById('download-info').textContent), { timeout: 30000 });
    let csv = null;
    for (let i = 0; i < 50 && !csv; i++) {
      csv = readdirSync(out).find((f) => f.endsWith('.csv'));
      if (!csv) await sleep(100);
    }
    const rows = csv ? readFileSync(join(out, csv), 'utf8').split('\n').filter((l) => l && !l.startsWith('#')).length - 1 : 0;
    check(rows === s.progress.done_samples, `explorer: the readings CSV downloaded from the archive has ${rows} rows (${csv})`);
    await page.screenshot({ path: join(out, 'archive-explorer.png'), fullPage: true });
    await page.close();
  }
  check(errors.length === 0, `no errors in the browser console${errors.length ? `: ${errors.join(' | ')}` : ''}`);
} catch (e) {
  failed = true;
  console.error(e.stack || e);
  if (errors.length) console.error('browser errors:', errors.join('\n'));
  if (archive) console.error(readFileSync(archive.log, 'utf8').slice(-3000));
} finally {
  if (browser) { await Promise.race([browser.close().catch(() => {}), sleep(5000)]); browser.process()?.kill('SIGKILL'); }
  for (const p of [archive, rig, pg]) if (p) await p.stop().catch(() => {});
  if (secrets) removeTestDir(secrets);
}
process.exit(failed ? 1 : 0);
