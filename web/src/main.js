// brdfd's web front end: sign in with a bearer token (kept in this tab's sessionStorage only),
// then the console (#console) or the explorer (#explorer). Served by brdfd (a rig's console) or
// by brdf-archive (GET /api/about says which): the archive's console is read-only, with no rig.
import './style.css';
import { call, getToken, setToken, whoAmI } from './api.js';
import { createConsole } from './console.js';
import { createExplorer } from './explorer.js';

const $ = (id) => document.getElementById(id);
let role = null;
let me = null; // Control.WhoAmI: the token's name and role
let server = 'brdfd';
const views = {};
let current = null;
let firstListing = null; // Control.ListSessions as signing in read it

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
  // The sign-in's listing is handed to the first view that opens: the explorer lists from it (one
  // round trip fewer); the console reads its own page of 50 (it refreshes that every 5 s).
  const listing = firstListing;
  firstListing = null;
  try { await view(name).show(listing); } catch (e) { report(e.message); }
}

// A view is built the first time it opens: the explorer's WebGL plots cost nothing to a console.
function view(name) {
  views[name] ??= name === 'console' ? createConsole($('console-view'), role, report, server) : createExplorer($('explorer-view'), report);
  return views[name];
}

// Signing in asks for the sessions (which checks the token) while the page is still asking which
// server it is on, then who the token is (Control.WhoAmI; a token the server does not know is
// refused once):
// the first view waits for two round trips, not four.
async function signIn() {
  try {
    const listing = call('Control/ListSessions', { page_size: 100 });
    const caller = Promise.all([listing, identified]).then(() => whoAmI());
    [firstListing, me] = await Promise.all([listing, caller]);
    // The archive has no rig and no control for anyone.
    role = server === 'brdf-archive' ? 'reader' : me.role;
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
  $('who').title = `token "${me.name}"`;
  $('who').className = `role ${role}`;
  document.body.dataset.role = role;
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

const identified = identify();
if (getToken()) signIn();
else identified.then(() => { $('login-view').hidden = false; });
