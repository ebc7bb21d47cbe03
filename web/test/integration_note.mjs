// A reading whose integration time the meter changed says so in the browser: brdf-sim overloads
// the first measurement (quality 19), the PR-650 driver halves the plan's 100 ms and measures
// again, and the console's readings view lists that reading with the 50 ms it used and the
// meter's note; the other readings are not listed. Headless Chromium (puppeteer-core) against a
// real brdfd on brdf-sim, as an analyst.
import { join } from 'node:path';
import { startRig, outputDir, check, launchBrowser, pageCollectingErrors, signIn } from './rig.mjs';

const out = outputDir();
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

const rig = await startRig({ timeScale: 40, simArgs: ['--serial-quality-code', '19', '--serial-quality-count', '1'] });
async function post(method, body) {
  const r = await fetch(new URL(`/api/brdf.v1.${method}`, rig.url), { method: 'POST', headers: { 'Content-Type': 'application/json', Authorization: `Bearer ${rig.operatorToken}` }, body: JSON.stringify(body) });
  const json = await r.json();
  if (r.status !== 200) throw new Error(`${method}: ${r.status} ${JSON.stringify(json)}`);
  return json;
}

let browser = null;
let failed = false;
try {
  // Two poses at 100 ms, a reference first; the operator's prompts answered through the API.
  const plan = {
    name: 'integration note', poseList: { poses: [{ alpha: 0, beta: 10, delta: 40 }, { alpha: 10, beta: 20, delta: 40 }] },
    measurement: { integrationMs: 100, averages: 1 }, retry: { maxAttempts: 2, backoffMs: 0 },
  };
  const id = (await post('Control/SubmitPlan', { plan, start_now: true })).session.session_id;
  const deadline = Date.now() + 60000;
  for (;;) {
    if (Date.now() > deadline) throw new Error('the session did not finish within a minute');
    const s = await post('Control/GetSession', { session_id: id });
    if (s.state === 'SESSION_STATE_COMPLETED') break;
    if (['SESSION_STATE_FAILED', 'SESSION_STATE_ABORTED', 'SESSION_STATE_PAUSED'].includes(s.state)) throw new Error(`the session is ${s.state}: ${s.state_reason}`);
    if (s.state === 'SESSION_STATE_AWAITING_OPERATOR' && s.pending_prompt) {
      await rig.simMount(s.pending_prompt.kind);
      await post('Control/AnswerPrompt', { session_id: id, step_index: s.pending_prompt.step_index ?? 0 });
    }
    await sleep(100);
  }
  check(true, `session ${id} completed`);

  browser = await launchBrowser();
  const errors = [];
  const page = await pageCollectingErrors(browser, errors);
  await signIn(page, rig.url, rig.analystToken, 'analyst');
  await page.waitForFunction(() => document.getElementById('session-state')?.textContent === 'completed', { timeout: 15000 });
  await page.waitForSelector('#integration-notes li[data-reading]', { timeout: 15000 });
  const items = await page.$$eval('#integration-notes li[data-reading]', (l) => l.map((e) => e.textContent));
  await page.screenshot({ path: join(out, 'integration-note.png'), fullPage: true });
  check(items.length === 1, `one reading listed as changed by the meter (${items.join(' | ')})`);
  check(/: 50 ms — quality 19 \(.*\): integration halved from 100 to 50 ms/.test(items[0]), `it says 50 ms and why: ${items[0]}`);
  check(errors.length === 0, `no errors in the browser console${errors.length ? `: ${errors.join(' | ')}` : ''}`);
} catch (e) {
  failed = true;
  console.error(e.stack || e);
} finally {
  if (browser) {
    await Promise.race([browser.close().catch(() => {}), sleep(5000)]);
    browser.process()?.kill('SIGKILL');
  }
  await rig.stop();
}
process.exit(failed ? 1 : 0);
