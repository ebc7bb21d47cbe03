// The operator console: the queue and history, submitting a plan (validated first: problems at
// their field paths, the estimated time), the operator verbs, live progress with ETA and the
// coverage of the hemisphere (WatchSession), prompts, the rig and the session's events; an adaptive
// session's rounds, uncertainty left against the target and next poses (rounds.js).
// Analysts see the same pages without any control (and the server refuses control anyway).
// Served by brdf-archive, it is the archive's read-only console: every rig's sessions (with the
// rig's name), their history, progress and coverage, refreshed as the rigs ship; no plan, no rig,
// no control.
import { plotly } from './plotly.js';
import { call, stream } from './api.js';
import { el, clear, stateName, duration } from './dom.js';
import { createRoundsView } from './rounds.js';

const ACTIVE = ['SESSION_STATE_QUEUED', 'SESSION_STATE_RUNNING', 'SESSION_STATE_PAUSING', 'SESSION_STATE_PAUSED', 'SESSION_STATE_AWAITING_OPERATOR'];

export function createConsole(root, role, report, server = 'brdfd') {
  const archive = server === 'brdf-archive';
  const operator = role === 'operator' && !archive;
  let selected = null;          // session id
  let watch = null;             // AbortController of the WatchSession stream
  let events = [];
  let covered = [];             // sample readings' directions
  let lastReadingId = 0;
  let changedReadings = [];     // readings whose integration time the meter changed
  let coverageBusy = false;

  const sessionsBody = el('tbody');
  const planFile = el('input', { type: 'file', id: 'plan-file', accept: '.json,application/json' });
  const validation = el('div', { id: 'validation' });
  const submitButton = el('button', { id: 'submit-plan', disabled: true }, 'Submit');
  const submitStartButton = el('button', { id: 'submit-start', disabled: true }, 'Submit and start');
  const detail = el('div', { id: 'session-detail' }, el('p', {}, 'Select a session.'));
  const rig = el('div', { id: 'rig' });
  const coverage = el('div', { id: 'coverage', class: 'plot' });
  const eventList = el('ol', { id: 'events' });
  const integrationNotes = el('ul', { id: 'integration-notes' });
  const history = el('div', { id: 'history' });
  const rounds = createRoundsView(); // an adaptive session's rounds (rounds.js)
  let plan = null;

  const rigSide = archive
    ? [el('p', { class: 'muted', id: 'archive-note' }, 'brdf-archive: the lab\'s archive of every rig\'s sessions, read only. Plans, prompts and the rig verbs belong to each rig\'s own brdfd.')]
    : [el('h2', {}, 'Plan'),
      el('p', {}, 'Choose a plan file (JSON); it is checked against this rig before anything is stored.'),
      planFile, validation,
      operator ? el('div', { class: 'buttons' }, submitButton, submitStartButton) : el('p', { class: 'muted' }, 'Analyst token: read only.'),
      el('h2', {}, 'Rig'), rig];
  root.append(
    el('div', { class: 'columns' },
      el('div', { class: 'col' },
        el('h2', {}, 'Sessions'),
        el('table', { id: 'sessions' }, el('thead', {}, el('tr', {}, el('th', {}, 'name'), archive ? el('th', {}, 'rig') : null, el('th', {}, 'state'), el('th', {}, 'progress'), el('th', {}, 'created'))), sessionsBody),
        ...rigSide),
      el('div', { class: 'col wide' },
        el('h2', {}, 'Session'), detail, rounds.element,
        el('h3', {}, 'Hemisphere coverage (measured outgoing directions)'), coverage,
        el('h3', {}, 'Readings whose integration time the meter changed'), integrationNotes,
        el('h3', {}, 'History (the states the session went through, as the rig recorded them)'), history,
        archive ? null : [el('h3', {}, 'Live events (since this page opened the session)'), eventList])));

  planFile.addEventListener('change', async () => {
    clear(validation);
    plan = null;
    submitButton.disabled = submitStartButton.disabled = true;
    const file = planFile.files[0];
    if (!file) return;
    try { plan = JSON.parse(await file.text()); }
    catch (e) { validation.append(el('p', { class: 'error' }, `${file.name} is not JSON: ${e.message}`)); return; }
    try {
      const v = await call('Control/ValidatePlan', { plan });
      if (v.valid) {
        validation.append(el('p', { class: 'ok', id: 'plan-valid' },
          `valid: ${v.step_count} steps, ${v.summary?.sample_readings ?? '?'} sample readings, ${v.operator_interventions} operator interventions, estimated ${duration(v.estimated_duration_s)}`));
        submitButton.disabled = submitStartButton.disabled = false;
      } else {
        validation.append(el('p', { class: 'error' }, `${v.problems.length} problem(s):`),
          el('ul', { id: 'plan-problems' }, v.problems.map((p) => el('li', {}, el('code', {}, p.field_path || '(plan)'), ' ', p.message))));
      }
    } catch (e) { validation.append(el('p', { class: 'error' }, e.message)); }
  });

  async function submit(start) {
    try {
      const r = await call('Control/SubmitPlan', { plan, start_now: start });
      report('');
      await refreshSessions();
      select(r.session.session_id);
    } catch (e) { report(e.message); }
  }
  submitButton.addEventListener('click', () => submit(false));
  submitStartButton.addEventListener('click', () => submit(true));

  async function refreshSessions() {
    const r = await call('Control/ListSessions', { page_size: 50 });
    clear(sessionsBody);
    for (const s of r.sessions) {
      const p = s.progress || {};
      sessionsBody.append(el('tr', {
        class: s.session_id === selected ? 'selected' : '', 'data-id': s.session_id,
        onclick: () => select(s.session_id),
      }, el('td', {}, s.name || s.session_id), archive ? el('td', { class: 'rig' }, s.rig || '') : null, el('td', { class: `state ${stateName(s.state)}` }, stateName(s.state)),
      el('td', {}, `${p.done_steps}/${p.total_steps}`), el('td', {}, (s.created_at || '').replace('T', ' ').slice(0, 19))));
    }
    return r.sessions;
  }

  async function refreshRig() {
    try {
      const r = await call('Control/GetRigStatus', {});
      clear(rig).append(...[
        el('ul', {}, r.devices.map((d) => el('li', {}, `${d.name}: ${String(d.state).replace('CONNECTION_STATE_', '').toLowerCase()} ${d.model} ${d.address} ${d.detail}`))),
        el('p', {}, r.live_pose_valid ? `pose α ${r.live_pose.alpha.toFixed(2)}°, β ${r.live_pose.beta.toFixed(2)}°, γ ${r.live_pose.gamma.toFixed(2)}°, δ ${r.live_pose.delta.toFixed(2)}°` : 'pose unknown'),
        el('p', {}, `meter serial: ${r.meter_serial || '—'}`),
        r.active_session_id ? el('p', {}, `active session: ${r.active_session_id}`) : null].filter(Boolean));
    } catch (e) { clear(rig).append(el('p', { class: 'error' }, e.message)); }
  }

  function verb(label, id, fn) {
    return el('button', { id, onclick: async () => { try { await fn(); report(''); } catch (e) { report(e.message); } } }, label);
  }

  function renderSession(s) {
    const p = s.progress || {};
    const fraction = p.total_steps ? p.done_steps / p.total_steps : 0;
    const state = s.state;
    const items = [
      el('p', {}, el('strong', {}, s.name || ''), ' ', el('code', {}, s.session_id), archive && s.rig ? ` recorded by rig ${s.rig}` : ''),
      el('p', {}, 'state: ', el('span', { id: 'session-state', class: `state ${stateName(state)}` }, stateName(state)), s.end_reason ? ` — ${s.end_reason}` : ''),
      el('progress', { id: 'session-progress', max: 1, value: fraction }),
      el('p', { id: 'progress-text' }, `${p.done_steps}/${p.total_steps} steps, ${p.done_samples}/${p.total_samples} sample readings` +
        (ACTIVE.includes(state) && state !== 'SESSION_STATE_QUEUED' ? `, ETA ${duration(s.eta_s)}` : '')),
      Number(s.last_quality_code) > 0 ? el('p', {}, `last meter quality code: ${s.last_quality_code}`) : null,
      s.last_fault ? el('p', { class: 'error' }, `fault at step ${s.last_fault.step_index}: ${s.last_fault.code} ${s.last_fault.reason}${s.last_fault.will_retry ? ' (retrying)' : ''}`) : null,
    ];
    if (s.pending_prompt) {
      const pr = s.pending_prompt;
      items.push(el('div', { class: 'prompt', id: 'prompt', 'data-kind': pr.kind, 'data-step': pr.step_index },
        el('h3', {}, 'The operator must act'),
        el('p', { id: 'prompt-text' }, pr.text),
        pr.expected_action ? el('p', {}, pr.expected_action) : null,
        operator ? el('div', {}, el('input', { id: 'prompt-note', placeholder: 'note (optional)' }),
          verb('Done — continue', 'answer-prompt', async () => {
            const note = document.getElementById('prompt-note').value;
            await call('Control/AnswerPrompt', { session_id: s.session_id, step_index: pr.step_index, note });
          })) : null));
    }
    if (operator) {
      const id = s.session_id;
      const abortReason = el('input', { id: 'abort-reason', placeholder: 'abort reason' });
      items.push(el('div', { class: 'buttons', id: 'controls' },
        state === 'SESSION_STATE_QUEUED' ? verb('Start', 'start', () => call('Control/StartSession', { session_id: id })) : null,
        ['SESSION_STATE_RUNNING', 'SESSION_STATE_AWAITING_OPERATOR'].includes(state) ? [
          verb('Pause (after this step)', 'pause-deferred', () => call('Control/PauseSession', { session_id: id, mode: 'PAUSE_MODE_DEFERRED' })),
          verb('Pause now', 'pause-immediate', () => call('Control/PauseSession', { session_id: id, mode: 'PAUSE_MODE_IMMEDIATE' }))] : null,
        ['SESSION_STATE_PAUSED', 'SESSION_STATE_PAUSING'].includes(state) ? verb('Resume', 'resume', () => call('Control/ResumeSession', { session_id: id })) : null,
        ACTIVE.includes(state) ? [abortReason, verb('Abort', 'abort', () => call('Control/AbortSession', { session_id: id, reason: abortReason.value || 'aborted from the web console' }))] : null));
    }
    clear(detail).append(...items.filter(Boolean));
  }

  function addEvent(ev) {
    let text = '';
    if (ev.snapshot) text = `snapshot: ${stateName(ev.snapshot.state)}`;
    else if (ev.state_changed) text = `${stateName(ev.state_changed.from)} → ${stateName(ev.state_changed.to)}${ev.state_changed.reason ? ` (${ev.state_changed.reason})` : ''}`;
    else if (ev.prompt) text = `prompt: ${ev.prompt.text}`;
    else if (ev.step_completed) text = `step ${ev.step_completed.step_index} done (${String(ev.step_completed.kind).replace('STEP_KIND_', '').toLowerCase()})${ev.step_completed.flagged ? ', flagged' : ''}`;
    else if (ev.fault) text = `fault: ${ev.fault.code} ${ev.fault.reason}`;
    else if (ev.adaptive_round) text = `round ${ev.adaptive_round.round}: ${(ev.adaptive_round.poses || []).length} poses, predicted gain ${Number(ev.adaptive_round.predicted_gain || 0).toPrecision(3)}, uncertainty left ${Number(ev.adaptive_round.uncertainty_left || 0).toPrecision(3)}`;
    else if (ev.adaptive_stop) text = `adaptive stop: ${ev.adaptive_stop.reason}; uncertainty left ${Number(ev.adaptive_stop.uncertainty_left || 0).toPrecision(3)}`;
    events.unshift(`${(ev.time || '').slice(11, 19)} #${ev.sequence} ${text}`);
    events = events.slice(0, 200);
    clear(eventList).append(...events.map((t) => el('li', {}, t)));
  }

  // The session's durable history (Control.ListSessionEvents): every state it entered, why and
  // when, also for a session that ran before this page was opened. Each row says how long the
  // session stayed in that state (the last one: until now, while the session is active).
  let historyAsk = 0; // only the latest answer is drawn
  async function refreshHistory(id) {
    const ask = ++historyAsk;
    let r;
    try { r = await call('Control/ListSessionEvents', { session_id: id }); } catch (e) { report(e.message); return; }
    if (selected !== id || ask !== historyAsk) return;
    const rows = r.events || [];
    const times = rows.map((ev) => Date.parse(ev.at));
    const last = rows.length ? rows[rows.length - 1].state : '';
    const until = (i) => (i + 1 < rows.length ? times[i + 1] : ACTIVE.includes(last) ? Date.now() : NaN);
    clear(history).append(el('table', { id: 'history-table' },
      el('tr', {}, el('th', {}, 'at'), el('th', {}, 'state'), el('th', {}, 'for'), el('th', {}, 'reason')),
      rows.map((ev, i) => el('tr', { 'data-state': stateName(ev.state) },
        el('td', {}, (ev.at || '').replace('T', ' ').slice(0, 19)),
        el('td', { class: `state ${stateName(ev.state)}` }, stateName(ev.state)),
        el('td', {}, Number.isFinite(until(i) - times[i]) ? duration((until(i) - times[i]) / 1000) : ''),
        el('td', {}, ev.reason || '')))));
  }

  async function updateCoverage(id) {
    if (coverageBusy) return;
    coverageBusy = true;
    try {
      // Every kind: a reference or dark the meter changed is worth seeing too; only samples cover.
      await stream('Data/StreamReadings', { session_id: id, after_id: String(lastReadingId) }, (r) => {
        lastReadingId = Math.max(lastReadingId, Number(r.id));
        if (r.kind === 'READING_KIND_SAMPLE') covered.push(r.directions);
        if (r.integration_note) changedReadings.push(r);
      }, undefined, ['radiance']);
      if (selected === id) renderIntegrationNotes();
      const Plotly = await plotly();
      Plotly.react(coverage, [{
        type: 'scatterpolar', mode: 'markers',
        r: covered.map((d) => d.theta_o), theta: covered.map((d) => d.phi_o),
        marker: { size: 6, color: covered.map((d) => d.theta_i), colorscale: 'Viridis', showscale: true, colorbar: { title: { text: 'θi °' } } },
      }], {
        margin: { t: 20, b: 20, l: 30, r: 30 }, height: 320,
        polar: { radialaxis: { range: [0, 90], title: { text: 'θo °' } }, angularaxis: { direction: 'counterclockwise' } },
      }, { displaylogo: false, responsive: true });
    } catch (e) { report(e.message); }
    finally { coverageBusy = false; }
  }

  function renderIntegrationNotes() {
    clear(integrationNotes).append(...(changedReadings.length
      ? changedReadings.map((r) => el('li', { 'data-reading': r.id },
        `reading ${r.id} (${String(r.kind).replace('READING_KIND_', '').toLowerCase()}, step ${r.step_index ?? 0}): ${r.integration_ms ?? 0} ms — ${r.integration_note}`))
      : [el('li', { class: 'muted' }, 'none: every reading used the plan\'s integration time')]));
  }

  async function select(id) {
    if (watch) watch.abort();
    selected = id;
    events = [];
    covered = [];
    changedReadings = [];
    clear(integrationNotes);
    lastReadingId = 0;
    clear(eventList);
    clear(history);
    rounds.show(null);
    refreshHistory(id);
    for (const tr of sessionsBody.children) tr.classList.toggle('selected', tr.dataset.id === id);
    updateCoverage(id);
    if (archive) { refreshArchived(id); return; }
    const controller = new AbortController();
    watch = controller;
    let session = null;
    stream('Control/WatchSession', { session_id: id }, async (ev) => {
      addEvent(ev);
      rounds.event(ev);
      if (ev.snapshot) {
        session = ev.snapshot;
        rounds.show(session).catch((e) => { if (selected === id) report(e.message); });
      }
      else if (session) {
        if (ev.step_completed) {
          session.progress = ev.step_completed.progress;
          session.eta_s = ev.step_completed.eta_s;
          if (ev.step_completed.kind === 'STEP_KIND_SAMPLE') updateCoverage(id);
        }
        if (ev.state_changed || ev.prompt || ev.fault) {
          try { session = await call('Control/GetSession', { session_id: id }); } catch (e) { report(e.message); }
          refreshSessions();
          if (ev.state_changed) refreshHistory(id);
        }
      }
      if (session && selected === id) renderSession(session);
    }, controller.signal).then(async () => {
      // The session ended: the final state and readings.
      if (selected !== id) return;
      try { renderSession(await call('Control/GetSession', { session_id: id })); } catch (e) { report(e.message); }
      updateCoverage(id);
      refreshHistory(id);
      refreshSessions();
    }).catch((e) => { if (e.name !== 'AbortError' && selected === id) report(e.message); });
  }

  // The archive has no live events: the selected session is read again as the rigs ship it.
  async function refreshArchived(id) {
    try {
      const s = await call('Control/GetSession', { session_id: id });
      if (selected === id) renderSession(s);
    } catch (e) { report(e.message); }
  }

  const timers = [];
  return {
    // (The sign-in's listing, main.js passes to a first view, is not used: this page has its own.)
    async show() {
      const sessions = await refreshSessions();
      if (archive) {
        timers.push(setInterval(() => {
          refreshSessions().catch(() => {});
          if (selected) { refreshArchived(selected); updateCoverage(selected); refreshHistory(selected); }
        }, 5000));
      } else {
        refreshRig();
        timers.push(setInterval(refreshRig, 2000), setInterval(() => refreshSessions().catch(() => {}), 5000));
      }
      if (!selected && sessions.length) select(sessions[0].session_id);
    },
    hide() { while (timers.length) clearInterval(timers.pop()); },
  };
}
