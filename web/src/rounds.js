// An adaptive session's rounds in the console (docs/adaptive.md, "Every choice explained"): the
// plan's target and budgets, a table of the rounds — the readings each was chosen from, the
// uncertainty left before it as a bar against the target, the predicted gain, the rig time and
// prompts spent before it against the budgets, its poses and detector positions — a chart of the
// uncertainty left per round with the target as a line, and the last round's poses (what the rig
// measures next). Filled from Control.ListAdaptiveRounds when the session is selected, then live
// from WatchSession's adaptive_round and adaptive_stop events.
import { plotly } from './plotly.js';
import { call } from './api.js';
import { el, clear, duration } from './dom.js';

const num = (v, digits = 3) => Number(Number(v || 0).toPrecision(digits)).toString();
const deg = (v) => `${num(v, 6)}°`;

// The plan's target level and its name.
function targetOf(adaptive) {
  const t = adaptive?.target || {};
  if (t.expected_error !== undefined && t.expected_error !== null && t.expected_error > 0) return { level: t.expected_error, name: 'expected error' };
  return { level: Number(t.expanded_uncertainty || 0), name: 'U (k = 2)' };
}

function goalText(adaptive) {
  const { level, name } = targetOf(adaptive);
  const b = adaptive?.budget || {};
  const limits = [
    b.max_readings ? `${b.max_readings} readings` : null,
    b.max_rig_minutes ? `${duration(b.max_rig_minutes * 60)} of rig time` : null,
    b.max_prompts ? `${b.max_prompts} prompts` : null].filter(Boolean);
  return `target: ${name} ≤ ${num(level)}${limits.length ? `; budget: ${limits.join(', ')}` : ''}`;
}

// "45° → 56.25° → 78.75°": the round's detector positions in measurement order.
function deltaPath(poses) {
  const out = [];
  for (const p of poses) if (out.at(-1) !== p.delta) out.push(p.delta);
  return out.map(deg).join(' → ');
}

// The sample-fixed form: "θi 50° θo 5° φ 130°", where the operator places lamp and detector
// (AdaptiveRound.directions; the poses are only their equivalents on a rotation stage).
function directionText(d) {
  const ti = Number(d?.theta_i || 0);
  const to = Number(d?.theta_o || 0);
  let phi = Math.abs(Number(d?.phi_o || 0) - Number(d?.phi_i || 0)) % 360;
  if (phi > 180) phi = 360 - phi;
  if (ti < 1e-9 || to < 1e-9) phi = 0;
  return `θi ${deg(ti)} θo ${deg(to)} φ ${deg(phi)}`;
}

// "25°–65°": the round's incidence range.
function thetaIRange(directions) {
  if (!directions.length) return '';
  const t = directions.map((d) => Number(d.theta_i || 0));
  const [lo, hi] = [Math.min(...t), Math.max(...t)];
  return lo === hi ? deg(lo) : `${deg(lo)}–${deg(hi)}`;
}

function spentOf(value, limit, text) {
  return limit ? `${text(value)} of ${text(limit)}` : text(value);
}

