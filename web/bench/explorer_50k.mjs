// The explorer on a 50,000-reading session, in headless Chromium: how long the first view takes
// (sign-in done; from opening #explorer to Figure 7's two 3D plots drawn and the plane of
// incidence computed) and how long a new direction's spectrum takes (from the click to the
// interpolated spectrum and its vertex spectra drawn), as medians, with the gateway's no-op round
// trip (an Interpolate without a direction: authorized, parsed and refused before any index
// lookup) measured in the same run as the baseline. The session is bench_storage's (a completed
// isotropic session of N sample readings at random directions); brdfd runs without a rig.
//   BRDF_BUILD_DIR=build node web/bench/explorer_50k.mjs [readings]    (from web/: node bench/…)
import puppeteer from 'puppeteer-core';
import { spawn, execFileSync } from 'node:child_process';
import { mkdtempSync, writeFileSync, openSync, readFileSync, copyFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { createInterface } from 'node:readline';

const build = process.env.BRDF_BUILD_DIR;
const readings = Number(process.argv[2] || 50000);
const dir = mkdtempSync(join(tmpdir(), 'brdf-web-bench-'));
const db = join(dir, 'brdfd.db');
const t0 = Date.now();
if (process.env.BRDF_BENCH_DB) {
  copyFileSync(process.env.BRDF_BENCH_DB, db); // a session made before (creating one takes minutes)
} else {
  execFileSync(join(build, 'bench/daemon/bench_storage'), ['create', '--db', db, '--readings', String(readings)]);
  console.log(`session of ${readings} readings created in ${Date.now() - t0} ms (keep ${db} and pass it as BRDF_BENCH_DB)`);
}
const token = 'bench-analyst-token-0123456789';
writeFileSync(join(dir, 'brdfd.toml'), `[server]
listen = "127.0.0.1:0"
[storage]
database = "${db}"
[meter]
port = "${dir}/no-meter"
[stage]
address = "127.0.0.1:1"
[[auth.tokens]]
name = "bench"
token = "${token}"
role = "analyst"
[web]
listen = "127.0.0.1:0"
[log]
level = "warn"
`);
const daemon = spawn(join(build, 'daemon/brdfd'), ['--config', join(dir, 'brdfd.toml')], { stdio: ['ignore', 'pipe', openSync(join(dir, 'brdfd.log'), 'w')] });
const url = await new Promise((resolve, reject) => {
  daemon.on('exit', (c) => reject(new Error(`brdfd exited ${c}: ${readFileSync(join(dir, 'brdfd.log'), 'utf8')}`)));
  createInterface({ input: daemon.stdout }).on('line', (l) => { const m = /^brdfd web console on (\S+)/.exec(l); if (m) resolve(m[1]); });
});
const median = (a) => { const s = [...a].sort((x, y) => x - y); return s[Math.floor(s.length / 2)]; };
const browser = await puppeteer.launch({ executablePath: process.env.BRDF_CHROMIUM || '/usr/bin/chromium', headless: true, args: ['--no-sandbox', '--disable-dev-shm-usage', '--enable-unsafe-swiftshader', '--use-angle=swiftshader'], defaultViewport: { width: 1400, height: 1000 } });
try {
  const page = await browser.newPage();
  await page.goto(url);
  await page.type('#token', token);
  await page.click('#login-button');
  await page.waitForFunction(() => document.getElementById('who').textContent === 'analyst');
  const firstViews = [];
  for (let i = 0; i < Number(process.env.BRDF_BENCH_VIEWS || 3); i++) {
    await page.goto('about:blank'); // a real page load each time (sessionStorage stays)
    const s = Date.now();
    await page.goto(`${url}#explorer`);
    await page.waitForFunction(() => /sample readings loaded/.test(document.getElementById('explorer-info')?.textContent || ''), { timeout: 120000, polling: 20 });
    firstViews.push(Date.now() - s);
    console.log(`first view ${firstViews.at(-1)} ms: ${await page.$eval('#explorer-info', (e) => e.textContent)}`);
  }
  await page.screenshot({ path: join(dir, 'explorer-50k.png'), fullPage: true });
  const spectra = [];
  const noop = [];
  for (let i = 0; i < 15; i++) {
    const dirn = { ti: 10 + (i * 7) % 60, to: 15 + (i * 11) % 60, phi: 20 + (i * 13) % 140 };
    const ms = await page.evaluate(async (d) => {
      document.getElementById('q-theta-i').value = d.ti;
      document.getElementById('q-theta-o').value = d.to;
      document.getElementById('q-phi').value = d.phi;
      document.getElementById('interp-status')?.remove();
      const s = performance.now();
      document.getElementById('interpolate').click();
      for (;;) {
        await new Promise((r) => requestAnimationFrame(r));
        const st = document.getElementById('interp-status');
        const traces = document.querySelectorAll('#interp-spectrum .scatterlayer .trace').length;
        if (st && (traces >= 2 || /status|empty|outside|no_/.test(st.textContent) || st.classList.contains('error'))) return performance.now() - s;
      }
    }, dirn);
    spectra.push(ms);
    noop.push(await page.evaluate(async () => {
      const s = performance.now();
      await fetch('/api/brdf.v1.Interpolation/Interpolate', { method: 'POST', headers: { 'Content-Type': 'application/json', Authorization: `Bearer ${sessionStorage.getItem('brdfd.token')}` }, body: JSON.stringify({ session_id: '1' }) });
      return performance.now() - s;
    }));
  }
  console.log(`a new direction's spectrum (click → interpolated and vertex spectra drawn): median ${median(spectra).toFixed(1)} ms, max ${Math.max(...spectra).toFixed(1)} ms over ${spectra.length}`);
  console.log(`gateway no-op round trip: median ${median(noop).toFixed(1)} ms; ratio spectrum/no-op ${(median(spectra) / median(noop)).toFixed(1)}`);
  console.log(`first view: median ${median(firstViews)} ms over ${firstViews.length} (target < 2000 ms); new direction target < 100 ms`);
  console.log(`screenshot: ${join(dir, 'explorer-50k.png')}`);
} finally {
  await browser.close();
  daemon.kill('SIGTERM');
}
