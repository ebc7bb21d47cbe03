// brdfd's web front end: sign in with a bearer token (kept in this tab's sessionStorage only),
// then the console (#console) or the explorer (#explorer). Served by brdfd (a rig's console) or
// by brdf-archive (GET /api/about says which): the archive's console is read-only, with no rig.
import './style.css';
import { call, getToken, setToken, probeRole } from './api.js';
import { createConsole } from './console.js';
import { createExplorer } from './explorer.js';

const $ = (id) => document.getElementById(id);
let role = null;
let server = 'brdfd';
let views = null;
let current = null;

function report(message) {
  let bar = $('error-bar');
  if (!bar) {
    bar = document.createElement('p');
    bar.id = 'error-bar';
    bar.className = 'error';
    document.querySelector('main').prepend(bar);
  }
  bar.textContent = message;
}

async function route() {
  if (!role) return;
  const name = location.hash === '#explorer' ? 'explorer' : 'console';
  if (current === name) return;
  if (current) { views[current].hide(); $(`${current}-view`).hidden = true; }
  current = name;
  $(`${name}-view`).hidden = false;
  for (const n of ['console', 'explorer']) $(`nav-${n}`).classList.toggle('active', n === name);
  try { await views[name].show(); } catch (e) { report(e.message); }
}

async function signIn() {
  try {
    await call('Control/ListSessions', { page_size: 1 });
    // The archive has no rig and no control for anyone.
    role = server === 'brdf-archive' ? 'reader' : await probeRole();
  } catch (e) {
    setToken('');
    $('login-view').hidden = false;
    $('login-error').textContent = e.code === 'UNAUTHENTICATED' ? 'That token is not known to this brdfd.' : e.message;
    return;
  }
  $('login-view').hidden = true;
  $('nav').hidden = false;
  $('logout').hidden = false;
  $('who').textContent = role;
  $('who').className = `role ${role}`;
  document.body.dataset.role = role;
  views = { console: createConsole($('console-view'), role, report, server), explorer: createExplorer($('explorer-view'), report) };
  await route();
}

$('login-form').addEventListener('submit', (e) => {
  e.preventDefault();
  setToken($('token').value.trim());
  $('token').value = '';
  signIn();
});
$('logout').addEventListener('click', () => { setToken(''); location.hash = ''; location.reload(); });
window.addEventListener('hashchange', route);

// Which program serves this page; an older brdfd without /api/about is a rig's.
async function identify() {
  try {
    const r = await fetch('/api/about');
    if (r.ok) server = (await r.json()).server || server;
  } catch { /* a rig's brdfd */ }
  document.body.dataset.server = server;
  document.querySelector('header h1').textContent = server;
  document.title = server === 'brdf-archive' ? 'brdf-archive: the lab archive' : 'brdfd';
}

identify().then(() => { if (getToken()) signIn(); else $('login-view').hidden = false; });