export function createRoundsView() {
  const goal = el('p', { id: 'rounds-goal' });
  const body = el('tbody');
  const table = el('table', { id: 'rounds-table' },
    el('thead', {}, el('tr', {}, ['round', 'chosen from', 'uncertainty left', 'against the target', 'predicted gain', 'rig time spent', 'prompts spent', 'poses', el('span', { id: 'rounds-where' }, 'δ')].map((h) => el('th', {}, h)))),
    body);
  const chart = el('div', { id: 'rounds-chart', class: 'plot' });
  const next = el('div', { id: 'next-round' });
  const stopLine = el('p', { id: 'adaptive-stop' });
  const element = el('div', { id: 'rounds', hidden: true },
    el('h3', {}, 'Adaptive rounds (each chosen before it was measured)'), goal, table, chart,
    el('h4', {}, 'The latest round (what the rig measures while the session runs)'), next, stopLine);

  let adaptive = null;
  let session = '';
  let rounds = new Map(); // round number → AdaptiveRound
  let asked = 0;

  function render() {
    const list = [...rounds.values()].sort((a, b) => a.round - b.round);
    const { level } = targetOf(adaptive);
    const b = adaptive?.budget || {};
    // The sample-fixed form (plan.adaptive.sample_fixed set): directions, not stage poses.
    const fixed = !!adaptive?.sample_fixed;
    const whereHead = element.querySelector('#rounds-where');
    if (whereHead) whereHead.textContent = fixed ? 'θi' : 'δ';
    const highest = Math.max(level, ...list.map((r) => r.uncertainty_left));
    clear(body).append(...list.map((r) => el('tr', { 'data-round': r.round, 'data-left': r.uncertainty_left },
      el('td', {}, r.round),
      el('td', {}, spentOf(r.readings_used, b.max_readings, (v) => `${v}`)),
      el('td', { class: 'left' }, num(r.uncertainty_left)),
      el('td', {}, el('div', { class: 'ubar' },
        el('div', { class: 'ubar-left', style: `width: ${(100 * r.uncertainty_left / highest).toFixed(1)}%` }),
        el('div', { class: 'ubar-target', style: `left: ${(100 * level / highest).toFixed(1)}%`, title: `target ${num(level)}` }))),
      el('td', {}, num(r.predicted_gain)),
      el('td', {}, spentOf(r.spent_rig_s, b.max_rig_minutes * 60, duration)),
      el('td', {}, spentOf(r.spent_prompts, b.max_prompts, (v) => `${v}`)),
      el('td', {}, (r.poses || []).length),
      el('td', {}, fixed ? thetaIRange(r.directions || []) : deltaPath(r.poses || [])))));
    const last = list.at(-1);
    const where = (r) => (fixed ? `θi ${thetaIRange(r.directions || [])}` : `δ ${deltaPath(r.poses || [])}`);
    clear(next).append(last
      ? el('p', {}, `round ${last.round}: ${(last.poses || []).length} poses, steps ${last.first_step}–${last.first_step + Math.max(last.step_count, 1) - 1}, +${duration(last.rig_s)} of rig time, +${last.prompts} prompts; ${where(last)}`)
      : el('p', { class: 'muted' }, 'no round yet: the seed design is measured first'));
    if (last?.poses?.length) {
      const items = last.poses.slice(0, 8).map((p, i) => el('li', {},
        `${fixed && last.directions?.[i] ? directionText(last.directions[i]) : `α ${deg(p.alpha)} β ${deg(p.beta)} γ ${deg(p.gamma)} δ ${deg(p.delta)}`} (gain ${num(last.pose_gains?.[i])})`));
      next.append(el('ol', { id: 'next-poses' }, items),
        last.poses.length > 8 ? el('p', { class: 'muted' }, `… and ${last.poses.length - 8} more`) : '');
    }
    drawChart(list, level);
  }

  async function drawChart(list, level) {
    if (!list.length) return;
    const Plotly = await plotly();
    const x = list.map((r) => r.round);
    Plotly.react(chart, [
      { x, y: list.map((r) => r.uncertainty_left), mode: 'lines+markers', name: 'uncertainty left', meta: { series: 'left' } },
      { x: [Math.min(...x) - 0.5, Math.max(...x) + 0.5], y: [level, level], mode: 'lines', line: { dash: 'dash', color: 'green' }, name: `target ${num(level)}`, meta: { series: 'target' } },
    ], { height: 260, margin: { t: 20, b: 40 }, xaxis: { title: { text: 'round' }, dtick: 1 }, yaxis: { title: { text: 'uncertainty left (relative)' }, rangemode: 'tozero' } }, { displaylogo: false, responsive: true });
  }

  return {
    element,
    // A session selected (its snapshot or GetSession answer): shown only when its plan is adaptive.
    async show(s) {
      const ask = ++asked;
      session = s?.session_id || '';
      adaptive = s?.plan?.adaptive || null;
      rounds = new Map();
      clear(stopLine);
      element.hidden = !adaptive;
      if (!adaptive) return;
      goal.textContent = goalText(adaptive);
      if (s.state_reason?.startsWith('adaptive:')) stopLine.textContent = `stopped: ${s.state_reason}`;
      render();
      const r = await call('Control/ListAdaptiveRounds', { session_id: session });
      if (ask !== asked) return;
      for (const round of r.rounds || []) rounds.set(round.round, round);
      render();
    },
    // WatchSession's events: a round stored, the stop.
    event(ev) {
      if (!adaptive) return;
      if (ev.adaptive_round) { rounds.set(ev.adaptive_round.round, ev.adaptive_round); render(); }
      if (ev.adaptive_stop) {
        const s = ev.adaptive_stop;
        const b = adaptive.budget || {};
        stopLine.textContent = `stopped: ${s.reason}; uncertainty left ${num(s.uncertainty_left)} (target ${num(targetOf(adaptive).level)}) after ${s.rounds} round(s): ${spentOf(s.readings, b.max_readings, (v) => `${v}`)} readings, ${spentOf(s.rig_s, b.max_rig_minutes * 60, duration)} of rig time, ${spentOf(s.prompts, b.max_prompts, (v) => `${v}`)} prompts`;
      }
    },
  };
}
