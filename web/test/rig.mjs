// brdf-sim and brdfd as real processes for the web tests: the simulated rig (a PR-650 on a pty,
// the stage on Modbus TCP), brdfd with an operator and an analyst token and the web console on a
// free port. Paths come from BRDF_BUILD_DIR (the CMake build tree).
import { spawn, execFile } from 'node:child_process';
import { mkdtempSync, writeFileSync, readFileSync, existsSync, mkdirSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { createInterface } from 'node:readline';

export const build = process.env.BRDF_BUILD_DIR;
if (!build) throw new Error('set BRDF_BUILD_DIR to the CMake build directory');
const brdfd = join(build, 'daemon/brdfd');
const sim = join(build, 'tools/brdf-sim/brdf-sim');
const ctl = join(build, 'tools/brdfctl/brdfctl');

function lines(child, onLine) {
  createInterface({ input: child.stdout }).on('line', onLine);
}

function waitFor(child, name, want, seconds, log) {
  return new Promise((resolve, reject) => {
    const found = {};
    const timer = setTimeout(() => reject(new Error(`${name} did not start in ${seconds} s: ${tail(log)}`)), seconds * 1000);
    child.on('exit', (code) => { clearTimeout(timer); reject(new Error(`${name} exited (${code}): ${tail(log)}`)); });
    child.on('error', (e) => { clearTimeout(timer); reject(new Error(`${name} could not be started (${e.message}): build it (cmake --build $BRDF_BUILD_DIR)`)); });
    lines(child, (line) => {
      for (const [key, re] of Object.entries(want)) {
        const m = re.exec(line);
        if (m) found[key] = m[1];
      }
      if (Object.keys(want).every((k) => k in found)) { clearTimeout(timer); resolve(found); }
    });
  });
}

function tail(file) {
  try { return readFileSync(file, 'utf8').slice(-3000); } catch { return ''; }
}

// The part of brdfd's and brdf-archive's configurations the web tests share: an operator and an
// analyst token, the web console on a free port, the log level.
function tokensWebAndLog(operatorToken, analystToken) {
  return `[[auth.tokens]]
name = "web-operator"
token = "${operatorToken}"
role = "operator"
[[auth.tokens]]
name = "web-analyst"
token = "${analystToken}"
role = "analyst"
[web]
listen = "127.0.0.1:0"
[log]
level = "info"
`;
}

// A test's working directory removed once its processes are gone (databases, logs, credentials),
// unless BRDF_KEEP_TEST_DIRS is set to look at them; tests print the logs they need before.
export function removeTestDir(dir) {
  if (process.env.BRDF_KEEP_TEST_DIRS) {
    console.error(`kept ${dir} (BRDF_KEEP_TEST_DIRS)`);
    return;
  }
  rmSync(dir, { recursive: true, force: true });
}

// SIGTERM, then SIGKILL after 8 s; resolves once the process has exited.
async function stopProcess(p) {
  if (p.exitCode !== null) return;
  p.kill('SIGTERM');
  await new Promise((r) => { const t = setTimeout(() => { p.kill('SIGKILL'); r(); }, 8000); p.on('exit', () => { clearTimeout(t); r(); }); });
}

// `extraConfig`: TOML appended to brdfd's configuration (e.g. [rig] name and [archive]);
// `simArgs`: more brdf-sim options (e.g. an injected quality code).
export async function startRig({ timeScale = 40, extraConfig = '', simArgs = [] } = {}) {
  const dir = mkdtempSync(join(tmpdir(), 'brdf-web-'));
  const operatorToken = 'op-' + Math.random().toString(36).slice(2) + 'xxxxxxxxxxxxxxxx';
  const analystToken = 'an-' + Math.random().toString(36).slice(2) + 'yyyyyyyyyyyyyyyy';
  const { openSync } = await import('node:fs');
  const simLog = join(dir, 'sim.log');
  const simProc = spawn(sim, ['--time-scale', String(timeScale), '--seed', '1', '--modbus-port', '0',
    '--pr650-link', join(dir, 'pr650'), '--wake-window', '0', '--log-level', 'warn', ...simArgs],
  { stdio: ['ignore', 'pipe', openSync(simLog, 'w')] });
  const simInfo = await waitFor(simProc, 'brdf-sim', { modbus: /^modbus-tcp (\S+)/, pr650: /^pr650 (\S+)/, ready: /^(ready)/ }, 20, simLog);
  const config = join(dir, 'brdfd.toml');
  writeFileSync(config, `[server]
listen = "127.0.0.1:0"
[storage]
database = "${dir}/brdfd.db"
[meter]
port = "${simInfo.pr650}"
pacing_ms = 5
quiet_gap_ms = 20
[meter.quality]
"10" = "accept_and_flag"
[stage]
transport = "tcp"
address = "${simInfo.modbus}"
detector_arm_motorized = true
[stage.axes.delta]
present = true
[sample]
white_reflectance = 0.99
${tokensWebAndLog(operatorToken, analystToken)}${extraConfig}`);
  const daemonLog = join(dir, 'brdfd.log');
  let daemon;
  let info;
  try {
    daemon = spawn(brdfd, ['--config', config, '--shutdown-timeout', '3'], { stdio: ['ignore', 'pipe', openSync(daemonLog, 'w')] });
    info = await waitFor(daemon, 'brdfd', { web: /^brdfd web console on (\S+)/, grpc: /^brdfd listening on (\S+)/ }, 20, daemonLog);
  } catch (e) {
    // brdfd missing or failing to start: the simulator must not outlive the test.
    await stopProcess(simProc);
    throw e;
  }
  const rig = {
    dir, url: info.web, grpc: info.grpc, modbus: simInfo.modbus, operatorToken, analystToken, daemonLog,
    // What an operator does by hand at a prompt, done on the simulator.
    simMount(kind) {
      const target = { PROMPT_KIND_MOUNT_WHITE: 'white', PROMPT_KIND_MOUNT_SAMPLE: 'sample', PROMPT_KIND_CLOSE_SHUTTER: 'dark' }[kind];
      if (!target) return Promise.resolve();
      return new Promise((resolve, reject) => execFile(ctl, ['sim-mount', target, '--modbus', simInfo.modbus], (err, so, se) => (err ? reject(new Error(se)) : resolve())));
    },
    async stop() {
      for (const p of [daemon, simProc]) await stopProcess(p);
      removeTestDir(dir);
    },
  };
  return rig;
}

// brdf-archive over `conninfo` (a libpq conninfo, written to a credentials file readable by
// its owner only) with the rig's two tokens and its web explorer on a free port.
export async function startArchive({ conninfo, operatorToken, analystToken }) {
  const dir = mkdtempSync(join(tmpdir(), 'brdf-web-archive-'));
  const { openSync } = await import('node:fs');
  const credentials = join(dir, 'archive.conninfo');
  writeFileSync(credentials, `${conninfo}\n`, { mode: 0o600 });
  const config = join(dir, 'brdf-archive.toml');
  writeFileSync(config, `[server]
listen = "127.0.0.1:0"
[archive]
credentials = "${credentials}"
${tokensWebAndLog(operatorToken, analystToken)}`, { mode: 0o600 });
  const log = join(dir, 'brdf-archive.log');
  const proc = spawn(join(build, 'daemon/brdf-archive'), ['--config', config], { stdio: ['ignore', 'pipe', openSync(log, 'w')] });
  const info = await waitFor(proc, 'brdf-archive', { web: /^brdf-archive web explorer on (\S+)/, grpc: /^brdf-archive listening on (\S+)/ }, 20, log);
  return {
    url: info.web, grpc: info.grpc, log,
    async stop() {
      await stopProcess(proc);
      removeTestDir(dir);
    },
  };
}

// Debian's Chromium ($BRDF_CHROMIUM), headless, driven by puppeteer-core, at 1400 × 1000.
export async function launchBrowser() {
  const { default: puppeteer } = await import('puppeteer-core');
  return puppeteer.launch({
    executablePath: process.env.BRDF_CHROMIUM || '/usr/bin/chromium',
    headless: true,
    args: ['--no-sandbox', '--disable-dev-shm-usage', '--enable-unsafe-swiftshader', '--use-angle=swiftshader', '--window-size=1400,1000'],
    defaultViewport: { width: 1400, height: 1000 },
  });
}

// A new page of `browser` whose uncaught errors and console errors go to `errors`.
export async function pageCollectingErrors(browser, errors) {
  const page = await browser.newPage();
  page.on('pageerror', (e) => errors.push(`page error: ${e.message}`));
  page.on('console', (m) => { if (m.type() === 'error') errors.push(`console: ${m.text()}`); });
  return page;
}

// Opens `url` in `page` and signs in with `token` at the login form; with `role`, waits until the
// header says who signed in (operator, analyst, reader).
export async function signIn(page, url, token, role) {
  await page.goto(url, { waitUntil: 'load' });
  await page.waitForSelector('#login-view:not([hidden])');
  await page.type('#token', token);
  await page.click('#login-button');
  if (role) await page.waitForFunction((r) => document.getElementById('who').textContent === r, {}, role);
}

export function outputDir() {
  const d = process.env.BRDF_TEST_OUTPUT_DIR || join(process.cwd(), 'web-test-output');
  if (!existsSync(d)) mkdirSync(d, { recursive: true });
  return d;
}

const started = Date.now();
export function check(cond, message) {
  if (!cond) throw new Error(`check failed: ${message}`);
  console.log(`ok (${((Date.now() - started) / 1000).toFixed(1)} s): ${message}`);
}
