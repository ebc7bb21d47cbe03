// The web gateway probed like the gRPC API, over real HTTP against a real brdfd on brdf-sim: no
// token, a wrong token, the wrong role, oversized and malformed requests, unknown methods, a
// stream refused before its first event, security headers, no inline script, no CORS, and the
// uncertainties (include_uncertainty, Reading.uncertainty) mapped to JSON and back.
import { readFileSync } from 'node:fs';
import { join, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';
import net from 'node:net';
import { startRig, check } from './rig.mjs';

const here = dirname(fileURLToPath(import.meta.url));
const rig = await startRig();
const api = (m) => new URL(`/api/brdf.v1.${m}`, rig.url).href;
async function post(method, body, token, extra = {}) {
  const headers = { 'Content-Type': 'application/json', ...(token ? { Authorization: `Bearer ${token}` } : {}), ...(extra.headers || {}) };
  const r = await fetch(api(method), { method: 'POST', headers, body: typeof body === 'string' ? body : JSON.stringify(body) });
  const text = await r.text();
  let json = null;
  try { json = JSON.parse(text); } catch { /* not JSON */ }
  return { status: r.status, json, text, headers: r.headers };
}
// A stream's messages (a stream that ends by itself), read whole: each event's data as JSON.
async function messages(method, body, token) {
  const r = await post(method, body, token);
  if (r.status !== 200) throw new Error(`${method}: ${r.status} ${r.text}`);
  return r.text.split('\n\n').filter((b) => b.startsWith('data: ')).map((b) => JSON.parse(b.slice(6)));
}
const sleep = (ms) => new Promise((res) => setTimeout(res, ms));
// A plan of three poses measured to its end on the simulator, its prompts answered; its id.
async function measureSmallSession() {
  const small = { name: 'uncertainty over JSON', poseList: { poses: [{ alpha: 0, beta: 10, delta: 40 }, { alpha: 10, beta: 20, delta: 40 }, { alpha: 20, beta: 40, delta: 40 }] }, measurement: { integrationMs: 100, averages: 1 } };
  const id = (await post('Control/SubmitPlan', { plan: small, start_now: true }, rig.operatorToken)).json.session.session_id;
  for (const deadline = Date.now() + 60000; Date.now() < deadline; await sleep(100)) {
    const s = (await post('Control/GetSession', { session_id: id }, rig.operatorToken)).json;
    if (s.state === 'SESSION_STATE_COMPLETED') return id;
    if (['SESSION_STATE_FAILED', 'SESSION_STATE_ABORTED'].includes(s.state)) throw new Error(`the small session is ${s.state}: ${s.state_reason}`);
    if (s.state === 'SESSION_STATE_AWAITING_OPERATOR' && s.pending_prompt) {
      await rig.simMount(s.pending_prompt.kind);
      await post('Control/AnswerPrompt', { session_id: id, step_index: s.pending_prompt.step_index ?? 0 }, rig.operatorToken);
    }
  }
  throw new Error('the small session did not finish within a minute');
}
const finiteNonNegative = (a, n) => Array.isArray(a) && a.length === n && a.every((v) => typeof v === 'number' && Number.isFinite(v) && v >= 0);
// include_uncertainty through the gateway, both ways (the JSON mapping is protobuf's, field names
// as in brdf.proto): a reading's budget in Data.StreamReadings (and left out with ?omit=), an
// interpolated spectrum's uncertainty in Interpolate and InterpolateBatch, none when not asked.
async function checkUncertaintyOverJson() {
  const id = await measureSmallSession();
  const readings = await messages('Data/StreamReadings', { session_id: id, kinds: ['READING_KIND_SAMPLE'] }, rig.analystToken);
  const budget = readings[0]?.uncertainty;
  const bands = readings[0]?.radiance.length;
  check(readings.length === 3 && budget?.quantity === 'QUANTITY_BRDF' && finiteNonNegative(budget.combined, bands) && budget.combined.some((v) => v > 0) && Array.isArray(budget.components) && Array.isArray(budget.not_estimated),
    `a reading's budget comes through as Reading.uncertainty (${readings.length} readings, ${budget?.combined?.length} bands, ${budget?.components?.length} components)`);
  const omitted = await messages('Data/StreamReadings?omit=uncertainty', { session_id: id, kinds: ['READING_KIND_SAMPLE'] }, rig.analystToken);
  check(omitted.length === 3 && omitted.every((m) => !('uncertainty' in m)), '?omit=uncertainty leaves the budgets out');
  const at = { session_id: id, method: 'INTERPOLATION_METHOD_NEAREST', direction: { iso: readings[0].iso } };
  let r = await post('Interpolation/Interpolate', at, rig.analystToken);
  check(r.status === 200 && r.json.result.status === 'INTERPOLATION_STATUS_OK' && !('uncertainty' in r.json.result), `Interpolate without include_uncertainty → no uncertainty (${r.status})`);
  r = await post('Interpolation/Interpolate', { ...at, include_uncertainty: true }, rig.analystToken);
  const u = r.json?.result?.uncertainty;
  // Equal to float precision (an answer's uncertainty may travel as float, the budget as double).
  const same = (a, b) => a.length === b.length && a.every((v, i) => Math.abs(v - b[i]) <= 1e-6 * Math.abs(b[i]) + 1e-30);
  check(r.status === 200 && finiteNonNegative(u?.measurement, bands) && finiteNonNegative(u.combined, bands) && same(u.measurement, budget.combined) && same(u.combined, u.measurement),
    `Interpolate with include_uncertainty: the nearest reading's measurement part is its stored budget, combined equals it (${u?.measurement?.length} bands)`);
  check(Array.isArray(u?.interpolation) && u.interpolation.length === 0 && Array.isArray(u.shared) && u.not_estimated.some((t) => /^interpolation: the nearest method/.test(t)),
    `…and its interpolation term is empty and named as not estimated (${u?.not_estimated?.join(' | ')})`);
  const directions = readings.map((m) => ({ iso: m.iso }));
  const chunks = await messages('Interpolation/InterpolateBatch', { session_id: id, method: 'INTERPOLATION_METHOD_NEAREST', directions, include_uncertainty: true }, rig.analystToken);
  const results = chunks.flatMap((c) => c.results);
  const byId = new Map(readings.map((m) => [m.id, m.uncertainty.combined]));
  check(results.length === 3 && results.every((x) => x.status === 'INTERPOLATION_STATUS_OK' && finiteNonNegative(x.uncertainty?.measurement, bands) && same(x.uncertainty.measurement, byId.get(x.vertices[0].reading_id))),
    `InterpolateBatch with include_uncertainty: each result's measurement part, per band, its reading's budget (${results.map((x) => x.uncertainty?.measurement?.length).join(', ')})`);
  const plain = (await messages('Interpolation/InterpolateBatch', { session_id: id, method: 'INTERPOLATION_METHOD_NEAREST', directions }, rig.analystToken)).flatMap((c) => c.results);
  check(plain.length === 3 && plain.every((x) => !('uncertainty' in x)), 'InterpolateBatch without it → no uncertainty');
}

let failed = false;
try {
  const plan = JSON.parse(readFileSync(join(here, '../../examples/plans/demo.json'), 'utf8'));

  let r = await post('Control/ListSessions', {}, '');
  check(r.status === 401 && r.json.code === 'UNAUTHENTICATED', `no token → 401 UNAUTHENTICATED (${r.status} ${r.text})`);
  r = await post('Control/ListSessions', {}, 'not-a-token-of-this-daemon');
  check(r.status === 401 && r.json.code === 'UNAUTHENTICATED', `unknown token → 401 (${r.status})`);
  r = await post('Control/ListSessions', {}, rig.analystToken);
  check(r.status === 200 && Array.isArray(r.json.sessions), 'analyst may list sessions');
  r = await post('Control/SubmitPlan', { plan }, rig.analystToken);
  check(r.status === 403 && r.json.code === 'PERMISSION_DENIED', `analyst SubmitPlan → 403 PERMISSION_DENIED (${r.status} ${r.text})`);
  r = await post('Control/PauseSession', { session_id: '' }, rig.analystToken);
  check(r.status === 403, 'analyst PauseSession → 403 before the body is looked at');
  // Who a token is, through the gateway's door as through the token gate.
  r = await post('Control/WhoAmI', {}, rig.analystToken);
  check(r.status === 200 && r.json.role === 'analyst' && r.json.server === 'brdfd' && r.json.name.length > 0, `analyst WhoAmI → analyst on brdfd (${r.text})`);
  r = await post('Control/WhoAmI', {}, rig.operatorToken);
  check(r.status === 200 && r.json.role === 'operator' && r.json.name !== (await post('Control/WhoAmI', {}, rig.analystToken)).json.name, `operator WhoAmI → operator, another name (${r.text})`);
  r = await post('Control/WhoAmI', {}, '');
  check(r.status === 401 && r.json.code === 'UNAUTHENTICATED', `WhoAmI without a token → 401 (${r.status})`);

  r = await post('Control/ValidatePlan', { plan: { name: 'x', sampleRotation: { delta: { start: 0, stop: 400, step: 0 } } } }, rig.operatorToken);
  check(r.status === 200 && r.json.valid === false && r.json.problems.length > 0 && r.json.problems.every((p) => typeof p.field_path === 'string'),
    `an invalid plan → problems at field paths (${r.json?.problems?.map((p) => p.field_path).join(', ')})`);
  r = await post('Control/ValidatePlan', { plan }, rig.operatorToken);
  check(r.status === 200 && r.json.valid === true && r.json.estimated_duration_s > 0, `the demo plan validates, estimated ${r.json.estimated_duration_s} s`);

  // The API's documented ranges hold through the gateway too (the same handlers): a relative
  // azimuth outside [0, 180] is refused naming the field, the value and the range.
  const direction = (phi) => ({ session_id: '1', direction: { iso: { theta_i: 20, theta_o: 30, phi } } });
  for (const phi of [-0.5, 180.5, 320]) {
    r = await post('Interpolation/Interpolate', direction(phi), rig.analystToken);
    check(r.status === 400 && r.json.code === 'INVALID_ARGUMENT' && r.json.message.includes('direction.iso.phi') && r.json.message.includes(String(phi)) && r.json.message.includes('[0, 180]'),
      `Interpolate φ ${phi} → 400 naming direction.iso.phi and [0, 180] (${r.status} ${r.json?.message})`);
  }

  r = await post('Control/ListSessions', '{"page_size": ', rig.operatorToken);
  check(r.status === 400 && r.json.code === 'INVALID_ARGUMENT' && /invalid JSON/.test(r.json.message), `malformed JSON → 400 (${r.json?.message})`);
  r = await post('Control/ListSessions', { page_sise: 3 }, rig.operatorToken);
  check(r.status === 400 && /page_sise/.test(r.json.message), `unknown field → 400 naming it (${r.json?.message})`);
  r = await post('Control/ListSessions', { page_size: 'many' }, rig.operatorToken);
  check(r.status === 400, 'wrong type → 400');
  r = await post('Control/Explode', {}, rig.operatorToken);
  check(r.status === 404 && r.json.code === 'UNIMPLEMENTED', 'unknown method → 404');
  // A client's strings come back as a short printable prefix, never whole (issue 20: errors echo
  // at most a short prefix of any client string).
  const longName = 'y'.repeat(20000);
  r = await post(`Control/${longName.slice(0, 5000)}`, {}, rig.operatorToken);
  check(r.status === 404 && r.text.length < 1024 && /\.\.\. \(\d+ bytes\)/.test(r.json?.message), `a 5 kB method name is quoted cut (${r.status}, ${r.text.length} bytes)`);
  r = await post('Control/ListSessions', `{"${longName}": 1}`, rig.operatorToken);
  check(r.status === 400 && r.text.length < 1024 && /yyyy/.test(r.json.message), `a 20 kB unknown field is quoted cut (${r.text.length} bytes)`);
  r = await post('Control/ListSessions', '{}', rig.operatorToken, { headers: { 'Content-Type': 'text/plain' } });
  check(r.status === 415, 'a text/plain body → 415 (no form posts)');
  const big = JSON.stringify({ plan: { name: 'x'.repeat(2 * 1024 * 1024) } });
  r = await post('Control/SubmitPlan', big, rig.operatorToken);
  check(r.status === 413, `a 2 MiB body → 413 (${r.status})`);
  const g = await fetch(api('Control/ListSessions'));
  check(g.status === 405, 'GET on the API → 405');
  r = await post('Control/ListSessions?timeout_s=5', {}, rig.analystToken);
  check(r.status === 200, `?timeout_s=5 on a unary call is accepted (${r.status})`);
  for (const bad of ['0', '601', 'abc', '1e3', '']) {
    r = await post(`Control/ListSessions?timeout_s=${bad}`, {}, rig.analystToken);
    check(r.status === 400 && /timeout_s: give whole seconds from 1 to 600/.test(r.json?.message), `?timeout_s=${bad} → 400 naming it (${r.json?.message})`);
  }
  r = await post('Control/WatchSession?timeout_s=5', { session_id: '1' }, rig.analystToken);
  check(r.status === 400 && /timeout_s: a stream has no deadline/.test(r.json?.message), `?timeout_s on a stream → 400 (${r.json?.message})`);
  const about = await fetch(new URL('/api/about', rig.url));
  const aboutJson = await about.json();
  check(about.status === 200 && aboutJson.server === 'brdfd' && Object.keys(aboutJson).length === 1 &&
    /default-src 'none'/.test(about.headers.get('content-security-policy') || ''), `GET /api/about → ${JSON.stringify(aboutJson)} with the security headers, no token needed`);

  r = await post('Data/StreamReadings?omit=radiance,nonsense', { session_id: '1' }, rig.analystToken);
  check(r.status === 400 && /no field "nonsense"/.test(r.json.message), `?omit= of an unknown field → 400 (${r.json?.message})`);
  r = await post('Data/StreamReadingPoints', { session_id: '1' }, '');
  check(r.status === 401 && r.json.code === 'UNAUTHENTICATED', `the compact readings listing without a token → 401 (${r.status})`);
  r = await post('Data/StreamReadingPoints', { session_id: '999999' }, rig.analystToken);
  check(r.status === 404, `the compact readings listing of an unknown session → 404 (${r.status} ${r.text})`);
  r = await post('Data/StreamReadingPoints', { session_id: '1', after_id: '-1' }, rig.analystToken);
  check(r.status === 400 && /after_id/.test(r.json.message), `the compact listing checks its request as StreamReadings does (${r.json?.message})`);
  r = await post('Control/WatchSession', { session_id: '1' }, '');
  check(r.status === 401 && !(r.headers.get('content-type') || '').includes('event-stream'), 'a stream without a token → 401, not an event stream');
  r = await post('Control/WatchSession', { session_id: '999999' }, rig.analystToken);
  check(r.status === 404, `a stream of an unknown session → 404 (${r.status} ${r.text})`);

  const sub = await post('Control/SubmitPlan', { plan }, rig.operatorToken);
  check(sub.status === 200 && sub.json.session.state === 'SESSION_STATE_QUEUED', 'operator submits the demo plan');
  const id = sub.json.session.session_id;
  const res = await fetch(api('Control/WatchSession'), { method: 'POST', headers: { 'Content-Type': 'application/json', Authorization: `Bearer ${rig.analystToken}` }, body: JSON.stringify({ session_id: id }) });
  check(res.status === 200 && res.headers.get('content-type').startsWith('text/event-stream'), 'WatchSession → text/event-stream');
  const reader = res.body.getReader();
  let text = '';
  while (!text.includes('\n\n')) text += new TextDecoder().decode((await reader.read()).value);
  const first = JSON.parse(text.split('\n\n')[0].replace(/^data: /, ''));
  check(first.snapshot && first.snapshot.session_id === id, 'its first event is the snapshot');
  await reader.cancel();
  r = await post('Control/AbortSession', { session_id: id, reason: 'gateway test' }, rig.operatorToken);
  check(r.status === 200 && r.json.session.state === 'SESSION_STATE_ABORTED', 'operator aborts it');
  r = await post('Control/ResumeSession', { session_id: id }, rig.operatorToken);
  check(r.status === 409 && r.json.code === 'FAILED_PRECONDITION', 'resuming an aborted session → 409');
  r = await post('Control/ListSessionEvents', { session_id: id }, rig.analystToken);
  const states = (r.json?.events || []).map((e) => e.state);
  check(r.status === 200 && states[0] === 'SESSION_STATE_QUEUED' && states[states.length - 1] === 'SESSION_STATE_ABORTED' &&
    /gateway test/.test(r.json.events[states.length - 1].reason), `analyst reads its history, queued … aborted (${states.join(', ')})`);
  r = await post('Control/ListSessionEvents', { session_id: '999999' }, rig.analystToken);
  check(r.status === 404 && /999999/.test(r.json.message), `the history of an unknown session → 404 (${r.status} ${r.text})`);
  // The explorer's grid step goes to Data.Export as it is: a step that does not divide 90 is
  // refused naming the field, before anything is streamed.
  r = await post('Data/Export', { session_id: id, format: 'EXPORT_FORMAT_GRID_NPY', step_theta_i: 7 }, rig.analystToken);
  check(r.status === 400 && /step_theta_i/.test(r.json?.message), `an export grid step of 7° → 400 naming step_theta_i (${r.status} ${r.json?.message})`);
  await checkUncertaintyOverJson();

  const page = await fetch(rig.url);
  const html = await page.text();
  const csp = page.headers.get('content-security-policy') || '';
  check(page.status === 200 && html.includes('id="login-view"'), 'GET / serves the console');
  check(/script-src 'self'(;|$)/.test(csp) && csp.includes("frame-ancestors 'none'") && csp.includes("default-src 'none'"), `CSP: ${csp}`);
  check(!/<script(?![^>]*\bsrc=)[^>]*>/.test(html), 'index.html has no inline script');
  check(page.headers.get('x-content-type-options') === 'nosniff' && page.headers.get('referrer-policy') === 'no-referrer' && page.headers.get('x-frame-options') === 'DENY', 'nosniff, no-referrer, DENY');
  check(r.headers.get('content-security-policy') === csp, 'API answers carry the same headers');
  const cors = await fetch(api('Control/ListSessions'), { method: 'POST', headers: { Origin: 'http://evil.example', 'Content-Type': 'application/json', Authorization: `Bearer ${rig.analystToken}` }, body: '{}' });
  check(cors.headers.get('access-control-allow-origin') === null, 'no CORS: other origins cannot read answers');

  // A raw request line climbing out of the web root.
  const u = new URL(rig.url);
  const raw = await new Promise((resolve) => {
    const s = net.connect(Number(u.port), u.hostname, () => s.write('GET /../../../../etc/passwd HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n'));
    let d = '';
    s.on('data', (c) => { d += c; });
    s.on('end', () => resolve(d));
    s.on('error', () => resolve(d));
  });
  check(!raw.includes('root:x:0:0') && /^HTTP\/1\.1 (400|404)/.test(raw), `path traversal refused (${raw.split('\r\n')[0]})`);
  // A header flood is refused, not buffered.
  const flood = await new Promise((resolve) => {
    const s = net.connect(Number(u.port), u.hostname, () => s.write(`POST /api/brdf.v1.Control/ListSessions HTTP/1.1\r\nHost: x\r\nX-Big: ${'a'.repeat(20000)}\r\n\r\n`));
    let d = '';
    s.on('data', (c) => { d += c; });
    s.on('end', () => resolve(d));
    s.on('error', () => resolve(d));
    s.setTimeout(5000, () => { s.destroy(); resolve(d); });
  });
  check(!flood.startsWith('HTTP/1.1 200'), `a 20 kB header is refused (${flood.split('\r\n')[0] || 'connection closed'})`);
} catch (e) {
  failed = true;
  console.error(e.stack || e);
  console.error(readFileSync(rig.daemonLog, 'utf8').slice(-3000));
} finally {
  await rig.stop();
}
process.exit(failed ? 1 : 0);
